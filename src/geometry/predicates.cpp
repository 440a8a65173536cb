#include "strata/geometry/predicates.h"

// GCC 12 reports a false "maybe uninitialized" inside Boost.Multiprecision's rational type.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/multiprecision/cpp_int.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cmath>
#include <limits>

namespace strata {

namespace {

using Rational = boost::multiprecision::cpp_rational;

int sign_of(const Rational& value) {
    return value > 0 ? 1 : (value < 0 ? -1 : 0);
}

}  // namespace

int detail::orient2d_exact(const Vec2& a, const Vec2& b, const Vec2& c) {
    // Every double is a dyadic rational: the conversions and the arithmetic are exact.
    const Rational acx = Rational(a.x) - Rational(c.x);
    const Rational bcx = Rational(b.x) - Rational(c.x);
    const Rational acy = Rational(a.y) - Rational(c.y);
    const Rational bcy = Rational(b.y) - Rational(c.y);
    return sign_of(acx * bcy - acy * bcx);
}

SegmentContact detail::segment_contact_in_boxes(const Vec2& p0, const Vec2& p1, const Vec2& q0,
                                                const Vec2& q1) {
    const int o1 = orient2d(p0, p1, q0);
    const int o2 = orient2d(p0, p1, q1);
    if (o1 * o2 > 0) return SegmentContact::None;
    const int o3 = orient2d(q0, q1, p0);
    const int o4 = orient2d(q0, q1, p1);
    if (o3 * o4 > 0) return SegmentContact::None;
    if (o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return SegmentContact::Proper;
    if (o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0) {
        // All four points on one line (or degenerate segments): the boxes overlap, and on a
        // line the box test is the interval test, so they share at least one point.
        return SegmentContact::Touch;
    }
    // One end lies on the other segment's line, and the segments straddle each other's lines.
    return SegmentContact::Touch;
}

int winding_contribution(const Vec2& a, const Vec2& b, const Vec2& p) {
    if (a.y <= p.y) {
        if (b.y > p.y && orient2d(a, b, p) > 0) return 1;
    } else if (b.y <= p.y && orient2d(a, b, p) < 0) {
        return -1;
    }
    return 0;
}

std::optional<int> winding_change_across(const Vec2& p0, const Vec2& p1, const Vec2& a,
                                         const Vec2& b) {
    switch (segment_contact(p0, p1, a, b)) {
        case SegmentContact::None:
            return 0;
        case SegmentContact::Touch:
            return std::nullopt;
        case SegmentContact::Proper:
            break;
    }
    return orient2d(a, b, p1) > 0 ? 1 : -1;
}

Vec2 crossing_point(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
    const Vec2 d = p1 - p0;
    const Vec2 e = q1 - q0;
    const double denom = d.x * e.y - d.y * e.x;
    if (denom == 0.0) return p0;
    const Vec2 w = q0 - p0;
    const double t = std::clamp((w.x * e.y - w.y * e.x) / denom, 0.0, 1.0);
    return p0 + t * d;
}

}  // namespace strata
