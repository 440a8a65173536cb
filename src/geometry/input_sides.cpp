#include "strata/geometry/input_sides.h"

#include "geometry/detail/segment_index.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace strata {

void validate(const InputSideParams& params) {
    if (!std::isfinite(params.reach) || params.reach < 0.0)
        throw InvalidInput("input sides: params.reach must be a finite value >= 0 (got " +
                           format_number(params.reach) + ")");
}

InputSides InputSides::renumbered(const std::vector<std::vector<std::size_t>>& origin) const {
    if (empty()) return {};
    if (origin.size() != n_)
        throw InvalidInput("input sides: renumbered() got " + std::to_string(origin.size()) +
                           " layers for " + std::to_string(n_));
    InputSides out = *this;
    out.origin_.assign(n_, {});
    for (std::size_t a = 0; a < n_; ++a) {
        const std::size_t count = vertex_count(a);
        std::vector<std::size_t>& to = out.origin_[a];
        to.reserve(origin[a].size());
        for (std::size_t k : origin[a]) {
            if (k >= count)
                throw InvalidInput("input sides: renumbered(): vertex " + std::to_string(k) +
                                   " of layer " + std::to_string(a) + " out of range (" +
                                   std::to_string(count) + " vertices)");
            to.push_back(origin_.empty() ? k : origin_[a][k]);
        }
    }
    return out;
}

namespace {

// True when segment [p, q] meets polyline `b` (its segments, closed or not).
bool meets(const Vec2& p, const Vec2& q, const Layer& b) {
    const std::size_t m = b.points.size();
    const std::size_t segments = b.closed ? m : (m > 0 ? m - 1 : 0);
    for (std::size_t j = 0; j < segments; ++j)
        if (segment_contact(p, q, b.points[j], b.points[(j + 1) % m]) != SegmentContact::None)
            return true;
    return false;
}

// Whether segments (p, q) and (u, w) of a layer other than `b` both meet one segment of b.
bool meet_same_segment(const Vec2& p, const Vec2& q, const Vec2& u, const Vec2& w, const Layer& b) {
    const std::size_t m = b.points.size();
    const std::size_t segments = b.closed ? m : (m > 0 ? m - 1 : 0);
    for (std::size_t j = 0; j < segments; ++j) {
        const Vec2& x = b.points[j];
        const Vec2& y = b.points[(j + 1) % m];
        if (segment_contact(p, q, x, y) != SegmentContact::None &&
            segment_contact(u, w, x, y) != SegmentContact::None)
            return true;
    }
    return false;
}

// The recorded sides `s` of open `layer` against open `b` with every poke taken back: a run
// of consecutive vertices on one side, entered and left by segments that meet one and the same
// segment of b (a chord of b cut across the layer, or the layer poked through b), takes the
// side of the vertices around it. A roll goes around b's end, a cut bend crosses b once.
std::vector<signed char> without_pokes(const Layer& layer, const Layer& b,
                                       const std::vector<signed char>& s) {
    std::vector<signed char> out = s;
    const std::size_t n = s.size();
    if (layer.closed || b.closed) return out;
    auto sided = [&](std::size_t k) { return s[k] == 1 || s[k] == -1; };
    for (std::size_t i = 1; i + 1 < n;) {
        if (!sided(i) || !sided(i - 1) || s[i - 1] == s[i]) {
            ++i;
            continue;
        }
        std::size_t j = i;
        while (j + 1 < n && s[j + 1] == s[i]) ++j;
        if (j + 1 < n && s[j + 1] == s[i - 1] &&
            meet_same_segment(layer.points[i - 1], layer.points[i], layer.points[j],
                              layer.points[j + 1], b))
            for (std::size_t k = i; k <= j; ++k) out[k] = s[i - 1];
        i = j + 1;
    }
    return out;
}

// A region of InputSides::by_region(): `count` consecutive vertices of a layer from `first`
// (wrapping around a closed layer), with `plus` and `minus` of them recorded on each side.
struct Region {
    std::size_t first = 0, count = 0, plus = 0, minus = 0;
};

// The regions of the vertices of `layer` with a side of layer `other` (`s`: their recorded
// codes, kBeyondEnd or 0 for none), as InputSides::by_region() documents them.
std::vector<Region> regions_of(const Layer& layer, const Layer& other,
                               const std::vector<signed char>& s) {
    const std::size_t n = s.size();
    auto has_side = [&](std::size_t k) { return s[k] == 1 || s[k] == -1; };
    // joins[k]: vertex k and the next one are in one region.
    std::vector<char> joins(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t next = k + 1 < n ? k + 1 : 0;
        if ((next == 0 && !layer.closed) || !has_side(k) || !has_side(next)) continue;
        joins[k] = s[k] == s[next] || meets(layer.points[k], layer.points[next], other);
    }
    // Start where a region starts (a closed layer's regions may wrap around).
    std::size_t start = 0;
    if (layer.closed) {
        while (start < n && joins[(start + n - 1) % n]) ++start;
        if (start == n) start = 0;  // one region around the whole loop
    }
    std::vector<Region> out;
    for (std::size_t i = 0; i < n;) {
        Region r;
        r.first = (start + i) % n;
        r.count = 1;
        while (i + r.count < n && joins[(r.first + r.count - 1) % n]) ++r.count;
        if (has_side(r.first)) {
            for (std::size_t c = 0; c < r.count; ++c)
                (s[(r.first + c) % n] > 0 ? r.plus : r.minus)++;
            out.push_back(r);
        }
        i += r.count;
    }
    return out;
}

// The majority's side of `r` (0 on a tie).
signed char majority(const Region& r) {
    return static_cast<signed char>(r.plus > r.minus ? 1 : (r.plus < r.minus ? -1 : 0));
}

// The segment of polyline q (>= 2 points) closest to p, and the parameter of the closest point
// on it (0 at q[segment], 1 at q[segment + 1]); the first of equals.
struct ClosestSegment {
    std::size_t segment = 0;
    double at = 0.0;
};
ClosestSegment closest_segment(const std::vector<Vec2>& q, const Vec2& p) {
    ClosestSegment out;
    double best = -1.0;
    for (std::size_t j = 0; j + 1 < q.size(); ++j) {
        const Vec2 d = q[j + 1] - q[j];
        const double len2 = glm::dot(d, d);
        const double t = len2 > 0.0 ? std::clamp(glm::dot(p - q[j], d) / len2, 0.0, 1.0) : 0.0;
        const Vec2 c = q[j] + t * d;
        const double dist2 = glm::dot(p - c, p - c);
        if (best < 0.0 || dist2 < best) {
            best = dist2;
            out = {j, t};
        }
    }
    return out;
}

// The side of open polyline `q` that `centre` lies on, by the rule of record_input_sides()
// (the side at the closest point; at a corner, the side of the corner's wedge); 0 when the
// closest point is an end point of `q`.
signed char polyline_side(const std::vector<Vec2>& q, const Vec2& centre) {
    if (q.size() < 2) return 0;
    const auto [segment, at] = closest_segment(q, centre);
    if ((segment == 0 && at <= 0.0) || (segment + 2 == q.size() && at >= 1.0)) return 0;
    int side = 0;
    if (at >= 1.0)
        side = corner_side(q[segment], q[segment + 1], q[segment + 2], centre);
    else if (at <= 0.0)
        side = corner_side(q[segment - 1], q[segment], q[segment + 1], centre);
    else
        side = segment_side(q[segment], q[segment + 1], centre);
    return static_cast<signed char>(side);
}

// The side of open layer `other` that the centroid of closed `layer`'s vertices lies on
// (polyline_side()).
signed char centroid_side(const Layer& layer, const Layer& other) {
    Vec2 centre(0.0);
    for (const Vec2& p : layer.points) centre += p;
    centre /= static_cast<double>(layer.points.size());
    return polyline_side(other.points, centre);
}

// The side of open layer `other` that closed `layer`'s vertices lie on by every part of
// `other` near them, not only the nearest: the sum over the vertices of `layer` and the
// segments of `other` closer than `near` whose closest point to the vertex is inside the
// segment, of the side of the segment the vertex is on (+1 right of its direction of travel);
// 0 on a tie, and 0 unless the segments counted include two that run opposite ways (a fold
// of `other` around the loop; along one arm, the centroid rule of by_region() decides). Around
// a fold both arms count: a loop inside it is on the same side of both (the fold's inside),
// where the nearest arm alone says what a chord of a decimated fold cut across it says.
signed char arms_side(const Layer& layer, const Layer& other, double near) {
    long vote = 0;
    bool fold = false;
    Vec2 first(0.0);
    const std::vector<Vec2>& q = other.points;
    for (const Vec2& v : layer.points)
        for (std::size_t j = 0; j + 1 < q.size(); ++j) {
            const Vec2 d = q[j + 1] - q[j];
            const double len2 = glm::dot(d, d);
            if (!(len2 > 0.0)) continue;
            const double t = glm::dot(v - q[j], d) / len2;
            if (t < 0.0 || t > 1.0) continue;
            const Vec2 c = q[j] + t * d;
            if (glm::dot(v - c, v - c) > near * near) continue;
            vote += segment_side(q[j], q[j + 1], v);
            if (first == Vec2(0.0))
                first = d;
            else if (glm::dot(first, d) < 0.0)
                fold = true;
        }
    if (!fold) return 0;
    return static_cast<signed char>(vote > 0 ? 1 : (vote < 0 ? -1 : 0));
}

// The diagonal of `layer`'s bounding box.
double diagonal(const Layer& layer) {
    const Vec2 size = layer.bounds().size();
    return std::hypot(size.x, size.y);
}

// The vertices where open `layer` turns back around an end of open layer `other`: vertex k
// within `within` of an end point of `other` (the one nearer to it) and nearest to that end's
// segment of `other` (not to a fold of `other` near its end), reached by a segment that runs
// out past that end (the way `other`'s end segment runs out) and left by one that does not. A layer
// that goes around the end of another without crossing it comes back on its other side: its parts
// between such turns lie on the other's sides in turn (whether the vertices around the bend are
// closest to the end point, or the decimation cut the bend across the other layer).
std::vector<std::size_t> turns_around_end(const Layer& layer, const Layer& other, double within) {
    std::vector<std::size_t> out;
    const std::vector<Vec2>& p = layer.points;
    const std::vector<Vec2>& q = other.points;
    if (layer.closed || other.closed || q.size() < 2) return out;
    for (std::size_t k = 1; k + 1 < p.size(); ++k) {
        const Vec2 v = p[k];
        const bool at_last =
            glm::dot(v - q.back(), v - q.back()) <= glm::dot(v - q.front(), v - q.front());
        const Vec2 end = at_last ? q.back() : q.front();
        if (glm::dot(v - end, v - end) > within * within) continue;
        const Vec2 out_way = at_last ? q[q.size() - 1] - q[q.size() - 2] : q[0] - q[1];
        if (!(glm::dot(p[k] - p[k - 1], out_way) > 0.0 &&
              glm::dot(p[k + 1] - p[k], out_way) <= 0.0))
            continue;
        // Around that end, not a fold of both layers near it: the segment of `other` nearest
        // to the vertex is its end segment.
        if (closest_segment(q, v).segment == (at_last ? q.size() - 2 : 0)) out.push_back(k);
    }
    return out;
}

}  // namespace

InputSides InputSides::by_region(const Scene& scene, const std::vector<int>& outside_sides) const {
    return from_codes(scene, region_codes(scene, outside_sides, nullptr));
}

std::vector<std::vector<signed char>> InputSides::region_codes(
    const Scene& scene, const std::vector<int>& outside_sides,
    std::vector<Alternative>* split) const {
    if (n_ != scene.size())
        throw InvalidInput("input sides: by_region() got a scene of " +
                           std::to_string(scene.size()) + " layers for " + std::to_string(n_));
    if (!outside_sides.empty() && outside_sides.size() != n_)
        throw InvalidInput("input sides: by_region() got " + std::to_string(outside_sides.size()) +
                           " outside sides for " + std::to_string(n_) + " layers");
    std::vector<std::vector<signed char>> codes(n_ * n_);
    double near = -1.0;  // automatic_near_distance(scene), when first needed
    for (std::size_t a = 0; a < n_; ++a)
        for (std::size_t b = 0; b < n_; ++b) {
            const Layer& layer = scene.layer(a);
            const std::size_t n = layer.points.size();
            if (a == b || n == 0 || vertex_count(a) != n) continue;
            std::vector<signed char>& s = codes[a * n_ + b];
            bool any = false;
            for (std::size_t k = 0; k < n; ++k) {
                s.push_back(static_cast<signed char>(code(a, k, b)));
                any = any || s.back() != 0;
            }
            if (!any) {
                s.clear();
                continue;
            }
            const std::vector<signed char> recorded = s;
            const std::vector<Region> regions = regions_of(layer, scene.layer(b), recorded);
            // turns_around_end() of the layer around b's ends, when first needed (by both rules
            // below).
            std::optional<std::vector<std::size_t>> turns;
            std::optional<std::vector<signed char>> unpoked;  // without_pokes(), when needed
            auto turns_of = [&]() -> const std::vector<std::size_t>& {
                if (!turns) {
                    if (near < 0.0) near = automatic_near_distance(scene);
                    turns = turns_around_end(layer, scene.layer(b), detail::kSideReach * near);
                }
                return *turns;
            };
            for (const Region& r : regions) {
                signed char side = majority(r);
                // A closed layer all of whose vertices form one region (a loop within reach
                // of the other layer, e.g. a cord in a fold) and whose vertices disagree: the
                // side its shape lies on (its vertex centroid's), not its vertices' vote.
                // Only for a loop at most half the open layer's size (bounding-box
                // diagonals), one that a fold of it can hold: a loop about as large as the
                // open layer is wrapped by all of it (a skirt's tier inside a tier left open
                // at a seam), and its centroid's closest point there says nothing.
                if (layer.closed && r.count == n && r.plus > 0 && r.minus > 0 &&
                    !scene.layer(b).closed && diagonal(layer) <= 0.5 * diagonal(scene.layer(b))) {
                    const signed char bulk = centroid_side(layer, scene.layer(b));
                    if (bulk != 0) side = bulk;
                }
                for (std::size_t c = 0; c < r.count; ++c) s[(r.first + c) % n] = side;
                if (!split || r.plus == 0 || r.minus == 0) continue;
                // No split where the disagreeing vertices are pokes (without_pokes()).
                bool poked_only = false;
                if (!layer.closed && !scene.layer(b).closed) {
                    if (!unpoked) unpoked = without_pokes(layer, scene.layer(b), recorded);
                    std::size_t plus = 0, minus = 0;
                    for (std::size_t c = 0; c < r.count; ++c) {
                        const signed char v = (*unpoked)[(r.first + c) % n];
                        plus += v == 1;
                        minus += v == -1;
                    }
                    poked_only = plus == 0 || minus == 0;
                }
                // The region read otherwise: an open layer's region split in two where the
                // two runs fit the recorded sides best, if that fits better than one side.
                const std::size_t one = std::max(r.plus, r.minus);
                std::size_t best = one, cut = 0;
                signed char before = 0, after = 0;
                if (!layer.closed) {
                    Region head, tail = r;
                    for (std::size_t c = 1; c < r.count; ++c) {
                        const bool plus = recorded[r.first + c - 1] > 0;
                        ++(plus ? head.plus : head.minus);
                        --(plus ? tail.plus : tail.minus);
                        const signed char h = majority(head), t = majority(tail);
                        const std::size_t fit =
                            std::max(head.plus, head.minus) + std::max(tail.plus, tail.minus);
                        if (h != 0 && t != 0 && h != t && fit > best) {
                            best = fit;
                            cut = c;
                            before = h;
                            after = t;
                        }
                    }
                }
                auto add = [&](std::size_t fit, auto side_at) {
                    Alternative alt;
                    alt.pair = a * n_ + b;
                    alt.first = r.first;
                    const std::size_t kept =
                        side > 0 ? r.plus : (side < 0 ? r.minus : std::max(r.plus, r.minus));
                    alt.score = (static_cast<double>(fit) - static_cast<double>(kept)) /
                                static_cast<double>(r.count);
                    for (std::size_t c = 0; c < r.count; ++c) alt.sides.push_back(side_at(c));
                    split->push_back(std::move(alt));
                };
                if (cut > 0 && poked_only) continue;
                if (cut > 0)
                    add(best, [&](std::size_t c) { return c < cut ? before : after; });
                else if (side != 0)  // otherwise the other side
                    add(side > 0 ? r.minus : r.plus,
                        [&](std::size_t) { return static_cast<signed char>(-side); });
                else
                    for (const int either : {1, -1})
                        add(one, [&](std::size_t) { return static_cast<signed char>(either); });
            }
            // A closed loop at most half the open layer's size (as above) with vertices within
            // reach: all of it (but vertices around b's end) on the side its vertices are on by
            // every arm of the layer near them (arms_side()), when that is not a tie. A loop
            // lies on one side of a layer: a vertex out of reach too.
            const bool small = layer.closed && diagonal(layer) <= 0.5 * diagonal(scene.layer(b));
            if (small && !scene.layer(b).closed) {
                if (near < 0.0) near = automatic_near_distance(scene);
                if (const signed char arms = arms_side(layer, scene.layer(b), near); arms != 0)
                    for (signed char& c : s)
                        if (c != kBeyondEnd) c = arms;
            }
            // A region of an open layer read on the other side than the global order's, next
            // to one on the global order's side with no turn around b's end (turns_around_end())
            // in their span: the layer did not go around b to get there, so the reading is a
            // tangle's (a chord of b cut across it), and the region takes the global order's
            // side.
            if (!outside_sides.empty() && !layer.closed && !scene.layer(b).closed &&
                regions.size() > 1) {
                const int wanted = global_side(scene.relation(a, b), outside_sides[b]);
                auto turn_in = [&](const Region& lo, const Region& hi) {
                    for (const std::size_t k : turns_of())
                        if (k >= lo.first && k < hi.first + hi.count) return true;
                    return false;
                };
                std::vector<char> untangled(regions.size(), 0);
                for (std::size_t i = 0; wanted != 0 && i < regions.size(); ++i) {
                    if (s[regions[i].first] != -wanted) continue;
                    const bool before = i > 0 && s[regions[i - 1].first] == wanted &&
                                        !turn_in(regions[i - 1], regions[i]);
                    const bool after = i + 1 < regions.size() &&
                                       s[regions[i + 1].first] == wanted &&
                                       !turn_in(regions[i], regions[i + 1]);
                    untangled[i] = before || after;
                }
                for (std::size_t i = 0; i < regions.size(); ++i)
                    if (untangled[i])
                        for (std::size_t c = 0; c < regions[i].count; ++c)
                            s[regions[i].first + c] = static_cast<signed char>(wanted);
            }
            // An open layer all of whose vertices with a side are read on the other side than
            // the global order's: not a roll (a roll is part of a layer, the rest on the global
            // order's side) but the two layers' order read inside out (a tangle that put most
            // of a layer across its neighbour). The global order's side.
            // A closed layer larger than half the open one (no fold of it can hold the loop,
            // as above): the same, its whole loop read on the other side is their order read
            // inside out (a shirt's chord cut across the body it wraps).
            const bool large = layer.closed && !small;
            if (!outside_sides.empty() && (!layer.closed || large) && !scene.layer(b).closed) {
                const int wanted = global_side(scene.relation(a, b), outside_sides[b]);
                bool swapped = wanted != 0;
                bool sided = false;
                for (const signed char c : s) {
                    if (c != 1 && c != -1) continue;
                    sided = true;
                    swapped = swapped && c != wanted;
                }
                // Part of such a closed layer read on the other side, the rest on the global
                // order's: no fold of b holds any part of it either, so that part may be a
                // tangle (a chord of b cut across it, or its vertices nearest b's roll once the
                // decimation took the part of b between them), but a real scene can have it so
                // (mh_elegantsuit01 at 2.5 dm: both arms in part over the ends of the sleeve
                // pieces half wrapping them, clean as read). Another reading, the first: all
                // of it on the global order's side.
                if (split && large && sided && !swapped && wanted != 0) {
                    Alternative all_global;
                    all_global.pair = a * n_ + b;
                    all_global.score = 2.0;  // above every region's (at most 1)
                    for (const signed char c : s)
                        all_global.sides.push_back(
                            c == 1 || c == -1 ? static_cast<signed char>(wanted) : c);
                    split->push_back(std::move(all_global));
                }
                if (sided && swapped) {
                    // Unless the layer turns back around b's end (turns_around_end(), within
                    // the reach of the sides): then its parts between the turns lie on b's
                    // sides in turn, and one of them at least is read wrong. The reading
                    // that alternates with more vertices recorded with a side on the global
                    // order's side (a roll is part of a layer, the rest on that side); a tie:
                    // all on the global order's side, as without a turn.
                    const std::vector<std::size_t>& turn = turns_of();
                    std::vector<int> part(n, 0);  // the number of turns before, modulo 2
                    std::size_t even = 0, odd = 0;
                    // The first vertex after each turn: the one after the turn vertex, or the
                    // turn vertex itself where the segment that reaches it meets b (the bend
                    // cut across b: that segment is the tangle, and the turn vertex lies on
                    // the side of the part after it, joined to it by a segment that does not
                    // meet b).
                    std::vector<std::size_t> after;
                    for (const std::size_t k : turn)
                        after.push_back(
                            meets(layer.points[k - 1], layer.points[k], scene.layer(b)) &&
                                    !meets(layer.points[k], layer.points[k + 1], scene.layer(b))
                                ? k
                                : k + 1);
                    for (std::size_t k = 0, t = 0; k < n; ++k) {
                        while (t < after.size() && after[t] <= k) ++t;
                        part[k] = static_cast<int>(t % 2);
                        if (recorded[k] == 1 || recorded[k] == -1) ++(t % 2 == 0 ? even : odd);
                    }
                    const int rolled = turn.empty() || even == odd ? -1 : (even > odd ? 1 : 0);
                    for (std::size_t k = 0; k < n; ++k)
                        if ((s[k] == 1 || s[k] == -1) && part[k] != rolled)
                            s[k] = static_cast<signed char>(wanted);
                }
            }
        }
    return codes;
}

std::vector<InputSides> InputSides::region_alternatives(
    const Scene& scene, const std::vector<int>& outside_sides) const {
    std::vector<Alternative> alternatives;
    const std::vector<std::vector<signed char>> codes =
        region_codes(scene, outside_sides, &alternatives);
    std::stable_sort(alternatives.begin(), alternatives.end(),
                     [](const Alternative& x, const Alternative& y) { return x.score > y.score; });
    std::vector<InputSides> out;
    out.reserve(alternatives.size());
    for (const Alternative& alt : alternatives) {
        std::vector<std::vector<signed char>> changed = codes;
        std::vector<signed char>& s = changed[alt.pair];
        for (std::size_t c = 0; c < alt.sides.size(); ++c)
            s[(alt.first + c) % s.size()] = alt.sides[c];
        out.push_back(from_codes(scene, std::move(changed)));
    }
    return out;
}

InputSides infer_input_sides(const Scene& scene, const InputSideParams& params,
                             const std::vector<int>& outside_sides) {
    return record_input_sides(scene, params).by_region(scene, outside_sides);
}

std::size_t InputSides::rolled_count(const Scene& scene,
                                     const std::vector<int>& outside_sides) const {
    std::size_t count = 0;
    for (std::size_t a = 0; a < n_ && a < scene.size(); ++a)
        for (std::size_t b = 0; b < n_ && b < outside_sides.size(); ++b) {
            if (a == b) continue;
            const int wanted = global_side(scene.relation(a, b), outside_sides[b]);
            const std::size_t vertices = std::min(vertex_count(a), scene.layer(a).points.size());
            for (std::size_t k = 0; k < vertices; ++k) {
                const int s = side(a, k, b);
                if (s != 0 && s != wanted) ++count;
            }
        }
    return count;
}

int global_side(Relation relation_of_a_to_b, int outside) {
    switch (relation_of_a_to_b) {
        case Relation::Under:
            return -outside;
        case Relation::Over:
            return outside;
        default:
            return 0;
    }
}

using detail::automatic_near;
using detail::kSideReach;
using detail::Nearest;
using detail::nearest_on;
using detail::SegmentIndex;
using detail::side_of;

// The recorded sides: decided by the nearest queries and the side rule of check_scene()
// (geometry/detail/segment_index.h).
struct InputSides::Recorded {
    static constexpr signed char kUnknown = 3;  // not found yet

    Scene scene;
    double reach = 0.0;
    std::size_t n = 0;
    // memo[a * n + b][k]: the code of vertex k of layer a against open layer b (kUnknown
    // until asked for); null where nothing is recorded (b closed, side by side, out of reach).
    std::vector<std::unique_ptr<std::atomic<signed char>[]>> memo;
    // The segment index of each open layer, built when first needed.
    mutable std::vector<std::unique_ptr<SegmentIndex>> indices;
    std::unique_ptr<std::once_flag[]> built;

    const SegmentIndex& index(std::size_t b) const {
        std::call_once(built[b],
                       [&] { indices[b] = std::make_unique<SegmentIndex>(scene.layer(b)); });
        return *indices[b];
    }

    int code(std::size_t a, std::size_t k, std::size_t b) const {
        const std::unique_ptr<std::atomic<signed char>[]>& found = memo[a * n + b];
        const std::vector<Vec2>& points = scene.layer(a).points;
        if (!found || k >= points.size()) return 0;
        signed char c = found[k].load(std::memory_order_relaxed);
        if (c != kUnknown) return c;
        // Threads that ask at once find the same value.
        const SegmentIndex& other = index(b);
        // Callers ask vertex after vertex: each thread's search starts where its last one
        // ended on the same layer (the result does not depend on where it starts).
        thread_local SegmentIndex::Cursor cursor;
        const Nearest nr = nearest_on(other, points[k], reach, &cursor);
        const int side = side_of(other, points[k], nr);
        // Found, not on b, and no side: closest to an end point of b.
        c = side == 0 && nr.found() && nr.distance > 0.0 ? InputSides::kBeyondEnd
                                                         : static_cast<signed char>(side);
        found[k].store(c, std::memory_order_relaxed);
        return c;
    }
};

InputSides record_input_sides(const Scene& scene, const InputSideParams& params) {
    validate(params);
    auto r = std::make_shared<InputSides::Recorded>();
    r->scene = scene;
    r->reach = params.reach > 0.0 ? params.reach : kSideReach * automatic_near(scene);
    const std::size_t n = scene.size();
    r->n = n;
    r->memo.resize(n * n);
    r->indices.resize(n);
    r->built = std::make_unique<std::once_flag[]>(n);
    std::vector<Box2> bounds;
    for (std::size_t i = 0; i < n; ++i) bounds.push_back(scene.layer(i).bounds());
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b) {
            const Relation rel = a == b ? Relation::Same : scene.relation(a, b);
            if (scene.layer(b).closed || (rel != Relation::Under && rel != Relation::Over) ||
                !bounds[a].overlaps(bounds[b].inflated(r->reach)))
                continue;
            const std::size_t count = scene.layer(a).points.size();
            auto& found = r->memo[a * n + b];
            found = std::make_unique<std::atomic<signed char>[]>(count);
            for (std::size_t k = 0; k < count; ++k)
                found[k].store(InputSides::Recorded::kUnknown, std::memory_order_relaxed);
        }
    InputSides out;
    out.n_ = n;
    out.recorded_ = std::move(r);
    return out;
}

InputSides InputSides::from_codes(const Scene& scene, std::vector<std::vector<signed char>> codes) {
    auto r = std::make_shared<InputSides::Recorded>();
    r->scene = scene;
    const std::size_t n = scene.size();
    r->n = n;
    r->memo.resize(n * n);
    r->indices.resize(n);
    r->built = std::make_unique<std::once_flag[]>(n);
    for (std::size_t p = 0; p < n * n && p < codes.size(); ++p) {
        const std::vector<signed char>& from = codes[p];
        if (from.empty()) continue;
        // Every code known: no query is ever made.
        const std::size_t count = scene.layer(p / n).points.size();
        auto& found = r->memo[p];
        found = std::make_unique<std::atomic<signed char>[]>(count);
        for (std::size_t k = 0; k < count; ++k)
            found[k].store(k < from.size() ? from[k] : 0, std::memory_order_relaxed);
    }
    InputSides out;
    out.n_ = n;
    out.recorded_ = std::move(r);
    return out;
}

int InputSides::code(std::size_t a, std::size_t k, std::size_t b) const {
    if (a >= n_ || b >= n_ || !recorded_) return 0;
    if (!origin_.empty()) {
        if (k >= origin_[a].size()) return 0;
        k = origin_[a][k];
    }
    if (!layer_.empty()) {
        a = layer_[a];
        b = layer_[b];
        if (a == kNoLayer || b == kNoLayer) return 0;
    }
    return recorded_->code(a, k, b);
}

std::size_t InputSides::vertex_count(std::size_t a) const {
    if (a >= n_ || !recorded_) return 0;
    if (!origin_.empty()) return origin_[a].size();
    const std::size_t r = layer_.empty() ? a : layer_[a];
    return r == kNoLayer ? 0 : recorded_->scene.layer(r).points.size();
}

std::vector<std::vector<signed char>> InputSides::codes_for(const Scene& scene,
                                                            const char* what) const {
    if (scene.size() != n_)
        throw InvalidInput(std::string("input sides: ") + what + " got " +
                           std::to_string(scene.size()) + " layers for " + std::to_string(n_));
    std::vector<std::vector<signed char>> codes(n_ * n_);
    for (std::size_t a = 0; a < n_; ++a)
        for (std::size_t b = 0; b < n_; ++b) {
            if (a == b) continue;
            std::vector<signed char>& out = codes[a * n_ + b];
            for (std::size_t k = 0; k < scene.layer(a).points.size(); ++k) {
                const int c = code(a, k, b);
                if (c == 0 && out.empty()) continue;
                out.resize(scene.layer(a).points.size(), 0);
                out[k] = static_cast<signed char>(c);
            }
        }
    return codes;
}

InputSides InputSides::without_end_sides(const Scene& scene) const {
    if (empty()) return {};
    std::vector<std::vector<signed char>> codes = codes_for(scene, "without_end_sides()");
    for (std::vector<signed char>& pair : codes)
        for (signed char& c : pair)
            if (c == kBeyondEnd) c = 0;
    return from_codes(scene, std::move(codes));
}

std::vector<InputSides> InputSides::loop_readings(const Scene& scene) const {
    if (empty()) return {};
    const std::vector<std::vector<signed char>> codes = codes_for(scene, "loop_readings()");
    std::vector<InputSides> readings;
    for (std::size_t a = 0; a < n_; ++a)
        for (std::size_t b = 0; b < n_; ++b) {
            const Layer& loop = scene.layer(a);
            const Layer& other = scene.layer(b);
            if (a == b || !loop.closed || other.closed || other.points.size() < 2 ||
                diagonal(loop) > 0.5 * diagonal(other))
                continue;
            const std::vector<signed char>& s = codes[a * n_ + b];
            const auto plus = std::count(s.begin(), s.end(), static_cast<signed char>(1));
            const auto minus = std::count(s.begin(), s.end(), static_cast<signed char>(-1));
            if (plus == 0 || minus == 0) continue;
            const signed char first = plus >= minus ? 1 : -1;
            for (const signed char side : {first, static_cast<signed char>(-first)}) {
                std::vector<std::vector<signed char>> changed = codes;
                for (signed char& c : changed[a * n_ + b])
                    if (c == 1 || c == -1) c = side;
                readings.push_back(from_codes(scene, std::move(changed)));
            }
        }
    return readings;
}

InputSides InputSides::off_other_sheets(const Scene& scene) const {
    if (empty()) return {};
    const Recorded& rec = *recorded_;
    std::vector<std::vector<signed char>> codes = codes_for(scene, "off_other_sheets()");
    std::vector<std::unique_ptr<SegmentIndex>> indices(n_);
    for (std::size_t a = 0; a < n_; ++a)
        for (std::size_t b = 0; b < n_; ++b) {
            if (a == b || scene.layer(b).closed || scene.layer(b).points.size() < 2) continue;
            const std::vector<Vec2>& points = scene.layer(a).points;
            std::vector<signed char>& out = codes[a * n_ + b];
            for (std::size_t k = 0; k < out.size(); ++k) {
                const int c = out[k];
                if (c != 1 && c != -1) continue;
                if (!indices[b]) indices[b] = std::make_unique<SegmentIndex>(scene.layer(b));
                const Nearest now = nearest_on(*indices[b], points[k]);
                if (side_of(*indices[b], points[k], now) != -c) continue;
                // The recorded vertex and its closest segment of b there.
                std::size_t ra = a, rb = b, rk = k;
                if (!layer_.empty()) ra = layer_[a], rb = layer_[b];
                if (!origin_.empty()) rk = origin_[a][k];
                if (rk >= rec.scene.layer(ra).points.size()) continue;
                const Vec2 rp = rec.scene.layer(ra).points[rk];
                const SegmentIndex& rindex = rec.index(rb);
                const Nearest then = nearest_on(rindex, rp);
                if (!now.found() || !then.found()) continue;
                const Vec2 d_now = indices[b]->end(now.segment) - indices[b]->start(now.segment);
                const Vec2 d_then = rindex.end(then.segment) - rindex.start(then.segment);
                if (glm::dot(d_now, d_then) >= 0.0) continue;
                // The stretch of b in the recorded scene between the recorded vertices of the
                // ends of that segment: a vertex between a fold's sheets (a roll's jacket) has
                // its side of both, and keeps it; one outside the fold does not.
                std::size_t lo = now.segment, hi = now.segment + 1;
                if (!origin_.empty()) lo = origin_[b][lo], hi = origin_[b][hi];
                if (lo > hi) std::swap(lo, hi);
                const std::vector<Vec2>& rq = rec.scene.layer(rb).points;
                if (hi >= rq.size()) continue;
                const std::vector<Vec2> stretch(rq.begin() + static_cast<std::ptrdiff_t>(lo),
                                                rq.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
                if (polyline_side(stretch, rp) == -c) out[k] = kBeyondEnd;
            }
        }
    return from_codes(scene, std::move(codes));
}

namespace {

// InputSides::matched()'s reordering of the matches `match` of `points` (open layer) onto
// the reference layer `ref`: see there. `exact`: the vertex is its matched reference vertex.
void match_in_order(const std::vector<Vec2>& points, const std::vector<Vec2>& ref,
                    const std::vector<char>& exact, std::vector<std::size_t>& match) {
    const std::size_t n = points.size();
    std::size_t j = 0;
    std::size_t lo = 0;  // the reference index of the last unmoved vertex (0: none yet)
    while (j < n) {
        if (exact[j]) {
            lo = match[j];
            ++j;
            continue;
        }
        std::size_t e = j;
        while (e < n && !exact[e]) ++e;
        const std::size_t hi = e < n ? match[e] : ref.size() - 1;
        bool ordered = lo <= hi;
        for (std::size_t k = j; k < e && ordered; ++k)
            ordered = match[k] >= lo && match[k] <= hi && (k == j || match[k - 1] <= match[k]);
        if (!ordered && lo <= hi &&
            static_cast<double>(hi - lo + 1) * static_cast<double>(e - j) <= 4e6) {
            // Candidates per vertex, by reference index; Viterbi over increasing indices (each
            // vertex of a simplification is a reference vertex of its own, in order).
            struct Cand {
                std::size_t k;
                double d, cost;
                std::size_t from;
            };
            std::vector<std::vector<Cand>> cands(e - j);
            std::vector<double> distance(hi - lo + 1);  // of vertex v to reference vertex lo + i
            for (std::size_t v = j; v < e; ++v) {
                for (std::size_t k = lo; k <= hi; ++k)
                    distance[k - lo] = std::hypot(points[v].x - ref[k].x, points[v].y - ref[k].y);
                const double nearest = *std::min_element(distance.begin(), distance.end());
                std::vector<Cand>& c = cands[v - j];
                for (std::size_t k = lo; k <= hi; ++k)
                    if (distance[k - lo] <= 3.0 * nearest)
                        c.push_back({k, distance[k - lo], detail::kFar, detail::kNoSegment});
                if (c.size() > 16) {
                    std::nth_element(c.begin(), c.begin() + 16, c.end(),
                                     [](const Cand& x, const Cand& y) { return x.d < y.d; });
                    c.resize(16);
                }
                // Each other sheet of the stretch passing near the vertex (a local minimum of
                // the distance along the reference, beyond the band above): its nearest
                // vertex and two on either side, so that the order can put the vertex on the
                // sheet it belongs to even when it moved nearer another one (the end of a
                // roll pulled toward the layer's main part).
                std::vector<std::size_t> minima;
                for (std::size_t k = lo; k <= hi; ++k) {
                    const double d = distance[k - lo];
                    if (d > 3.0 * nearest && (k == lo || d <= distance[k - 1 - lo]) &&
                        (k == hi || d < distance[k + 1 - lo]))
                        minima.push_back(k);
                }
                const std::size_t sheets = std::min<std::size_t>(minima.size(), 4);
                std::partial_sort(minima.begin(),
                                  minima.begin() + static_cast<std::ptrdiff_t>(sheets),
                                  minima.end(), [&](std::size_t x, std::size_t y) {
                                      return distance[x - lo] < distance[y - lo];
                                  });
                for (std::size_t m = 0; m < sheets; ++m)
                    for (std::size_t k = minima[m] - std::min<std::size_t>(minima[m] - lo, 2);
                         k <= std::min(hi, minima[m] + 2); ++k)
                        c.push_back({k, distance[k - lo], detail::kFar, detail::kNoSegment});
                std::sort(c.begin(), c.end(),
                          [](const Cand& x, const Cand& y) { return x.k < y.k; });
                c.erase(std::unique(c.begin(), c.end(),
                                    [](const Cand& x, const Cand& y) { return x.k == y.k; }),
                        c.end());
            }
            // The cost of a match: its distance, plus how differently from the previous vertex
            // the vertex moved (the untangling moves neighbours alike; on a roll, whose sheets
            // run opposite ways, a run moved nearer the other sheet keeps its own).
            auto moved_apart = [&](std::size_t v, std::size_t k, std::size_t pk) {
                return std::hypot(points[v].x - ref[k].x - (points[v - 1].x - ref[pk].x),
                                  points[v].y - ref[k].y - (points[v - 1].y - ref[pk].y));
            };
            for (Cand& c : cands[0]) c.cost = c.d + (j > 0 ? moved_apart(j, c.k, match[j - 1]) : 0.0);
            for (std::size_t r = 1; r < cands.size(); ++r)
                for (Cand& c : cands[r])
                    for (std::size_t q = 0; q < cands[r - 1].size(); ++q) {
                        const Cand& p = cands[r - 1][q];
                        if (p.k >= c.k) continue;
                        const double cost = p.cost + c.d + moved_apart(j + r, c.k, p.k);
                        if (cost < c.cost) {
                            c.cost = cost;
                            c.from = q;
                        }
                    }
            std::size_t best = detail::kNoSegment;
            for (std::size_t q = 0; q < cands.back().size(); ++q)
                if (cands.back()[q].cost < detail::kFar &&
                    (best == detail::kNoSegment || cands.back()[q].cost < cands.back()[best].cost))
                    best = q;
            for (std::size_t r = cands.size(); best != detail::kNoSegment && r-- > 0;) {
                match[j + r] = cands[r][best].k;
                best = cands[r][best].from;
            }
        }
        j = e;
    }
}

}  // namespace

InputSides InputSides::matched(const InputSides& recorded, const Scene& reference,
                               const Scene& scene) {
    InputSides out;
    if (recorded.empty()) return out;
    const std::size_t n = scene.size();
    out.n_ = n;
    out.recorded_ = recorded.recorded_;
    out.layer_.assign(n, kNoLayer);
    out.origin_.assign(n, {});
    for (std::size_t a = 0; a < n; ++a) {
        const std::optional<std::size_t> namesake = reference.find(scene.layer(a).name);
        if (!namesake || *namesake >= recorded.n_) continue;
        const std::size_t ra = *namesake;
        out.layer_[a] = recorded.layer_.empty() ? ra : recorded.layer_[ra];
        if (out.layer_[a] == kNoLayer) continue;
        const Layer& ref_layer = reference.layer(ra);
        const SegmentIndex index(ref_layer);
        const std::vector<Vec2>& ref = ref_layer.points;
        const std::vector<Vec2>& points = scene.layer(a).points;
        // The reference vertex of each vertex of layer a: the nearer end of its closest segment.
        std::vector<std::size_t> match(points.size(), 0);
        std::vector<char> exact(points.size(), 0);  // the vertex is that reference vertex
        for (std::size_t j = 0; j < points.size(); ++j) {
            const Nearest nr = nearest_on(index, points[j]);
            if (!nr.found()) continue;
            const Vec2 s0 = index.start(nr.segment), s1 = index.end(nr.segment);
            const bool first = std::hypot(nr.point.x - s0.x, nr.point.y - s0.y) <=
                               std::hypot(nr.point.x - s1.x, nr.point.y - s1.y);
            match[j] = first ? nr.segment : (nr.segment + 1) % ref.size();
            exact[j] = points[j] == ref[match[j]];
        }
        // A simplification keeps its vertices in their order. Where the matches of a run of
        // vertices that moved (untangled) between two that did not are out of that order (a
        // vertex closest to another sheet of a roll, nearer than it moved), the run takes the
        // reference vertices in order, between those of its unmoved ends, that are nearest in
        // all (each vertex choosing among the reference vertices within 3 times its nearest
        // one's distance and the nearest ones of the 4 nearest other sheets of the stretch;
        // runs whose stretch times length exceeds 4e6 keep their matches).
        if (!ref_layer.closed) match_in_order(points, ref, exact, match);
        std::vector<std::size_t>& origin = out.origin_[a];
        for (std::size_t k : match) {
            if (!recorded.origin_.empty())
                k = k < recorded.origin_[ra].size() ? recorded.origin_[ra][k] : kNoLayer;
            origin.push_back(k);
        }
    }
    return out;
}

}  // namespace strata
