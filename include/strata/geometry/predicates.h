#pragma once
/// @file Exact geometric predicates on double coordinates.
///
/// orient2d uses a floating-point filter and falls back to exact rational arithmetic when the
/// filter cannot decide, so its sign is always the sign of the exact determinant.

#include "strata/core/types.h"

namespace strata {

/// Sign of the area of triangle (a, b, c): +1 counter-clockwise (c left of a->b), -1
/// clockwise, 0 collinear. Exact.
int orient2d(const Vec2& a, const Vec2& b, const Vec2& c);

/// How two closed segments meet. Exact.
enum class SegmentContact {
    None,    ///< Disjoint.
    Proper,  ///< The interiors cross at one point that is an end of neither segment.
    Touch,   ///< They share a point that is an end of one of them, or overlap collinearly.
};

/// Exact classification of segments [p0, p1] and [q0, q1].
SegmentContact segment_contact(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1);

/// Intersection point of the supporting lines of two properly crossing segments (rounded).
Vec2 crossing_point(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1);

/// Distance from `p` to segment [a, b], and the closest point of the segment.
double point_segment_distance(const Vec2& p, const Vec2& a, const Vec2& b, Vec2* closest = nullptr);

}  // namespace strata
