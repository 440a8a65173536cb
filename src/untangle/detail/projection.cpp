#include "untangle/detail/projection.h"

#include "strata/geometry/predicates.h"
#include "strata/untangle/shape_matching.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace strata::detail {

namespace {

// The segments of one layer binned in a uniform grid by the box of each segment over two
// states of the layer (`before` and `after` a step), so that one build answers for every state
// in between that moves vertices from the one to the other: keep_simple()'s candidates.
class SegmentBins {
  public:
    void build(const std::vector<Vec2>& before, const std::vector<Vec2>& after, bool closed) {
        const std::size_t n = before.size();
        segments_ = closed ? n : n - 1;
        boxes_.assign(segments_, Box2{});
        Box2 all;
        for (std::size_t s = 0; s < segments_; ++s) {
            for (const Vec2& p : {before[s], before[(s + 1) % n], after[s], after[(s + 1) % n]})
                boxes_[s].extend(p);
            all.extend(boxes_[s]);
        }
        const Vec2 size = all.max - all.min;
        origin_ = all.min;
        cell_ = std::max(std::max(size.x, size.y) / std::sqrt(static_cast<double>(segments_) + 1.0),
                         std::numeric_limits<double>::min());
        cells_.clear();
        large_.clear();
        for (std::size_t s = 0; s < segments_; ++s) {
            const auto [x0, y0, x1, y1] = range(boxes_[s]);
            if ((x1 - x0 + 1) * (y1 - y0 + 1) > kLargest) {
                large_.push_back(s);
                continue;
            }
            for (long long ix = x0; ix <= x1; ++ix)
                for (long long iy = y0; iy <= y1; ++iy) cells_[pack(ix, iy)].push_back(s);
        }
        seen_.assign(segments_, 0);
        stamp_ = 0;
    }

    // Calls f(s) once for every segment s whose box overlaps `box`.
    template <class F>
    void query(const Box2& box, F&& f) {
        if (++stamp_ == 0) {
            std::fill(seen_.begin(), seen_.end(), 0);
            stamp_ = 1;
        }
        auto visit = [&](std::size_t s) {
            if (seen_[s] == stamp_ || !boxes_[s].overlaps(box)) return;
            seen_[s] = stamp_;
            f(s);
        };
        for (std::size_t s : large_) visit(s);
        const auto [x0, y0, x1, y1] = range(box);
        if (static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1) >
            static_cast<double>(segments_)) {
            for (std::size_t s = 0; s < segments_; ++s) visit(s);
            return;
        }
        for (long long ix = x0; ix <= x1; ++ix)
            for (long long iy = y0; iy <= y1; ++iy) {
                const auto it = cells_.find(pack(ix, iy));
                if (it != cells_.end())
                    for (std::size_t s : it->second) visit(s);
            }
    }

  private:
    static constexpr long long kLargest = 16;  // cells a segment is binned in, at most
    struct Range {
        long long x0, y0, x1, y1;
    };
    Range range(const Box2& b) const {
        auto c = [this](double v, double o) {
            return static_cast<long long>(std::floor((v - o) / cell_));
        };
        return {c(b.min.x, origin_.x), c(b.min.y, origin_.y), c(b.max.x, origin_.x),
                c(b.max.y, origin_.y)};
    }
    static std::uint64_t pack(long long ix, long long iy) {
        return (static_cast<std::uint64_t>(ix) << 32) ^
               (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
    }
    std::size_t segments_ = 0;
    std::vector<Box2> boxes_;
    Vec2 origin_{0.0};
    double cell_ = 1.0;
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
    std::vector<std::size_t> large_;
    std::vector<unsigned> seen_;
    unsigned stamp_ = 0;
};

// Number of segments of `x` (open unless `closed`, binned in `bins`) other than the two at
// vertex v and their neighbours that the two segments at v meet (segment_contact() not None).
std::size_t own_contacts(const std::vector<Vec2>& x, bool closed, std::size_t v,
                         SegmentBins& bins) {
    const std::size_t n = x.size();
    std::size_t count = 0;
    for (int side = 0; side < 2; ++side) {
        // The segment (v - 1, v) or (v, v + 1), as the index of its first vertex.
        if (side == 0 && !closed && v == 0) continue;
        if (side == 1 && !closed && v + 1 >= n) continue;
        const std::size_t s = side == 0 ? (v + n - 1) % n : v;
        const Vec2 a = x[s], b = x[(s + 1) % n];
        Box2 box;
        box.extend(a);
        box.extend(b);
        bins.query(box, [&](std::size_t t) {
            // Skip s itself and the segments sharing a vertex with it.
            const std::size_t d = (t + n - s) % n;
            if (d == 0 || d == 1 || (closed ? d == n - 1 : t + 1 == s)) return;
            if (segment_contact(a, b, x[t], x[(t + 1) % n]) != SegmentContact::None) ++count;
        });
    }
    return count;
}

// Uniform grid of vertices, rebuilt at every projection step: finds the vertices of other
// layers near an edge, where a sample is needed to see them poke through a long chord. The
// vertices sorted by cell (column, then row; in filing order within a cell), each query's
// column one binary search: no allocation once the buffers have grown.
//
// The vertices of `region` are looked for among those of a larger box found at an earlier
// build (cover_, while it holds the region), in the same (layer, vertex) order: a local
// untangling's scene is whole while its region holds a few percent of it. Sound for the
// engine's scenes, whose vertices move only where every region holds them (the free
// vertices of the pieces, whose box the region grows), the others staying put.
class VertexGrid {
  public:
    void build(const Scene& scene, const Box2& region, double cell) {
        cell_ = cell;
        if (!(cover_.contains(region.min) && cover_.contains(region.max))) {
            const Vec2 size = region.size();
            cover_ = region.inflated(0.25 * std::max(size.x, size.y));
            candidates_.clear();
            for (std::size_t l = 0; l < scene.size(); ++l) {
                const Layer& layer = scene.layer(l);
                if (!layer.bounds().overlaps(cover_)) continue;
                for (std::size_t v = 0; v < layer.points.size(); ++v)
                    if (cover_.contains(layer.points[v])) candidates_.push_back({l, v});
            }
        }
        all_.clear();
        for (const auto& [l, v] : candidates_) {
            const Vec2& p = scene.layer(l).points[v];
            if (region.contains(p)) all_.push_back({p, l, v, coord(p.x), coord(p.y)});
        }
        sorted_.resize(all_.size());
        for (std::size_t k = 0; k < all_.size(); ++k) sorted_[k] = k;
        std::sort(sorted_.begin(), sorted_.end(), [this](std::size_t a, std::size_t b) {
            const Entry &ea = all_[a], &eb = all_[b];
            return std::tie(ea.column, ea.row, a) < std::tie(eb.column, eb.row, b);
        });
    }

    // Calls f(layer, vertex) for the vertices in the cells that `box` touches (cells column by
    // column, bottom to top), or, when the box spans more cells than there are vertices, for
    // every vertex in the box.
    template <class F>
    void query(const Box2& box, F&& f) const {
        const auto x0 = coord(box.min.x), x1 = coord(box.max.x);
        const auto y0 = coord(box.min.y), y1 = coord(box.max.y);
        if (static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1) >
            static_cast<double>(all_.size())) {
            for (const Entry& e : all_)
                if (box.contains(e.point)) f(e.layer, e.vertex);
            return;
        }
        for (auto ix = x0; ix <= x1; ++ix) {
            auto it =
                std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(ix, y0),
                                 [this](std::size_t k, const std::pair<long long, long long>& c) {
                                     return std::make_pair(all_[k].column, all_[k].row) < c;
                                 });
            for (; it != sorted_.end(); ++it) {
                const Entry& e = all_[*it];
                if (e.column != ix || e.row > y1) break;
                f(e.layer, e.vertex);
            }
        }
    }

  private:
    long long coord(double v) const { return static_cast<long long>(std::floor(v / cell_)); }

    struct Entry {
        Vec2 point;
        std::size_t layer, vertex;
        long long column, row;
    };
    double cell_ = 1.0;
    Box2 cover_;  // the box of candidates_ (empty: none yet)
    std::vector<std::pair<std::size_t, std::size_t>> candidates_;  // (layer, vertex) in cover_
    std::vector<Entry> all_;           // in filing order (layer, then vertex)
    std::vector<std::size_t> sorted_;  // indices into all_, by (column, row, filing order)
};

// The composed value and gradient of one layer at one point.
struct Composed {
    double fhat = 0.0;
    double f = 0.0;
    Vec2 gradient{0.0};
    bool is_violated = false;  // the composition changed this layer's value
};

// Scratch buffers of one composition, one set per thread.
struct Scratch {
    explicit Scratch(const CompositionParams& params) : composer(params) {}
    Composer composer;
    std::vector<FieldSample> samples;
    std::vector<double> f, w, separations, ts;
    std::vector<std::size_t> members, chain;
    std::vector<CompositionConstraint> constraints;
};

}  // namespace

// ProjectionPass's state and work (the class comment in projection.h).
class ProjectionPass::Impl {
  public:
    Impl(const Scene& work, const RelationSource& relations, const SceneFields& fields,
         const UntangleParams& params, double min_separation, double sample_spacing)
        : fields_(fields),
          relations_(relations),
          params_(params),
          sample_spacing_(sample_spacing),
          short_edge_(params.short_edge_fraction > 0.0
                          ? params.short_edge_fraction * median_segment_length(work)
                          : 0.0),
          scratch_([&params] { return Scratch(params.composition); }) {
        double largest = 0.0;
        for (std::size_t a = 0; a < fields.size(); ++a)
            for (std::size_t b = a + 1; b < fields.size(); ++b)
                largest = std::max(largest, relations.separation(a, b));
        reach_ = std::max(largest, min_separation) + 2.0 * sample_spacing;
        for (std::size_t j = 0; j < fields.size(); ++j)
            band_boxes_.push_back(work.layer(j).bounds().inflated(fields.params().band_width));
        // Pairwise relations and separations once per pass, and whether the layers form one
        // chain (every two of different parents nested, none side by side): then a point's
        // members sorted by rank are a chain, composed without the general constraint search.
        const std::size_t n = fields.size();
        bool gap_free_pair = false;  // a constrained pair that needs no gap (see slack())
        relation_.resize(n * n);
        separation_.resize(n * n);
        layer_weight_.resize(n);
        rank_.assign(n, 0);
        is_chain_ = true;
        for (std::size_t a = 0; a < n; ++a) {
            layer_weight_[a] = relations.weight(a);
            for (std::size_t b = 0; b < n; ++b) {
                if (a == b) continue;
                const Relation r = relations.relation(a, b);
                relation_[a * n + b] = r;
                separation_[a * n + b] = std::max(relations.separation(a, b), min_separation);
                // What the final check accepts below the aim: gap >= required * (1 - tol).
                const double required = relations.separation(a, b);
                if (r != Relation::Same) {
                    if (required >= min_separation)
                        slack_ = std::min(slack_, params.separation_tolerance * required);
                    else
                        gap_free_pair = true;
                }
                if (r == Relation::Over) ++rank_[a];
                if (r == Relation::SideBySide) is_chain_ = false;
            }
        }
        if (gap_free_pair) slack_ = std::numeric_limits<double>::infinity();
    }

    // The composed value and gradient of `layer` at x (thread-safe with one Scratch per thread).
    // `local`: the layers whose field x takes otherwise than the global order says (local
    // sides, see RelationSource::local_sides), or nullptr.
    Composed compose_at(std::size_t layer, const Vec2& x, Scratch& s,
                        const std::vector<RelationSource::LocalSide>* local = nullptr) const {
        // Only layers whose band box holds x can take part: the others are not sampled.
        s.samples.resize(fields_.size());
        s.f.clear();
        s.w.clear();
        s.members.clear();
        s.constraints.clear();
        s.members.push_back(layer);
        s.samples[layer] = fields_.field(layer).sample(x);
        for (std::size_t j = 0; j < s.samples.size(); ++j) {
            if (j == layer || !band_boxes_[j].contains(x)) continue;
            s.samples[j] = fields_.field(j).sample_in_band(x);
            // Past an end of open layer j (border b_j(x) <= 0), x does not take j, or with
            // EngineSettings::ends_by_nearest only where j's nearest feature is that end.
            const FieldSample& sj = s.samples[j];
            if (!sj.in_band || (!(sj.border > 0.0) && (!ends_by_nearest_ || sj.past_end))) continue;
            s.members.push_back(j);
            if (local) take_local_side(layer, j, *local, s.samples[j]);
        }
        Composed out;
        out.f = s.samples[layer].value;
        if (s.members.size() == 1) {
            out.fhat = out.f;
            out.gradient = s.samples[layer].gradient;
            return out;
        }
        if (!(is_chain_ && params_.composition.use_chain_fast_path &&
              compose_chain_at(layer, s, out)))
            compose_general_at(s, out);
        out.is_violated = std::abs(out.fhat - out.f) > 1e-12 * (1.0 + std::abs(out.f));
        return out;
    }

    // Sample j of the point of `layer` as its local side says: Flipped, the sign changed (the
    // composition sees the point on the other side of j and pushes it away from j there);
    // AnySide, the sign the nesting wants (only the distance to j is kept).
    void take_local_side(std::size_t layer, std::size_t j,
                         const std::vector<RelationSource::LocalSide>& local,
                         FieldSample& sample) const {
        for (const RelationSource::LocalSide& x : local) {
            if (x.layer != j) continue;
            bool flip = x.side == RelationSource::Side::Flipped;
            if (x.side == RelationSource::Side::AnySide) {
                const Relation r = relation_[layer * fields_.size() + j];
                flip = (r == Relation::Under && sample.value > 0.0) ||
                       (r == Relation::Over && sample.value < 0.0);
            }
            if (flip) {
                sample.value = -sample.value;
                sample.gradient = -sample.gradient;
            }
            return;
        }
    }

    // compose_at() with any constraint set: the members' pairwise constraints, `layer` first.
    void compose_general_at(Scratch& s, Composed& out) const {
        const std::size_t n = fields_.size();
        for (std::size_t a = 0; a < s.members.size(); ++a) {
            s.f.push_back(s.samples[s.members[a]].value);
            s.w.push_back(layer_weight_[s.members[a]]);
            for (std::size_t b = a + 1; b < s.members.size(); ++b) {
                const std::size_t ab = s.members[a] * n + s.members[b];
                const double sep = separation_[ab];
                switch (relation_[ab]) {
                    case Relation::Under:
                        s.constraints.push_back({a, b, false, sep});
                        break;
                    case Relation::Over:
                        s.constraints.push_back({b, a, false, sep});
                        break;
                    case Relation::SideBySide:
                        s.constraints.push_back({a, b, true, sep});
                        break;
                    case Relation::Same:
                        break;
                }
            }
        }
        const CompositionResult& r = s.composer.compose(s.f, s.w, s.constraints);
        out.fhat = r.fhat[0];
        for (std::size_t j = 0; j < s.members.size(); ++j)
            out.gradient += r.coefficient(0, j) * s.samples[s.members[j]].gradient;
    }

    // compose_at() for members of distinct ranks in a chain scene: sorted innermost first,
    // composed by compose_chain(). Same result as the general path, whose chain detection
    // finds this order and drops the implied constraints. false: two members share a rank
    // (parts of one layer), left to the general path.
    bool compose_chain_at(std::size_t layer, Scratch& s, Composed& out) const {
        s.chain = s.members;  // members keeps `layer` first for the general path
        std::sort(s.chain.begin(), s.chain.end(),
                  [this](std::size_t a, std::size_t b) { return rank_[a] < rank_[b]; });
        for (std::size_t i = 0; i + 1 < s.chain.size(); ++i)
            if (rank_[s.chain[i]] == rank_[s.chain[i + 1]]) return false;
        const std::size_t n = fields_.size();
        std::size_t own = 0;
        s.separations.clear();
        for (std::size_t i = 0; i < s.chain.size(); ++i) {
            if (s.chain[i] == layer) own = i;
            s.f.push_back(s.samples[s.chain[i]].value);
            s.w.push_back(layer_weight_[s.chain[i]]);
            if (i + 1 < s.chain.size())
                s.separations.push_back(separation_[s.chain[i] * n + s.chain[i + 1]]);
        }
        const CompositionResult& r = s.composer.compose_chain(s.f, s.w, s.separations);
        out.fhat = r.fhat[own];
        for (std::size_t j = 0; j < s.chain.size(); ++j)
            out.gradient += r.coefficient(own, j) * s.samples[s.chain[j]].gradient;
        return true;
    }

    // Parameters t in (0, 1) of the points tested on edge (a, b) of `layer`, in `ts`: evenly
    // spaced ones, and the feet of the nearby vertices of the other layers.
    void edge_samples(const Scene& scene, std::size_t layer, const Vec2& a, const Vec2& b,
                      std::vector<double>& ts) const {
        ts.clear();
        const double length = glm::distance(a, b);
        int count = params_.edge_samples;
        if (sample_spacing_ > 0.0)
            count =
                std::max(count, static_cast<int>(std::min(64.0, length / (4.0 * sample_spacing_))));
        for (int s = 1; s <= count; ++s) ts.push_back(static_cast<double>(s) / (count + 1.0));
        if (sample_spacing_ <= 0.0 || !(length > 0.0)) return;
        const Vec2 dir = (b - a) / length;
        const double reach = std::min(reach_, 0.5 * length);
        Box2 box;
        box.extend(a);
        box.extend(b);
        const std::size_t regular = ts.size();
        grid_.query(box.inflated(reach), [&](std::size_t other, std::size_t vertex) {
            if (other == layer || ts.size() >= regular + 64) return;
            const Vec2 w = scene.layer(other).points[vertex];
            const double along = glm::dot(w - a, dir);
            if (along <= 0.0 || along >= length) return;
            const double across = std::abs(dir.x * (w.y - a.y) - dir.y * (w.x - a.x));
            if (across <= reach) ts.push_back(along / length);
        });
    }

    // Normalised damped step toward fhat = 0, before clamping.
    Vec2 step_toward_zero(const Composed& c) const {
        const double g2 = glm::dot(c.gradient, c.gradient);
        if (!(g2 > 1e-24)) return Vec2(0.0);
        return -params_.step * c.fhat * c.gradient / g2;
    }

    // One projection step of every free vertex (Jacobi: from the positions at the start).
    // Returns the summed displacement length.
    double project(Scene& scene, const std::vector<Piece>& pieces) {
        double moved = 0.0;
        if (sample_spacing_ > 0.0) {
            Box2 region;
            for (const Piece& piece : pieces)
                for (std::size_t v : piece.vertices)
                    region.extend(scene.layer(piece.layer).points[v]);
            grid_.build(scene, region.inflated(reach_), sample_spacing_);
        }
        // Every free vertex and every edge (between consecutive piece vertices, sampled when
        // one end is free) of every piece is one task, writing only its own slots; all read the
        // positions at the start of the step (Jacobi). Tasks run in parallel; the sums are
        // gathered in a fixed order, so the step does not depend on the number of threads.
        vertex_offset_.assign(1, 0);
        edge_offset_.assign(1, 0);
        for (const Piece& piece : pieces) {
            const std::size_t m = piece.vertices.size();
            vertex_offset_.push_back(vertex_offset_.back() + m);
            edge_offset_.push_back(edge_offset_.back() + (m == 0                ? 0
                                                          : piece.is_whole_loop ? m
                                                                                : m - 1));
        }
        const std::size_t vertices = vertex_offset_.back(), edges = edge_offset_.back();
        own_.assign(vertices, Vec2(0.0));
        edge_a_.assign(edges, Vec2(0.0));
        edge_b_.assign(edges, Vec2(0.0));
        edge_wa_.assign(edges, 0.0);
        edge_wb_.assign(edges, 0.0);
        violation_.assign(vertices + edges, 0.0);
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, vertices + edges, 4),
            [&](const tbb::blocked_range<std::size_t>& range) {
                Scratch& s = scratch_.local();
                for (std::size_t i = range.begin(); i != range.end(); ++i) {
                    const bool is_vertex = i < vertices;
                    const std::vector<std::size_t>& offset =
                        is_vertex ? vertex_offset_ : edge_offset_;
                    const std::size_t index = is_vertex ? i : i - vertices;
                    const std::size_t p = static_cast<std::size_t>(
                        std::upper_bound(offset.begin(), offset.end(), index) - offset.begin() - 1);
                    const Piece& piece = pieces[p];
                    const std::vector<Vec2>& x = scene.layer(piece.layer).points;
                    const std::size_t k = index - offset[p];
                    if (is_vertex) {
                        if (piece.is_free[k]) {
                            const Composed c =
                                compose_at(piece.layer, x[piece.vertices[k]], s,
                                           relations_.local_at(piece.layer, piece.vertices[k]));
                            violation_[i] = std::abs(c.fhat - c.f);
                            own_[i] = step_toward_zero(c);
                        }
                        continue;
                    }
                    const std::size_t k2 = (k + 1) % piece.vertices.size();
                    if (!piece.is_free[k] && !piece.is_free[k2]) continue;
                    const Vec2 a = x[piece.vertices[k]], b = x[piece.vertices[k2]];
                    edge_samples(scene, piece.layer, a, b, s.ts);
                    const auto* local_a = relations_.local_at(piece.layer, piece.vertices[k]);
                    const auto* local_b = relations_.local_at(piece.layer, piece.vertices[k2]);
                    for (double t : s.ts) {
                        // An edge's points take the local sides of its nearer end.
                        const Composed c = compose_at(piece.layer, a + t * (b - a), s,
                                                      t < 0.5 ? local_a : local_b);
                        if (!c.is_violated) continue;
                        violation_[i] = std::max(violation_[i], std::abs(c.fhat - c.f));
                        const Vec2 d = step_toward_zero(c);
                        edge_a_[index] += (1.0 - t) * d;
                        edge_wa_[index] += 1.0 - t;
                        edge_b_[index] += t * d;
                        edge_wb_[index] += t;
                    }
                }
            });
        for (std::size_t p = 0; p < pieces.size(); ++p) {
            const Piece& piece = pieces[p];
            const Layer& layer = scene.layer(piece.layer);
            const std::vector<Vec2>& x = layer.points;
            const std::size_t n = x.size();
            const std::size_t m = piece.vertices.size();
            const std::size_t piece_edges = edge_offset_[p + 1] - edge_offset_[p];
            const Vec2* own = own_.data() + vertex_offset_[p];
            const std::size_t e0 = edge_offset_[p];
            sum_.assign(m, Vec2(0.0));
            weight_.assign(m, 0.0);
            for (std::size_t k = 0; k < m; ++k) {
                if (!piece.is_free[k]) continue;
                sum_[k] = own[k];
                weight_[k] = 1.0;
                if (k > 0 || piece.is_whole_loop) {  // the edge ending at k
                    const std::size_t e = e0 + (k > 0 ? k - 1 : piece_edges - 1);
                    sum_[k] += edge_b_[e];
                    weight_[k] += edge_wb_[e];
                }
                if (k < piece_edges) {  // the edge starting at k
                    sum_[k] += edge_a_[e0 + k];
                    weight_[k] += edge_wa_[e0 + k];
                }
            }
            next_ = x;
            for (std::size_t k = 0; k < m; ++k) {
                if (!piece.is_free[k] || weight_[k] <= 0.0) continue;
                const std::size_t v = piece.vertices[k];
                Vec2 d = sum_[k] / weight_[k];
                // Clamp to a fraction of the shorter adjacent edge (past short edges).
                double edge = std::numeric_limits<double>::infinity();
                if (layer.closed || v > 0) edge = std::min(edge, step_edge(x, layer.closed, v, -1));
                if (layer.closed || v + 1 < n)
                    edge = std::min(edge, step_edge(x, layer.closed, v, +1));
                const double limit = params_.max_step_fraction * edge;
                const double len = glm::length(d);
                if (len > limit) d *= limit / len;
                next_[v] = x[v] + d;
                moved += glm::length(d);
            }
            if (keep_simple_) keep_simple(piece, layer.closed, x, next_);
            scene.set_points(piece.layer, std::move(next_));  // next_ is refilled before use
        }
        return moved;
    }

    // The length that bounds the step of vertex v of a layer (`x`, `closed`) on the side `dir`
    // (-1: toward v - 1, +1: toward v + 1; a side that exists): its distance to the first
    // vertex that way at least short_edge_ from it, at most kShortEdgeHops edges on (then to
    // the last one reached, as at an open layer's end). With short_edge_ 0, the adjacent edge.
    double step_edge(const std::vector<Vec2>& x, bool closed, std::size_t v, int dir) const {
        constexpr int kShortEdgeHops = 8;
        const std::size_t n = x.size();
        double distance = 0.0;
        std::size_t j = v;
        for (int hop = 0; hop < kShortEdgeHops; ++hop) {
            if (!closed && (dir < 0 ? j == 0 : j + 1 == n)) break;
            j = dir < 0 ? (j + n - 1) % n : (j + 1) % n;
            distance = glm::distance(x[v], x[j]);
            if (distance >= short_edge_) break;
        }
        return distance;
    }

    // EngineSettings::keep_simple: the moves of `piece` from `before` to `after` taken one
    // vertex at a time, in order; a move whose two segments meet more segments of the layer
    // than they did before it is not made (the vertex stays where it was), so the layer never
    // gets a self-crossing it did not have.
    void keep_simple(const Piece& piece, bool closed, const std::vector<Vec2>& before,
                     std::vector<Vec2>& after) {
        state_ = before;
        bins_.build(before, after, closed);
        for (std::size_t k = 0; k < piece.vertices.size(); ++k) {
            const std::size_t v = piece.vertices[k];
            if (after[v] == before[v]) continue;
            const std::size_t was = own_contacts(state_, closed, v, bins_);
            state_[v] = after[v];
            if (own_contacts(state_, closed, v, bins_) > was) state_[v] = before[v];
        }
        after = state_;
    }

    // The largest |fhat - f| over the samples of the last project() (scene units).
    double max_violation() const {
        double worst = 0.0;
        for (double v : violation_) worst = std::max(worst, v);
        return worst;
    }

    // give_up_when_stalled's threshold: the smallest slack, over the constrained pairs of
    // work layers, between the gap aimed for and the gap the final check accepts
    // (separation_tolerance x required). +inf (never give up) when a constrained pair needs
    // less than min_separation: only crossings fail there, and the worst violation, a layer's
    // share of the correction toward min_separation, says little about them (on the real
    // garment slices, whose thickness is 0, the rule gave up on untanglings that succeed).
    double slack() const { return slack_; }

    void match_shapes(Scene& scene, const std::vector<Piece>& pieces,
                      const std::vector<std::vector<Vec2>>& rest) {
        for (std::size_t p = 0; p < pieces.size(); ++p) {
            const Piece& piece = pieces[p];
            const Layer& layer = scene.layer(piece.layer);
            ShapeMatchParams sm;
            sm.alpha = layer.alpha.value_or(params_.alpha);
            sm.beta = layer.beta.value_or(params_.beta);
            current_.clear();
            fixed_.clear();
            for (std::size_t k = 0; k < piece.vertices.size(); ++k) {
                current_.push_back(layer.points[piece.vertices[k]]);
                fixed_.push_back(piece.is_free[k] ? 0 : 1);
            }
            shape_match(rest[p], current_, {}, fixed_, sm);
            next_ = layer.points;
            for (std::size_t k = 0; k < piece.vertices.size(); ++k)
                next_[piece.vertices[k]] = current_[k];
            if (keep_simple_) keep_simple(piece, layer.closed, layer.points, next_);
            scene.set_points(piece.layer, std::move(next_));  // next_ is refilled before use
        }
    }

    void set_keep_simple(bool on) { keep_simple_ = on; }
    void set_ends_by_nearest(bool on) { ends_by_nearest_ = on; }

  private:
    bool keep_simple_ = false;      // EngineSettings::keep_simple
    bool ends_by_nearest_ = false;  // EngineSettings::ends_by_nearest
    std::vector<Vec2> state_;       // keep_simple()'s scratch
    SegmentBins bins_;
    const SceneFields& fields_;
    const RelationSource& relations_;
    const UntangleParams& params_;
    double sample_spacing_ = 0.0;
    double short_edge_ = 0.0;  // UntangleParams::short_edge_fraction x the median segment
    double reach_ = 0.0;  // how far from an edge a vertex of another layer gets its own sample
    tbb::enumerable_thread_specific<Scratch> scratch_;
    VertexGrid grid_;
    std::vector<Box2> band_boxes_;  // each layer's bounds grown by the band width
    // project(): per vertex and per edge of all pieces, and where each piece's start.
    std::vector<Vec2> own_, edge_a_, edge_b_;
    std::vector<double> edge_wa_, edge_wb_;
    std::vector<double> violation_;  // per vertex and edge task: largest |fhat - f|
    std::vector<std::size_t> vertex_offset_, edge_offset_;
    std::vector<Relation> relation_;  // n x n, work layers
    std::vector<double> separation_;  // n x n, max(required, min_separation)
    double slack_ = std::numeric_limits<double>::infinity();  // see slack()
    std::vector<double> layer_weight_;                        // per work layer
    std::vector<std::size_t> rank_;                           // layers each is over: innermost 0
    bool is_chain_ = true;
    std::vector<Vec2> sum_, next_, current_;
    std::vector<double> weight_;
    std::vector<char> fixed_;
};

ProjectionPass::ProjectionPass(const Scene& work, const RelationSource& relations,
                               const SceneFields& fields, const UntangleParams& params,
                               double min_separation, double sample_spacing)
    : impl_(std::make_unique<Impl>(work, relations, fields, params, min_separation,
                                   sample_spacing)) {}

ProjectionPass::~ProjectionPass() = default;

void ProjectionPass::set_keep_simple(bool on) {
    impl_->set_keep_simple(on);
}

void ProjectionPass::set_ends_by_nearest(bool on) {
    impl_->set_ends_by_nearest(on);
}

double ProjectionPass::project(Scene& scene, const std::vector<Piece>& pieces) {
    return impl_->project(scene, pieces);
}

void ProjectionPass::match_shapes(Scene& scene, const std::vector<Piece>& pieces,
                                  const std::vector<std::vector<Vec2>>& rest) {
    impl_->match_shapes(scene, pieces, rest);
}

double ProjectionPass::max_violation() const {
    return impl_->max_violation();
}

double ProjectionPass::slack() const {
    return impl_->slack();
}

}  // namespace strata::detail
