#include "untangle/detail/engine.h"

#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/untangle/shape_matching.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

namespace strata::detail {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Uniform hash grid of vertices, rebuilt at every projection step: finds the vertices of other
// layers near an edge, where a sample is needed to see them poke through a long chord.
class VertexGrid {
  public:
    void build(const Scene& scene, const Box2& region, double cell) {
        cell_ = cell;
        cells_.clear();
        all_.clear();
        for (std::size_t l = 0; l < scene.size(); ++l) {
            const Layer& layer = scene.layer(l);
            if (!layer.bounds().overlaps(region)) continue;
            for (std::size_t v = 0; v < layer.points.size(); ++v)
                if (region.contains(layer.points[v])) {
                    cells_[key(layer.points[v])].push_back({l, v});
                    all_.push_back({layer.points[v], l, v});
                }
        }
    }

    // Calls f(layer, vertex) for the vertices in the cells that `box` touches, or, when the
    // box spans more cells than there are vertices, for every vertex in the box.
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
        for (auto ix = x0; ix <= x1; ++ix)
            for (auto iy = y0; iy <= y1; ++iy) {
                auto it = cells_.find(pack(ix, iy));
                if (it == cells_.end()) continue;
                for (const auto& [layer, vertex] : it->second) f(layer, vertex);
            }
    }

  private:
    long long coord(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
    static std::uint64_t pack(long long ix, long long iy) {
        return (static_cast<std::uint64_t>(ix) << 32) ^
               (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
    }
    std::uint64_t key(const Vec2& p) const { return pack(coord(p.x), coord(p.y)); }

    struct Entry {
        Vec2 point;
        std::size_t layer, vertex;
    };
    double cell_ = 1.0;
    std::unordered_map<std::uint64_t, std::vector<std::pair<std::size_t, std::size_t>>> cells_;
    std::vector<Entry> all_;
};

// The composed value and gradient of one layer at one point.
struct Composed {
    double fhat = 0.0;
    double f = 0.0;
    Vec2 gradient{0.0};
    bool is_violated = false;  // the composition changed this layer's value
};

// One pass of projection + shape matching over fixed fields.
class Pass {
  public:
    Pass(const Scene& work, const RelationSource& relations, const SceneFields& fields,
         const UntangleParams& params, double min_separation, double sample_spacing)
        : fields_(fields),
          params_(params),
          min_separation_(min_separation),
          sample_spacing_(sample_spacing),
          composer_(params.composition) {
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
                if (r == Relation::Over) ++rank_[a];
                if (r == Relation::SideBySide) is_chain_ = false;
            }
        }
    }

    Composed compose_at(std::size_t layer, const Vec2& x) {
        // Only layers whose band box holds x can take part: the others are not sampled.
        samples_.resize(fields_.size());
        f_.clear();
        w_.clear();
        members_.clear();
        constraints_.clear();
        members_.push_back(layer);
        samples_[layer] = fields_.field(layer).sample(x);
        for (std::size_t j = 0; j < samples_.size(); ++j) {
            if (j == layer || !band_boxes_[j].contains(x)) continue;
            samples_[j] = fields_.field(j).sample_in_band(x);
            if (samples_[j].in_band && samples_[j].border > 0.0) members_.push_back(j);
        }
        Composed out;
        out.f = samples_[layer].value;
        if (members_.size() == 1) {
            out.fhat = out.f;
            out.gradient = samples_[layer].gradient;
            return out;
        }
        if (is_chain_ && params_.composition.use_chain_fast_path && compose_chain_at(layer, out))
            return out;
        const std::size_t n = fields_.size();
        for (std::size_t a = 0; a < members_.size(); ++a) {
            f_.push_back(samples_[members_[a]].value);
            w_.push_back(layer_weight_[members_[a]]);
            for (std::size_t b = a + 1; b < members_.size(); ++b) {
                const std::size_t ab = members_[a] * n + members_[b];
                const double s = separation_[ab];
                switch (relation_[ab]) {
                    case Relation::Under:
                        constraints_.push_back({a, b, false, s});
                        break;
                    case Relation::Over:
                        constraints_.push_back({b, a, false, s});
                        break;
                    case Relation::SideBySide:
                        constraints_.push_back({a, b, true, s});
                        break;
                    case Relation::Same:
                        break;
                }
            }
        }
        const CompositionResult& r = composer_.compose(f_, w_, constraints_);
        out.fhat = r.fhat[0];
        for (std::size_t j = 0; j < members_.size(); ++j)
            out.gradient += r.coefficient(0, j) * samples_[members_[j]].gradient;
        out.is_violated = std::abs(out.fhat - out.f) > 1e-12 * (1.0 + std::abs(out.f));
        return out;
    }

    // compose_at() for members of distinct ranks in a chain scene: sorted innermost first,
    // composed by compose_chain(). Same result as the general path, whose chain detection
    // finds this order and drops the implied constraints. false: two members share a rank
    // (parts of one layer), left to the general path.
    bool compose_chain_at(std::size_t layer, Composed& out) {
        chain_ = members_;  // members_ keeps `layer` first for the general path
        std::sort(chain_.begin(), chain_.end(),
                  [this](std::size_t a, std::size_t b) { return rank_[a] < rank_[b]; });
        for (std::size_t i = 0; i + 1 < chain_.size(); ++i)
            if (rank_[chain_[i]] == rank_[chain_[i + 1]]) return false;
        const std::size_t n = fields_.size();
        std::size_t own = 0;
        separations_.clear();
        for (std::size_t i = 0; i < chain_.size(); ++i) {
            if (chain_[i] == layer) own = i;
            f_.push_back(samples_[chain_[i]].value);
            w_.push_back(layer_weight_[chain_[i]]);
            if (i + 1 < chain_.size())
                separations_.push_back(separation_[chain_[i] * n + chain_[i + 1]]);
        }
        const CompositionResult& r = composer_.compose_chain(f_, w_, separations_);
        out.fhat = r.fhat[own];
        for (std::size_t j = 0; j < chain_.size(); ++j)
            out.gradient += r.coefficient(own, j) * samples_[chain_[j]].gradient;
        out.is_violated = std::abs(out.fhat - out.f) > 1e-12 * (1.0 + std::abs(out.f));
        return true;
    }

    // Parameters t in (0, 1) of the points tested on edge (a, b) of `layer`, in ts_: evenly
    // spaced ones, and the feet of the nearby vertices of the other layers.
    void edge_samples(const Scene& scene, std::size_t layer, const Vec2& a, const Vec2& b) {
        ts_.clear();
        const double length = glm::distance(a, b);
        int count = params_.edge_samples;
        if (sample_spacing_ > 0.0)
            count =
                std::max(count, static_cast<int>(std::min(64.0, length / (4.0 * sample_spacing_))));
        for (int s = 1; s <= count; ++s) ts_.push_back(static_cast<double>(s) / (count + 1.0));
        if (sample_spacing_ <= 0.0 || !(length > 0.0)) return;
        const Vec2 dir = (b - a) / length;
        const double reach = std::min(reach_, 0.5 * length);
        Box2 box;
        box.extend(a);
        box.extend(b);
        const std::size_t regular = ts_.size();
        grid_.query(box.inflated(reach), [&](std::size_t other, std::size_t vertex) {
            if (other == layer || ts_.size() >= regular + 64) return;
            const Vec2 w = scene.layer(other).points[vertex];
            const double along = glm::dot(w - a, dir);
            if (along <= 0.0 || along >= length) return;
            const double across = std::abs(dir.x * (w.y - a.y) - dir.y * (w.x - a.x));
            if (across <= reach) ts_.push_back(along / length);
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
        for (const Piece& piece : pieces) {
            const Layer& layer = scene.layer(piece.layer);
            const std::vector<Vec2>& x = layer.points;
            const std::size_t n = x.size();
            const std::size_t m = piece.vertices.size();
            sum_.assign(m, Vec2(0.0));
            weight_.assign(m, 0.0);
            for (std::size_t k = 0; k < m; ++k) {
                if (!piece.is_free[k]) continue;
                const Composed c = compose_at(piece.layer, x[piece.vertices[k]]);
                sum_[k] += step_toward_zero(c);
                weight_[k] += 1.0;
            }
            // Edges between consecutive piece vertices with a free end.
            const std::size_t edges = piece.is_whole_loop ? m : m - 1;
            for (std::size_t k = 0; k < edges; ++k) {
                const std::size_t k2 = (k + 1) % m;
                if (!piece.is_free[k] && !piece.is_free[k2]) continue;
                const Vec2 a = x[piece.vertices[k]], b = x[piece.vertices[k2]];
                edge_samples(scene, piece.layer, a, b);
                for (double t : ts_) {
                    const Composed c = compose_at(piece.layer, a + t * (b - a));
                    if (!c.is_violated) continue;
                    const Vec2 d = step_toward_zero(c);
                    sum_[k] += (1.0 - t) * d;
                    weight_[k] += 1.0 - t;
                    sum_[k2] += t * d;
                    weight_[k2] += t;
                }
            }
            next_ = x;
            for (std::size_t k = 0; k < m; ++k) {
                if (!piece.is_free[k] || weight_[k] <= 0.0) continue;
                const std::size_t v = piece.vertices[k];
                Vec2 d = sum_[k] / weight_[k];
                // Clamp to a fraction of the shorter adjacent edge.
                double edge = std::numeric_limits<double>::infinity();
                if (layer.closed || v > 0)
                    edge = std::min(edge, glm::distance(x[v], x[(v + n - 1) % n]));
                if (layer.closed || v + 1 < n)
                    edge = std::min(edge, glm::distance(x[v], x[(v + 1) % n]));
                const double limit = params_.max_step_fraction * edge;
                const double len = glm::length(d);
                if (len > limit) d *= limit / len;
                next_[v] = x[v] + d;
                moved += glm::length(d);
            }
            scene.set_points(piece.layer, next_);
        }
        return moved;
    }

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
            scene.set_points(piece.layer, next_);
        }
    }

  private:
    const SceneFields& fields_;
    const UntangleParams& params_;
    double min_separation_ = 0.0;
    double sample_spacing_ = 0.0;
    double reach_ = 0.0;  // how far from an edge a vertex of another layer gets its own sample
    Composer composer_;
    VertexGrid grid_;
    std::vector<Box2> band_boxes_;  // each layer's bounds grown by the band width
    std::vector<double> ts_;
    std::vector<FieldSample> samples_;
    std::vector<double> f_, w_;
    std::vector<std::size_t> members_;
    std::vector<CompositionConstraint> constraints_;
    std::vector<std::size_t> chain_;    // compose_chain_at(): members innermost first
    std::vector<double> separations_;   // compose_chain_at(): between consecutive members
    std::vector<Relation> relation_;    // n x n, work layers
    std::vector<double> separation_;    // n x n, max(required, min_separation)
    std::vector<double> layer_weight_;  // per work layer
    std::vector<std::size_t> rank_;     // layers each is over: innermost 0
    bool is_chain_ = true;
    std::vector<Vec2> sum_, next_, current_;
    std::vector<double> weight_;
    std::vector<char> fixed_;
};

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

std::vector<double> segment_lengths(const Layer& layer) {
    std::vector<double> lengths;
    for (std::size_t i = 0; i < layer.segment_count(); ++i)
        lengths.push_back(glm::distance(layer.segment_start(i), layer.segment_end(i)));
    return lengths;
}

double median_segment_length(const Scene& scene) {
    std::vector<double> lengths;
    for (const Layer& layer : scene.layers()) {
        const std::vector<double> l = segment_lengths(layer);
        lengths.insert(lengths.end(), l.begin(), l.end());
    }
    return median(std::move(lengths));
}

double finest_layer_median(const Scene& scene) {
    double finest = std::numeric_limits<double>::infinity();
    for (const Layer& layer : scene.layers())
        finest = std::min(finest, median(segment_lengths(layer)));
    return std::isfinite(finest) ? finest : 0.0;
}

// The pieces' current vertex positions.
std::vector<std::vector<Vec2>> shapes_of(const Scene& work, const std::vector<Piece>& pieces) {
    std::vector<std::vector<Vec2>> shapes;
    for (const Piece& piece : pieces) {
        shapes.emplace_back();
        for (std::size_t v : piece.vertices)
            shapes.back().push_back(work.layer(piece.layer).points[v]);
    }
    return shapes;
}

}  // namespace

EngineSettings resolve_settings(const Scene& scene, const UntangleParams& params) {
    EngineSettings settings;
    settings.min_separation =
        params.min_separation > 0.0 ? params.min_separation : 0.01 * median_segment_length(scene);
    settings.sample_spacing =
        params.sample_spacing > 0.0 ? params.sample_spacing : finest_layer_median(scene);
    const Vec2 size = scene.bounds().size();
    settings.diagonal = std::max(std::hypot(size.x, size.y), std::numeric_limits<double>::min());
    settings.outside_signs.resize(scene.size());
    for (std::size_t i = 0; i < scene.size(); ++i)
        settings.outside_signs[i] = outside_side(scene, i);
    return settings;
}

EngineResult run_engine(Scene& work, const std::vector<Piece>& pieces, const UntangleParams& params,
                        const RelationSource& relations, const EngineSettings& settings,
                        const std::function<bool(const Scene&)>& is_ok,
                        const ProgressFn& progress) {
    EngineResult result;
    std::size_t free_vertices = 0;
    for (const Piece& piece : pieces)
        free_vertices +=
            static_cast<std::size_t>(std::count(piece.is_free.begin(), piece.is_free.end(), 1));
    auto start = Clock::now();
    result.ok = is_ok(work);
    result.seconds_check += seconds_since(start);
    result.converged = result.ok;  // nothing to do is a converged run
    const int total_rounds = params.max_rounds * params.max_passes;
    std::vector<std::vector<Vec2>> rest = shapes_of(work, pieces);  // shape matching's rest
    for (int pass = 0; pass < params.max_passes && !result.ok; ++pass) {
        ++result.passes;
        start = Clock::now();
        const SceneFields fields(work, params.field, settings.outside_signs);
        result.seconds_fields += seconds_since(start);
        // Aim above the grid's interpolation error, or its fields cannot see the gap.
        const double separation =
            params.min_separation > 0.0 || params.field.backend != FieldBackend::Grid
                ? settings.min_separation
                : std::max(settings.min_separation, 0.25 * fields.params().voxel_size);
        start = Clock::now();
        Pass engine(work, relations, fields, params, separation, settings.sample_spacing);
        result.converged = false;
        if (!settings.rest_at_start) rest = shapes_of(work, pieces);
        for (int round = 0; round < params.max_rounds; ++round) {
            const bool match = settings.rest_at_start ? pass > 0 || round > 0 : round > 0;
            if (match && params.shape == ShapeMode::ShapeMatching)
                engine.match_shapes(work, pieces, rest);
            // V (Eq. 7) of the round's last projection step: shape matching moves the
            // vertices at the start of every round, the projection must settle them again.
            double moved = 0.0;
            for (int s = 0; s < params.gradient_steps && !result.ok; ++s) {
                moved = engine.project(work, pieces);
                if (settings.check_every_step && s + 1 < params.gradient_steps) {
                    result.seconds_untangle += seconds_since(start);
                    start = Clock::now();
                    result.ok = is_ok(work);
                    result.seconds_check += seconds_since(start);
                    start = Clock::now();
                }
            }
            ++result.rounds;
            if (result.ok) break;
            result.mean_speed = free_vertices ? moved / static_cast<double>(free_vertices) : 0.0;
            if (progress &&
                !progress("untangle", static_cast<double>(result.rounds) / total_rounds))
                throw Cancelled();
            if (result.mean_speed <= params.tolerance * settings.diagonal) {
                result.converged = true;
                break;
            }
            // The exact check after every round: a region that is already good stops here.
            result.seconds_untangle += seconds_since(start);
            start = Clock::now();
            result.ok = is_ok(work);
            result.seconds_check += seconds_since(start);
            start = Clock::now();
            if (result.ok) break;
        }
        result.seconds_untangle += seconds_since(start);
        if (!result.ok) {
            start = Clock::now();
            result.ok = is_ok(work);
            result.seconds_check += seconds_since(start);
        }
    }
    return result;
}

}  // namespace strata::detail
