#include "untangle/detail/separation.h"

#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>

namespace strata::detail {

namespace {

// Segment k of a polyline with n points joins point k to point (k + 1) % n.
struct SegId {
    std::uint32_t layer, index;
};

// The segments of the work scene in a uniform hash grid, kept up to date as vertices move.
class SegmentCells {
  public:
    SegmentCells(const std::vector<std::vector<Vec2>>& pts, const std::vector<char>& closed,
                 double cell)
        : pts_(pts), closed_(closed), cell_(cell) {
        offset_.assign(1, 0);
        for (std::size_t l = 0; l < pts.size(); ++l)
            offset_.push_back(offset_.back() + segment_count(l));
        range_.resize(offset_.back());
        stamp_.assign(offset_.back(), 0);
        for (std::size_t l = 0; l < pts.size(); ++l)
            for (std::size_t k = 0; k < segment_count(l); ++k) insert(l, k);
    }

    std::size_t segment_count(std::size_t l) const {
        const std::size_t n = pts_[l].size();
        return n < 2 ? 0 : closed_[l] ? n : n - 1;
    }
    Vec2 start(const SegId& s) const { return pts_[s.layer][s.index]; }
    Vec2 end(const SegId& s) const { return pts_[s.layer][(s.index + 1) % pts_[s.layer].size()]; }

    // Re-files segment k of layer l after one of its ends moved.
    void refile(std::size_t l, std::size_t k) {
        const Range& r = range_[offset_[l] + k];
        for (long long ix = r.x0; ix <= r.x1; ++ix)
            for (long long iy = r.y0; iy <= r.y1; ++iy) {
                std::vector<SegId>& cell = cells_[pack(ix, iy)];
                for (std::size_t i = 0; i < cell.size(); ++i)
                    if (cell[i].layer == l && cell[i].index == k) {
                        cell[i] = cell.back();
                        cell.pop_back();
                        break;
                    }
            }
        insert(l, k);
    }

    // Calls f(SegId) once for every segment filed in a cell that `box` touches.
    template <class F>
    void query(const Box2& box, F&& f) {
        ++tick_;
        const long long x0 = coord(box.min.x), x1 = coord(box.max.x);
        const long long y0 = coord(box.min.y), y1 = coord(box.max.y);
        for (long long ix = x0; ix <= x1; ++ix)
            for (long long iy = y0; iy <= y1; ++iy) {
                auto it = cells_.find(pack(ix, iy));
                if (it == cells_.end()) continue;
                for (const SegId& s : it->second) {
                    std::uint32_t& seen = stamp_[offset_[s.layer] + s.index];
                    if (seen == tick_) continue;
                    seen = tick_;
                    f(s);
                }
            }
    }

  private:
    struct Range {
        long long x0 = 0, x1 = -1, y0 = 0, y1 = -1;
    };

    void insert(std::size_t l, std::size_t k) {
        const SegId s{static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(k)};
        const Vec2 a = start(s), b = end(s);
        Range& r = range_[offset_[l] + k];
        r = {coord(std::min(a.x, b.x)), coord(std::max(a.x, b.x)), coord(std::min(a.y, b.y)),
             coord(std::max(a.y, b.y))};
        for (long long ix = r.x0; ix <= r.x1; ++ix)
            for (long long iy = r.y0; iy <= r.y1; ++iy) cells_[pack(ix, iy)].push_back(s);
    }
    long long coord(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
    static std::uint64_t pack(long long ix, long long iy) {
        return (static_cast<std::uint64_t>(ix) << 32) ^
               (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
    }

    const std::vector<std::vector<Vec2>>& pts_;
    const std::vector<char>& closed_;
    double cell_;
    std::vector<std::size_t> offset_;
    std::vector<Range> range_;
    std::vector<std::uint32_t> stamp_;
    std::uint32_t tick_ = 0;
    std::unordered_map<std::uint64_t, std::vector<SegId>> cells_;
};

bool in_closed_triangle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& p) {
    const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

class Finisher {
  public:
    Finisher(Scene& work, const std::vector<Piece>& pieces, const RelationSource& relations,
             const SeparationParams& params)
        : work_(work), params_(params) {
        const std::size_t n = work.size();
        for (std::size_t l = 0; l < n; ++l) {
            pts_.push_back(work.layer(l).points);
            closed_.push_back(work.layer(l).closed ? 1 : 0);
            inverse_mass_.emplace_back(pts_[l].size(), 0.0);
        }
        for (const Piece& piece : pieces)
            for (std::size_t k = 0; k < piece.vertices.size(); ++k)
                if (piece.is_free[k])
                    inverse_mass_[piece.layer][piece.vertices[k]] =
                        1.0 / relations.weight(piece.layer);
        aim_.assign(n * n, 0.0);
        relation_.assign(n * n, Relation::Same);
        for (std::size_t a = 0; a < n; ++a)
            for (std::size_t b = 0; b < n; ++b) {
                if (a == b) continue;
                relation_[a * n + b] = relations.relation(a, b);
                if (relation_[a * n + b] == Relation::Same) continue;
                aim_[a * n + b] = std::max(relations.separation(a, b), params.min_separation);
                reach_ = std::max(reach_, aim_[a * n + b]);
            }
    }

    SeparationResult run() {
        SeparationResult result;
        if (!(reach_ > 0.0)) return result;
        std::vector<double> lengths;
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t k = 0; k + 1 < pts_[l].size(); ++k)
                lengths.push_back(glm::distance(pts_[l][k], pts_[l][k + 1]));
        double cell = 2.0 * reach_;
        if (!lengths.empty()) {
            auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
            std::nth_element(lengths.begin(), mid, lengths.end());
            cell = std::max(cell, *mid);
        }
        cells_.emplace(pts_, closed_, cell);
        std::vector<bool> changed(pts_.size(), false);
        // A close vertex on the wrong side of another layer is a tangle the projection has to
        // take out first (the check fails on it anyway): look before moving anything.
        measure(result, changed);
        if (wrong_side_ == 0 && worst_ <= params_.tolerance) return result;
        const std::size_t wrong_before = wrong_side_;
        const double worst_before = worst_;
        const std::vector<std::vector<Vec2>> before = pts_;
        double previous = std::numeric_limits<double>::infinity();
        int stalled = 0;
        for (int sweep = 0; sweep < params_.max_sweeps; ++sweep) {
            ++result.sweeps;
            worst_ = 0.0;
            wrong_side_ = 0;
            for (std::size_t l = 0; l < pts_.size(); ++l)
                for (std::size_t v = 0; v < pts_[l].size(); ++v)
                    relax_vertex(l, v, result, changed, true);
            result.worst = worst_;
            result.wrong_side = wrong_side_;
            if (worst_ <= params_.tolerance) break;
            // Constraints that fight each other (a vertex squeezed between fixed ones) stop
            // improving: give up after 5 sweeps without a 1% gain.
            stalled = worst_ < 0.99 * previous ? 0 : stalled + 1;
            if (stalled >= 5) break;
            previous = std::min(previous, worst_);
        }
        // Where the aims cannot all be met (a layer squeezed between fixed collars), pushing
        // can leave the worst pair worse than it was: then nothing is moved.
        measure(result, changed);
        if (wrong_side_ > wrong_before || (wrong_side_ == wrong_before && worst_ > worst_before)) {
            pts_ = before;
            result.worst = worst_before;
            result.wrong_side = wrong_before;
            result.reverted = true;
            return result;
        }
        for (std::size_t l = 0; l < pts_.size(); ++l)
            if (changed[l]) work_.set_points(l, pts_[l]);
        return result;
    }

  private:
    std::size_t layer_size(std::size_t l) const { return pts_[l].size(); }

    // worst_ and wrong_side_ of the current positions, in the result too.
    void measure(SeparationResult& result, std::vector<bool>& changed) {
        worst_ = 0.0;
        wrong_side_ = 0;
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t v = 0; v < pts_[l].size(); ++v)
                relax_vertex(l, v, result, changed, false);
        result.worst = worst_;
        result.wrong_side = wrong_side_;
    }

    // Every segment of another constrained layer closer to vertex (l, v) than aimed for is
    // pushed away from it, the vertex the other way, in proportion to the inverse masses.
    // apply = false: only measures (worst_, wrong_side_).
    void relax_vertex(std::size_t l, std::size_t v, SeparationResult& result,
                      std::vector<bool>& changed, bool apply) {
        const std::size_t n = pts_.size();
        Box2 box;
        box.extend(pts_[l][v]);
        found_.clear();
        cells_->query(box.inflated(reach_), [&](const SegId& s) {
            if (s.layer != l && relation_[l * n + s.layer] != Relation::Same) found_.push_back(s);
        });
        for (const SegId& s : found_) {
            const std::size_t m = s.layer;
            const double aim = aim_[l * n + m];
            const std::size_t k0 = s.index, k1 = (s.index + 1) % layer_size(m);
            const Vec2 p = pts_[l][v], q0 = pts_[m][k0], q1 = pts_[m][k1];
            const double wp = inverse_mass_[l][v], w0 = inverse_mass_[m][k0],
                         w1 = inverse_mass_[m][k1];
            if (wp == 0.0 && w0 == 0.0 && w1 == 0.0) continue;
            Vec2 c;
            const double d = point_segment_distance(p, q0, q1, &c);
            if (!(d < aim)) continue;
            const Vec2 e = q1 - q0;
            const double e2 = glm::dot(e, e);
            const double t = e2 > 0.0 ? std::clamp(glm::dot(p - q0, e) / e2, 0.0, 1.0) : 0.0;
            // The side p must be on; at an end of the segment, the side it is on.
            Vec2 normal;
            double shortfall = aim - d;
            if (t > 0.0 && t < 1.0) {
                const Vec2 left(-e.y, e.x);  // orient2d(q0, q1, q0 + left) = +1
                const int wanted = wanted_side(l, m);
                const int side = orient2d(q0, q1, p);
                normal = (wanted != 0 ? static_cast<double>(wanted)
                          : side != 0 ? side
                                      : 1.0) *
                         left / std::sqrt(e2);
                if (wanted != 0 && side != wanted) {  // crossed: over to the other side
                    ++wrong_side_;
                    shortfall = aim + d;
                }
            } else if (d > 1e-12 * aim) {
                normal = (p - c) / d;
            } else {
                ++wrong_side_;  // on an end of the segment: a contact, left to the projection
                continue;
            }
            worst_ = std::max(worst_, shortfall / aim);
            if (!apply) continue;
            const double denominator = wp + w0 * (1.0 - t) * (1.0 - t) + w1 * t * t;
            if (!(denominator > 0.0)) continue;
            const double lambda = shortfall / denominator;
            if (wp > 0.0) try_move(l, v, wp * lambda * normal, result, changed);
            if (w0 > 0.0 && t < 1.0)
                try_move(m, k0, -w0 * (1.0 - t) * lambda * normal, result, changed);
            if (w1 > 0.0 && t > 0.0) try_move(m, k1, -w1 * t * lambda * normal, result, changed);
        }
    }

    // The side of layer m's segments (orient2d sign) that layer l's vertices must be on, by
    // the nesting: inside m when l is under m, outside when over; 0 when any side will do
    // (side-by-side layers push apart whatever the side).
    int wanted_side(std::size_t l, std::size_t m) const {
        const Relation r = relation_[l * pts_.size() + m];
        if (r == Relation::SideBySide || params_.outside_signs == nullptr ||
            m >= params_.outside_signs->size())
            return 0;
        const int outside = (*params_.outside_signs)[m];  // +1: outside on the right
        return r == Relation::Under ? outside : -outside;
    }

    // Moves vertex (l, v) by `delta`, or by a half, a quarter or an eighth of it when the full
    // move would tunnel; refuses the move when none is safe.
    void try_move(std::size_t l, std::size_t v, Vec2 delta, SeparationResult& result,
                  std::vector<bool>& changed) {
        const Vec2 p = pts_[l][v];
        for (int attempt = 0; attempt < 4; ++attempt, delta *= 0.5) {
            const Vec2 to = p + delta;
            if (to == p) return;
            if (!is_safe(l, v, p, to)) continue;
            pts_[l][v] = to;
            const std::size_t n = layer_size(l);
            if (closed_[l] || v > 0) cells_->refile(l, (v + n - 1) % n);
            if (closed_[l] || v + 1 < n) cells_->refile(l, v);
            changed[l] = true;
            ++result.moves;
            return;
        }
        ++result.refused;
    }

    // Exact: moving vertex (l, v) from p to `to` keeps every other segment and vertex where it
    // was relative to layer l. The new segments (prev, to) and (to, next) must meet no segment
    // they do not share an end with, and the triangles swept by the old ones must hold no
    // other vertex; then no segment can have passed through the moving ones.
    bool is_safe(std::size_t l, std::size_t v, const Vec2& p, const Vec2& to) {
        const std::size_t n = layer_size(l);
        const bool has_prev = closed_[l] || v > 0, has_next = closed_[l] || v + 1 < n;
        const std::size_t prev = (v + n - 1) % n, next = (v + 1) % n;
        Box2 box;
        box.extend(p);
        box.extend(to);
        if (has_prev) box.extend(pts_[l][prev]);
        if (has_next) box.extend(pts_[l][next]);
        bool safe = true;
        auto shares_end = [&](const SegId& s, std::size_t a, std::size_t b) {
            if (s.layer != l) return false;
            const std::size_t s1 = (s.index + 1) % n;
            return s.index == a || s.index == b || s1 == a || s1 == b;
        };
        auto is_mover = [&](std::size_t m, std::size_t k) {
            return m == l && (k == v || (has_prev && k == prev) || (has_next && k == next));
        };
        cells_->query(box, [&](const SegId& s) {
            if (!safe) return;
            const Vec2 a = cells_->start(s), b = cells_->end(s);
            if (has_prev && !shares_end(s, prev, v) &&
                segment_contact(pts_[l][prev], to, a, b) != SegmentContact::None)
                safe = false;
            if (has_next && !shares_end(s, v, next) &&
                segment_contact(to, pts_[l][next], a, b) != SegmentContact::None)
                safe = false;
            const std::size_t ends[2] = {s.index, (s.index + 1) % layer_size(s.layer)};
            for (std::size_t e = 0; e < 2 && safe; ++e) {
                if (is_mover(s.layer, ends[e])) continue;
                const Vec2 w = pts_[s.layer][ends[e]];
                if (has_prev && in_closed_triangle(pts_[l][prev], p, to, w)) safe = false;
                if (has_next && in_closed_triangle(p, to, pts_[l][next], w)) safe = false;
            }
        });
        return safe;
    }

    Scene& work_;
    const SeparationParams& params_;
    std::vector<std::vector<Vec2>> pts_;
    std::vector<char> closed_;
    std::vector<std::vector<double>> inverse_mass_;
    std::vector<double> aim_;  // n x n, 0 where unconstrained
    std::vector<Relation> relation_;
    double reach_ = 0.0;  // largest aim
    std::optional<SegmentCells> cells_;
    std::vector<SegId> found_;
    double worst_ = 0.0;
    std::size_t wrong_side_ = 0;
};

}  // namespace

SeparationResult finish_separations(Scene& work, const std::vector<Piece>& pieces,
                                    const RelationSource& relations,
                                    const SeparationParams& params) {
    return Finisher(work, pieces, relations, params).run();
}

}  // namespace strata::detail
