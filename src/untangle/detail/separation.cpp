#include "untangle/detail/separation.h"

#include "untangle/detail/segment_cells.h"

#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace strata::detail {

namespace {

// p lies in the closed triangle (a, b, c). The side (a, b) is tested last, and only when the
// other two leave p possibly inside: is_safe() passes a vertex's move there, often so short
// that orient2d() on it falls to its exact (rational) stage.
bool in_closed_triangle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& p) {
    const int o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    if (o2 * o3 < 0) return false;
    const int o1 = orient2d(a, b, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

class Finisher {
  public:
    Finisher(Scene& work, const std::vector<Piece>& pieces, const RelationSource& relations,
             const SeparationParams& params, FinishCache* cache)
        : work_(work), pieces_(pieces), relations_(relations), params_(params), cache_(cache) {
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
        slot_.assign(n, -1);
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
        double cell = 2.0 * reach_;
        if (const std::optional<double> mid = median_length()) {
            cell = std::max(cell, *mid);
            tangle_reach_ = params_.tangle_reach * *mid;
        }
        tangle_reach_ = std::max(tangle_reach_, reach_);
        cell = std::max(cell, tangle_reach_);
        // Only what lies near the free vertices (and their neighbours) can be relaxed.
        Box2 region;
        for (std::size_t l = 0; l < pts_.size(); ++l) {
            const std::size_t n = pts_[l].size();
            for (std::size_t v = 0; v < n; ++v) {
                if (inverse_mass_[l][v] == 0.0) continue;
                region.extend(pts_[l][v]);
                if (closed_[l] || v > 0) region.extend(pts_[l][(v + n - 1) % n]);
                if (closed_[l] || v + 1 < n) region.extend(pts_[l][(v + 1) % n]);
            }
        }
        if (region.is_empty()) return result;
        region = region.inflated(2.0 * tangle_reach_);
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t v = 0; v < pts_[l].size(); ++v)
                if (region.contains(pts_[l][v]))
                    active_.push_back(
                        {static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(v)});
        cells_.emplace(pts_, closed_, cell, region);
        std::vector<bool> changed(pts_.size(), false);
        // A close vertex on the wrong side of another layer is a tangle the projection has to
        // take out first (the check fails on it anyway): look before moving anything.
        measure(result, changed);
        if (wrong_side_ == 0 && worst_ <= params_.tolerance) return result;
        if (wrong_side_ > 0 && params_.only_when_untangled) return result;
        const std::size_t wrong_before = wrong_side_;
        const double worst_before = worst_;
        const std::vector<std::vector<Vec2>> before = pts_;
        double previous = std::numeric_limits<double>::infinity();
        int stalled = 0;
        for (int sweep = 0; sweep < params_.max_sweeps; ++sweep) {
            ++result.sweeps;
            worst_ = 0.0;
            wrong_side_ = 0;
            for (const SegId& a : active_) relax_vertex(a.layer, a.index, result, changed, true);
            result.worst = worst_;
            result.wrong_side = wrong_side_;
            if (worst_ <= params_.tolerance) break;
            if (params_.stop_when_wrong_stays > 0 && wrong_side_ > 0 &&
                wrong_side_ >= wrong_before && result.sweeps >= params_.stop_when_wrong_stays)
                break;
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
            result.moves = 0;
            result.worst = worst_before;
            result.wrong_side = wrong_before;
            result.reverted = true;
            return result;
        }
        for (std::size_t l = 0; l < pts_.size(); ++l)
            if (changed[l]) work_.set_points(l, std::move(pts_[l]));  // pts_ is done with
        return result;
    }

  private:
    std::size_t layer_size(std::size_t l) const { return pts_[l].size(); }

    // The median length of the segments (k, k + 1) of every layer (the closing segment of a
    // closed layer left out), the element at position count / 2 in increasing order; none
    // when there is no segment. With cache_, the fixed segments' lengths are taken from it.
    std::optional<double> median_length() {
        if (cache_ && !cache_->is_set) fill_cache();
        if (cache_ && !cache_->fixed_lengths.empty()) {
            moving_lengths_.clear();
            for (const auto& [l, k] : cache_->moving)
                moving_lengths_.push_back(glm::distance(pts_[l][k], pts_[l][k + 1]));
            std::sort(moving_lengths_.begin(), moving_lengths_.end());
            const std::vector<double>& a = cache_->fixed_lengths;
            const std::vector<double>& b = moving_lengths_;
            // The element at position k of the two sorted lists merged: i of the first k + 1
            // come from `a`, the smallest i with a[i] >= b[k - i] (or i = min(k + 1, |a|)).
            const std::size_t k = (a.size() + b.size()) / 2;
            std::size_t lo = k + 1 > b.size() ? k + 1 - b.size() : 0;
            std::size_t hi = std::min(k + 1, a.size());
            while (lo < hi) {
                const std::size_t i = lo + (hi - lo) / 2;
                if (a[i] < b[k - i])
                    lo = i + 1;
                else
                    hi = i;
            }
            const std::size_t j = k + 1 - lo;
            if (lo == 0) return b[j - 1];
            if (j == 0) return a[lo - 1];
            return std::max(a[lo - 1], b[j - 1]);
        }
        std::vector<double> lengths;
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t k = 0; k + 1 < pts_[l].size(); ++k)
                lengths.push_back(glm::distance(pts_[l][k], pts_[l][k + 1]));
        if (lengths.empty()) return std::nullopt;
        auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
        std::nth_element(lengths.begin(), mid, lengths.end());
        return *mid;
    }

    // Fills cache_: the segments with a free end of a piece (only those move), and, when the
    // others are most of the scene, their lengths sorted.
    void fill_cache() {
        FinishCache& c = *cache_;
        c.is_set = true;
        std::vector<std::vector<char>> free(pts_.size());
        for (std::size_t l = 0; l < pts_.size(); ++l) free[l].assign(pts_[l].size(), 0);
        for (const Piece& piece : pieces_)
            for (std::size_t k = 0; k < piece.vertices.size(); ++k)
                if (piece.is_free[k]) free[piece.layer][piece.vertices[k]] = 1;
        std::size_t total = 0;
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t k = 0; k + 1 < pts_[l].size(); ++k) {
                ++total;
                if (free[l][k] || free[l][k + 1])
                    c.moving.emplace_back(static_cast<std::uint32_t>(l),
                                          static_cast<std::uint32_t>(k));
            }
        // Mostly moving (a whole-scene untangling): every call measures every segment.
        if (2 * c.moving.size() >= total) {
            c.moving.clear();
            return;
        }
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t k = 0; k + 1 < pts_[l].size(); ++k)
                if (!free[l][k] && !free[l][k + 1])
                    c.fixed_lengths.push_back(glm::distance(pts_[l][k], pts_[l][k + 1]));
        std::sort(c.fixed_lengths.begin(), c.fixed_lengths.end());
    }

    // worst_ and wrong_side_ of the current positions, in the result too.
    void measure(SeparationResult& result, std::vector<bool>& changed) {
        worst_ = 0.0;
        wrong_side_ = 0;
        for (const SegId& a : active_) relax_vertex(a.layer, a.index, result, changed, false);
        result.worst = worst_;
        result.wrong_side = wrong_side_;
    }

    // Every segment of another constrained layer closer to vertex (l, v) than aimed for is
    // pushed away from it, the vertex the other way, in proportion to the inverse masses.
    // When the vertex lies on the wrong side of its nearest segment of another layer (judged
    // within tangle_reach_, which is larger than the aims), it is pushed over to its side
    // instead, and that layer's other segments wait. apply = false: only measures (worst_,
    // wrong_side_).
    void relax_vertex(std::size_t l, std::size_t v, SeparationResult& result,
                      std::vector<bool>& changed, bool apply) {
        const std::size_t n = pts_.size();
        Box2 box;
        box.extend(pts_[l][v]);
        found_.clear();
        cells_->query(box.inflated(tangle_reach_), [&](const SegId& s) {
            if (s.layer != l && relation_[l * n + s.layer] != Relation::Same) found_.push_back(s);
        });
        if (found_.empty()) return;
        // The nearest segment of each layer, and whether the vertex is on its wrong side. Only
        // a segment closer than tangle_reach_ can make the vertex wrong or be pushed (every
        // aim is within it): one whose box is farther is not measured (distance +inf; its
        // layer's entry stays +inf and not wrong unless a closer one comes).
        const Vec2 p0 = pts_[l][v];
        // (A margin far above the rounding of the closest point, at any offset.)
        const double far = tangle_reach_ + 1e-9 * (tangle_reach_ + std::abs(p0.x) + std::abs(p0.y));
        nearest_.clear();
        distance_.resize(found_.size());
        for (std::size_t i = 0; i < found_.size(); ++i) {
            const SegId& s = found_[i];
            const Vec2 a = cells_->start(s), b = cells_->end(s);
            const double gap = std::max({std::min(a.x, b.x) - p0.x, p0.x - std::max(a.x, b.x),
                                         std::min(a.y, b.y) - p0.y, p0.y - std::max(a.y, b.y)});
            const double d = gap > far ? std::numeric_limits<double>::infinity()
                                       : point_segment_distance(p0, a, b);
            distance_[i] = d;
            std::int32_t& slot = slot_[s.layer];
            if (slot < 0) {
                slot = static_cast<std::int32_t>(nearest_.size());
                nearest_.push_back({s.layer, i, d, false, 0, kNoTip, kNoTip});
            } else if (d < nearest_[static_cast<std::size_t>(slot)].distance) {
                nearest_[static_cast<std::size_t>(slot)] = {s.layer, i,      d,     false,
                                                            0,       kNoTip, kNoTip};
            }
        }
        for (Nearest& x : nearest_) {
            const SegId& s = found_[x.index];
            const Vec2 q0 = cells_->start(s), q1 = cells_->end(s), p = pts_[l][v];
            int wanted = wanted_side(l, v, s.layer);
            // No side asked of an open side-by-side layer: the side the rest of the vertex's
            // run is on. (Not where a local side asks for any side around an end: a roll's
            // bend is there, which this would push back.)
            if (wanted == 0 && !closed_[s.layer] && x.distance < tangle_reach_ &&
                relation_[l * pts_.size() + s.layer] == Relation::SideBySide)
                wanted = poke_side(l, v, q0, q1);
            x.wanted = wanted;
            x.is_wrong = wanted != 0 && x.distance < tangle_reach_ && interior(p, q0, q1) &&
                         orient2d(q0, q1, p) != wanted;
            x.tip = kNoTip;
            x.end = kNoTip;
            if (!x.is_wrong && wanted != 0 && x.distance < tangle_reach_ && opens_cut_bends())
                x.tip = hairpin_tip(s, p, wanted);
            if (wanted == 0 && x.distance < tangle_reach_) x.end = slipped_end(l, v, s, p);
        }
        for (const Nearest& x : nearest_) {
            if (x.end == kNoTip) continue;
            // Around an end of layer m (any side), but m's end segment has come to reach past
            // it, the vertex on the global order's wrong side of it: the end moves back behind
            // the vertex's foot by the aim (or, when the end is fixed, the vertex moves out past
            // it), so that the end is again the vertex's closest point on m.
            const std::size_t m = x.layer, last = layer_size(m) - 1;
            const std::size_t inner = x.end == 0 ? 1 : last - 1;
            const Vec2 p = pts_[l][v], q = pts_[m][x.end], f = pts_[m][inner];
            const double length = glm::distance(q, f);
            const double aim = aim_[l * n + m];
            ++wrong_side_;
            worst_ = std::max(worst_, 1.0 + x.distance / aim);
            if (!apply || !(length > 0.0)) continue;
            const Vec2 u = (q - f) / length;  // out of m at the end
            const double shift = length - glm::dot(p - f, u) + aim;
            const double wp = inverse_mass_[l][v], wq = inverse_mass_[m][x.end];
            if (wq > 0.0 && shift < 0.5 * length)
                try_move(m, x.end, -shift * u, result, changed);
            else if (wp > 0.0)
                try_move(l, v, shift * u, result, changed);
        }
        const std::size_t moves_before = result.moves;
        for (const Nearest& x : nearest_) {
            if (x.tip == kNoTip) continue;
            // Beyond the tip of a hairpin of layer m (a bend the decimation cut), on the wrong
            // side (SeparationParams::open_cut_bends): the tip moves past the vertex by the aim,
            // so that the vertex lies in the hairpin's wedge, and that layer's other segments
            // wait. The projection would drag the vertex around the tip instead, and its layer
            // with it (issue 19).
            const std::size_t m = x.layer;
            const Vec2 p = pts_[l][v], q = pts_[m][x.tip];
            const double d = glm::distance(p, q);
            const double aim = aim_[l * n + m];
            ++wrong_side_;
            worst_ = std::max(worst_, (aim + d) / aim);
            if (!apply || !(d > 0.0)) continue;
            const double wp = inverse_mass_[l][v], wq = inverse_mass_[m][x.tip];
            if (!(wp + wq > 0.0)) continue;
            // The vertex moves past the tip only when the tip is fixed.
            const Vec2 u = (q - p) / d;
            if (wq > 0.0)
                try_move(m, x.tip, -(d + aim) * u, result, changed);
            else
                try_move(l, v, (d + aim) * u, result, changed);
        }
        for (std::size_t i = 0; i < found_.size(); ++i) {
            const SegId& s = found_[i];
            const std::size_t m = s.layer;
            const Nearest& near = nearest_[static_cast<std::size_t>(slot_[m])];
            if (near.tip != kNoTip || near.end != kNoTip) continue;  // the tip, the end above
            if (near.is_wrong && near.index != i) continue;          // the tangle first
            const double aim = aim_[l * n + m];
            // Nothing moved yet in this call: the distance measured above is the one below.
            if (!near.is_wrong && result.moves == moves_before && !(distance_[i] < aim)) continue;
            const std::size_t k0 = s.index, k1 = (s.index + 1) % layer_size(m);
            const Vec2 p = pts_[l][v], q0 = pts_[m][k0], q1 = pts_[m][k1];
            const double wp = inverse_mass_[l][v], w0 = inverse_mass_[m][k0],
                         w1 = inverse_mass_[m][k1];
            if (wp == 0.0 && w0 == 0.0 && w1 == 0.0) continue;
            Vec2 c;
            const double d = point_segment_distance(p, q0, q1, &c);
            const Vec2 e = q1 - q0;
            const double e2 = glm::dot(e, e);
            const double t = e2 > 0.0 ? std::clamp(glm::dot(p - q0, e) / e2, 0.0, 1.0) : 0.0;
            Vec2 normal;
            double shortfall = aim - d;
            if (near.is_wrong) {             // over to the side it belongs on, at the aim
                const Vec2 left(-e.y, e.x);  // orient2d(q0, q1, q0 + left) = +1
                normal = static_cast<double>(near.wanted) * left / std::sqrt(e2);
                shortfall = aim + d;
                ++wrong_side_;
            } else if (!(d < aim)) {
                continue;
            } else if (d > 1e-12 * aim) {
                normal = (p - c) / d;
            } else {
                ++wrong_side_;  // on the other layer: a contact, left to the projection
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
        for (const Nearest& x : nearest_) slot_[x.layer] = -1;
    }

    bool opens_cut_bends() const {
        return params_.open_cut_bends && !relations_.local_sides.empty();
    }

    // When the closest point of open layer m's segment s to p is an interior vertex of m where
    // m turns back on itself (a hairpin: the two segments at it more than 120 degrees apart)
    // and p lies outside the hairpin's wedge while `wanted` (orient2d sign) asks for inside:
    // that vertex; else kNoTip.
    std::size_t hairpin_tip(const SegId& s, const Vec2& p, int wanted) const {
        const std::size_t m = s.layer, n = layer_size(m);
        if (closed_[m] || n < 3) return kNoTip;
        const Vec2 q0 = cells_->start(s), q1 = cells_->end(s);
        const Vec2 e = q1 - q0;
        const double along = glm::dot(p - q0, e);
        std::size_t w;
        if (along <= 0.0)
            w = s.index;
        else if (along >= glm::dot(e, e))
            w = s.index + 1;
        else
            return kNoTip;
        if (w == 0 || w + 1 >= n) return kNoTip;  // an end of m
        const Vec2 a = pts_[m][w - 1], c = pts_[m][w], b = pts_[m][w + 1];
        const Vec2 in = c - a, out = b - c;
        const double li = glm::length(in), lo = glm::length(out);
        if (!(li > 0.0 && lo > 0.0) || glm::dot(in, out) > -0.5 * li * lo) return kNoTip;
        const int turn = orient2d(a, c, b);
        if (turn == 0) return kNoTip;
        // The wedge is on the side of the turn: inside it, p is on that side of both segments.
        const bool in_wedge = orient2d(a, c, p) == turn && orient2d(c, b, p) == turn;
        if (in_wedge) return kNoTip;
        // corner_side()'s rule: outside the wedge, p counts as on the side away from the turn,
        // which is the wrong one when the wedge's side (turn) is wanted.
        return wanted == turn ? w : kNoTip;
    }
    static constexpr std::size_t kNoTip = static_cast<std::size_t>(-1);

    // Vertex (l, v) at p takes any side of open layer m (it lies around m's end in the input:
    // RelationSource::Side::AnySide), but segment s, its closest on m, is an end segment of m
    // whose span holds p's foot, and p is on the other side of it than the global order asks
    // for: p is no longer around the end, and the checks judge it by the global order (a
    // vertex with no recorded side), so it is on the wrong side. Returns that end of m (0 or
    // its last vertex), else kNoTip. Moves of m's end (pushed apart from another segment) make
    // it so: the end turns and its segment comes to reach past p.
    std::size_t slipped_end(std::size_t l, std::size_t v, const SegId& s, const Vec2& p) const {
        const std::size_t m = s.layer, count = layer_size(m);
        if (closed_[m] || count < 2 || params_.outside_signs == nullptr ||
            m >= params_.outside_signs->size())
            return kNoTip;
        const Relation r = relation_[l * pts_.size() + m];
        if (r == Relation::SideBySide || r == Relation::Same) return kNoTip;
        if (relations_.side_of(l, v, m) != RelationSource::Side::AnySide) return kNoTip;
        const std::size_t end = s.index == 0 ? 0 : s.index + 2 == count ? count - 1 : kNoTip;
        if (end == kNoTip) return kNoTip;
        const Vec2 q0 = cells_->start(s), q1 = cells_->end(s);
        if (!interior(p, q0, q1)) return kNoTip;
        // Just past: the foot within the aim of the end (deeper in, a tangle the projection
        // takes out).
        const Vec2 q = pts_[m][end], e = q - (end == 0 ? q1 : q0);
        const double length = glm::length(e);
        if (!(length > 0.0) || glm::dot(q - p, e) / length >= aim_[l * pts_.size() + m])
            return kNoTip;
        const int outside = (*params_.outside_signs)[m];
        const int global = r == Relation::Under ? outside : -outside;
        const int side = orient2d(q0, q1, p);
        return side != 0 && side != global ? end : kNoTip;
    }

    // The foot of p on segment (q0, q1) lies strictly inside it.
    static bool interior(const Vec2& p, const Vec2& q0, const Vec2& q1) {
        const Vec2 e = q1 - q0;
        const double along = glm::dot(p - q0, e);
        return along > 0.0 && along < glm::dot(e, e);
    }

    // The side of layer m's segments (orient2d sign) that layer l's vertices must be on, by
    // the nesting: inside m when l is under m, outside when over; 0 when any side will do
    // (side-by-side layers push apart whatever the side; see poke_side() for open m). Vertex v
    // keeps the other side where the input has it there, or any side around an end of m
    // (RelationSource::local_sides).
    int wanted_side(std::size_t l, std::size_t v, std::size_t m) const {
        const Relation r = relation_[l * pts_.size() + m];
        if (r == Relation::SideBySide || params_.outside_signs == nullptr ||
            m >= params_.outside_signs->size())
            return 0;
        const int outside = (*params_.outside_signs)[m];  // +1: outside on the right
        const int wanted = r == Relation::Under ? outside : -outside;
        switch (relations_.side_of(l, v, m)) {
            case RelationSource::Side::Flipped:
                return -wanted;
            case RelationSource::Side::AnySide:
                return 0;
            default:
                return wanted;
        }
    }

    // Where no side is asked of an open side-by-side layer: the side of segment
    // (q0, q1) of another layer that vertex (l, v) pokes through from. Walking along layer l
    // from v both ways (at most kPokeRun segments each), the first segments that properly
    // cross (q0, q1) bound a run of l that lies on the other side of it than the rest of the
    // layer; an end of an open layer reached first bounds it too (a dangling end), but not
    // on both sides. Returns the side of (q0, q1) that the rest of the layer is on, the one
    // v belongs on, or 0 when v is not in such a run.
    int poke_side(std::size_t l, std::size_t v, const Vec2& q0, const Vec2& q1) const {
        constexpr std::size_t kPokeRun = 8;
        const std::vector<Vec2>& x = pts_[l];
        const std::size_t n = x.size();
        const int own = orient2d(q0, q1, x[v]);
        if (own == 0 || n < 2) return 0;
        int bounded = 0, ends = 0;
        for (int dir : {-1, 1}) {
            std::size_t k = v;
            bool found = false;
            for (std::size_t step = 0; step < kPokeRun && step + 1 < n; ++step) {
                const bool at_end = dir < 0 ? (!closed_[l] && k == 0) : (!closed_[l] && k + 1 == n);
                if (at_end) {
                    ++ends;
                    found = true;
                    break;
                }
                const std::size_t j = dir < 0 ? (k + n - 1) % n : (k + 1) % n;
                if (segment_contact(x[k], x[j], q0, q1) == SegmentContact::Proper) {
                    ++bounded;
                    found = true;
                    break;
                }
                k = j;
            }
            if (!found) return 0;
        }
        return bounded >= 1 && ends <= 1 ? -own : 0;
    }

    // Moves vertex (l, v) by `delta`, or by a half, a quarter or an eighth of it when the full
    // move would tunnel; refuses the move when none is safe.
    void try_move(std::size_t l, std::size_t v, Vec2 delta, SeparationResult& result,
                  std::vector<bool>& changed) {
        const Vec2 p = pts_[l][v];
        bool gathered = false;
        // The candidate that refused the last attempt: a shorter move along the same line
        // mostly meets it too, so it is tested first (is_safe() tests every candidate anyway:
        // the order changes no verdict).
        std::size_t blocker = kNoTip;
        for (int attempt = 0; attempt < 4; ++attempt, delta *= 0.5) {
            const Vec2 to = p + delta;
            if (to == p) return;
            // The first (largest) move's box holds every later one's (p + delta / 2^k rounds
            // between p and p + delta): its candidates serve them all.
            if (!gathered) gather_candidates(l, v, p, to);
            gathered = true;
            if (!is_safe(l, v, p, to, blocker)) continue;
            pts_[l][v] = to;
            cells_->moved(l, v);
            changed[l] = true;
            ++result.moves;
            return;
        }
        ++result.refused;
    }

    // The box of vertex (l, v)'s move from p to `to` with its two neighbours: what is_safe()
    // tests lies in it.
    Box2 move_box(std::size_t l, std::size_t v, const Vec2& p, const Vec2& to) const {
        const std::size_t n = layer_size(l);
        Box2 box;
        box.extend(p);
        box.extend(to);
        if (closed_[l] || v > 0) box.extend(pts_[l][(v + n - 1) % n]);
        if (closed_[l] || v + 1 < n) box.extend(pts_[l][(v + 1) % n]);
        return box;
    }

    // A segment whose box is apart from `box` (exact comparisons, as segment_contact()'s own).
    static bool is_apart(const Vec2& a, const Vec2& b, const Box2& box) {
        return std::max(a.x, b.x) < box.min.x || std::min(a.x, b.x) > box.max.x ||
               std::max(a.y, b.y) < box.min.y || std::min(a.y, b.y) > box.max.y;
    }

    // candidates_: the segments of cells_ not apart from the box of the move of vertex (l, v)
    // from p to `to`, for is_safe() on that move or a shorter one in the same direction
    // (nothing moves in between).
    void gather_candidates(std::size_t l, std::size_t v, const Vec2& p, const Vec2& to) {
        const Box2 box = move_box(l, v, p, to);
        candidates_.clear();
        cells_->query(box, [&](const SegId& s) {
            const std::size_t e = cells_->end_index(s);
            const Vec2 a = pts_[s.layer][s.index], b = pts_[s.layer][e];
            if (!is_apart(a, b, box)) candidates_.push_back({s, e, a, b});
        });
    }

    // Exact: moving vertex (l, v) from p to `to` tunnels through nothing. The new segments
    // (prev, to) and (to, next) may meet another segment only as many times as the old ones
    // did (a vertex on the wrong side of a layer moves back over it one vertex at a time: the
    // crossing passes from one of its segments to the other), and the triangles swept
    // by the old segments must hold no other vertex; then no segment that the old ones did
    // not meet can have passed through the moving ones, and no new contact is made.
    // The segments tested are those of candidates_ (gather_candidates() of this move or of a
    // longer one): every segment that may meet the move's box is among them.
    // `blocker`: a candidates_ index tested first (none: past the end); set to the one that
    // refuses the move, if any.
    bool is_safe(std::size_t l, std::size_t v, const Vec2& p, const Vec2& to,
                 std::size_t& blocker) const {
        const std::size_t n = layer_size(l);
        const bool has_prev = closed_[l] || v > 0, has_next = closed_[l] || v + 1 < n;
        const std::size_t prev = (v + n - 1) % n, next = (v + 1) % n;
        auto shares_end = [&](const Candidate& c, std::size_t a, std::size_t b) {
            if (c.id.layer != l) return false;
            const std::size_t s0 = c.id.index, s1 = c.end_index;
            return s0 == a || s0 == b || s1 == a || s1 == b;
        };
        auto is_mover = [&](std::size_t m, std::size_t k) {
            return m == l && (k == v || (has_prev && k == prev) || (has_next && k == next));
        };
        auto meets = [](const Vec2& a0, const Vec2& a1, const Vec2& b0, const Vec2& b1) {
            return segment_contact(a0, a1, b0, b1) != SegmentContact::None;
        };
        // The boxes of the triangles swept by the old segments.
        Box2 sweep_prev, sweep_next;
        sweep_prev.extend(p);
        sweep_prev.extend(to);
        sweep_next = sweep_prev;
        if (has_prev) sweep_prev.extend(pts_[l][prev]);
        if (has_next) sweep_next.extend(pts_[l][next]);
        // Whether candidate c refuses the move.
        auto refuses = [&](const Candidate& c) {
            const Vec2 &a = c.a, &b = c.b;
            // Everything tested below on the side of `prev` lies in sweep_prev (the old and
            // new segments and the swept triangle), and likewise for `next`: a segment whose
            // box is apart from one can neither meet what lies in it nor have an end inside it.
            const bool near_prev = has_prev && !is_apart(a, b, sweep_prev);
            const bool near_next = has_next && !is_apart(a, b, sweep_next);
            if (!near_prev && !near_next) return false;
            const bool with_prev = near_prev && !shares_end(c, prev, v);
            const bool with_next = near_next && !shares_end(c, v, next);
            const int now = (with_prev && meets(pts_[l][prev], to, a, b) ? 1 : 0) +
                            (with_next && meets(to, pts_[l][next], a, b) ? 1 : 0);
            // Allowed only as often as the old segments met it.
            if (now > 0 && now > (with_prev && meets(pts_[l][prev], p, a, b) ? 1 : 0) +
                                     (with_next && meets(p, pts_[l][next], a, b) ? 1 : 0))
                return true;
            const std::size_t ends[2] = {c.id.index, c.end_index};
            const Vec2 at[2] = {a, b};
            for (std::size_t e = 0; e < 2; ++e) {
                if (is_mover(c.id.layer, ends[e])) continue;
                const Vec2& w = at[e];
                if (near_prev && sweep_prev.contains(w) &&
                    in_closed_triangle(p, to, pts_[l][prev], w))
                    return true;
                if (near_next && sweep_next.contains(w) &&
                    in_closed_triangle(p, to, pts_[l][next], w))
                    return true;
            }
            return false;
        };
        if (blocker < candidates_.size() && refuses(candidates_[blocker])) return false;
        for (std::size_t i = 0; i < candidates_.size(); ++i) {
            if (i == blocker || !refuses(candidates_[i])) continue;
            blocker = i;
            return false;
        }
        return true;
    }

    Scene& work_;
    const std::vector<Piece>& pieces_;
    const RelationSource& relations_;
    const SeparationParams& params_;
    FinishCache* cache_ = nullptr;
    std::vector<double> moving_lengths_;  // median_length()'s scratch
    std::vector<std::vector<Vec2>> pts_;
    std::vector<char> closed_;
    std::vector<std::vector<double>> inverse_mass_;
    std::vector<double> aim_;  // n x n, 0 where unconstrained
    std::vector<Relation> relation_;
    double reach_ = 0.0;  // largest aim
    // How far from another layer a vertex on its wrong side is seen: max(reach_, the median
    // segment length of the work scene).
    double tangle_reach_ = 0.0;
    struct Nearest {
        std::size_t layer, index;  // index into found_
        double distance;
        bool is_wrong;
        int wanted;  // the side the vertex must be on (orient2d sign), 0: any
        std::size_t tip = static_cast<std::size_t>(-1);  // see hairpin_tip()
        std::size_t end = static_cast<std::size_t>(-1);  // see slipped_end()
    };
    std::vector<Nearest> nearest_;
    std::vector<std::int32_t> slot_;  // per work layer: its entry in nearest_, -1: none
    std::optional<SegmentCells> cells_;
    std::vector<SegId> active_;  // (layer, vertex) of the vertices near the free ones
    std::vector<SegId> found_;
    // A segment that gather_candidates() found, with the index of its end point and the
    // positions of its ends (nothing moves while is_safe() tests them).
    struct Candidate {
        SegId id;
        std::size_t end_index;
        Vec2 a, b;
    };
    std::vector<Candidate> candidates_;
    std::vector<double> distance_;  // from the vertex relaxed to each of found_, as found
    double worst_ = 0.0;
    std::size_t wrong_side_ = 0;
};

}  // namespace

SeparationResult finish_separations(Scene& work, const std::vector<Piece>& pieces,
                                    const RelationSource& relations, const SeparationParams& params,
                                    FinishCache* cache) {
    return Finisher(work, pieces, relations, params, cache).run();
}

}  // namespace strata::detail
