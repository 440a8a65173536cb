#pragma once
/// @file Exact geometric predicates on double coordinates.
///
/// orient2d uses a floating-point filter and falls back to exact rational arithmetic when the
/// filter cannot decide, so its sign is always the sign of the exact determinant.

#include "strata/core/types.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace strata {

namespace detail {
/// orient2d() by exact rational arithmetic.
int orient2d_exact(const Vec2& a, const Vec2& b, const Vec2& c);
}  // namespace detail

/// Sign of the area of triangle (a, b, c): +1 counter-clockwise (c left of a->b), -1
/// clockwise, 0 collinear. Exact: the floating-point filter below (inline: the checks call it
/// hundreds of thousands of times) decides almost every case, exact arithmetic the rest.
inline int orient2d(const Vec2& a, const Vec2& b, const Vec2& c) {
    const double left = (a.x - c.x) * (b.y - c.y);
    const double right = (a.y - c.y) * (b.x - c.x);
    const double det = left - right;
    const double sum = std::fabs(left) + std::fabs(right);
    // Products far from underflow and overflow (NaN fails both tests): Shewchuk's bound for
    // the first stage, (3 + 16 eps) eps with eps = 2^-53, holds.
    if (sum > 1e-280 && sum < 1e280) {
        constexpr double kEpsilon = 0x1p-53;
        const double bound = (3.0 + 16.0 * kEpsilon) * kEpsilon * sum;
        if (det > bound) return 1;
        if (-det > bound) return -1;
    }
    return detail::orient2d_exact(a, b, c);
}

/// How two closed segments meet. Exact.
enum class SegmentContact {
    None,    ///< Disjoint.
    Proper,  ///< The interiors cross at one point that is an end of neither segment.
    Touch,   ///< They share a point that is an end of one of them, or overlap collinearly.
};

namespace detail {
/// segment_contact() of segments whose boxes meet.
SegmentContact segment_contact_in_boxes(const Vec2& p0, const Vec2& p1, const Vec2& q0,
                                        const Vec2& q1);
}  // namespace detail

/// Exact classification of segments [p0, p1] and [q0, q1]. The box test is inline: most
/// segments a caller asks about (near a move, in a grid cell) are apart.
inline SegmentContact segment_contact(const Vec2& p0, const Vec2& p1, const Vec2& q0,
                                      const Vec2& q1) {
    // Quick reject on the bounding boxes (exact comparisons).
    if (std::max(p0.x, p1.x) < std::min(q0.x, q1.x) ||
        std::max(q0.x, q1.x) < std::min(p0.x, p1.x) ||
        std::max(p0.y, p1.y) < std::min(q0.y, q1.y) || std::max(q0.y, q1.y) < std::min(p0.y, p1.y))
        return SegmentContact::None;
    return detail::segment_contact_in_boxes(p0, p1, q0, q1);
}

/// Contribution of the directed segment a -> b to the winding number of a closed polyline
/// around p, by the crossing rule (the ray from p toward +x; each segment half-open in y):
/// +1 when the segment goes up across the ray with p on its left, -1 when it goes down across
/// it with p on its right, 0 otherwise. Summed over the segments of a closed polyline that
/// does not pass through p: its winding number around p. Exact.
int winding_contribution(const Vec2& a, const Vec2& b, const Vec2& p);

/// The change of the winding number of a closed polyline around a point that moves along
/// p0 -> p1, due to the polyline's segment a -> b: +1 when the path crosses it from its right
/// to its left through the interiors of both, -1 the other way, 0 when they do not meet;
/// std::nullopt when they touch (an end of one on the other, or a collinear overlap), where
/// the change is not decided segment by segment. Summed over the polyline's segments (none
/// nullopt): winding(p1) - winding(p0). Exact.
std::optional<int> winding_change_across(const Vec2& p0, const Vec2& p1, const Vec2& a,
                                         const Vec2& b);

/// Intersection point of the supporting lines of two properly crossing segments (rounded).
Vec2 crossing_point(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1);

/// Distance from `p` to segment [a, b], and the closest point of the segment. Inline: the
/// nearest-segment queries of the checks and the fields call it in their innermost loops.
inline double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b,
                                     Vec2* closest = nullptr) {
    const Vec2 d = b - a;
    const double len2 = d.x * d.x + d.y * d.y;
    Vec2 c = a;
    if (len2 > 0.0) {
        const Vec2 w = p - a;
        const double t = (w.x * d.x + w.y * d.y) / len2;
        if (t >= 1.0)
            c = b;
        else if (t > 0.0)
            c = a + t * d;
    }
    if (closest) *closest = c;
    const double dx = p.x - c.x, dy = p.y - c.y;
    return std::sqrt(dx * dx + dy * dy);
}

/// p lies in the closed triangle (a, b, c), exactly. The box test comes first: it is exact,
/// rejects most points without a predicate, and is what decides for a flat triangle (collinear
/// a, b, c), where every point of the line through them has three zero orientations.
/// `box`: the box of a, b and c (a caller testing many points computes it once).
inline bool point_in_closed_triangle(const Box2& box, const Vec2& a, const Vec2& b, const Vec2& c,
                                     const Vec2& p) {
    if (!box.contains(p)) return false;
    const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

}  // namespace strata
