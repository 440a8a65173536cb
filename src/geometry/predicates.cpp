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

// orient2d() by exact rational arithmetic: every double is a dyadic rational, so the
// conversions and the arithmetic are exact (any finite coordinates).
int orient2d_rational(const Vec2& a, const Vec2& b, const Vec2& c) {
    const Rational acx = Rational(a.x) - Rational(c.x);
    const Rational bcx = Rational(b.x) - Rational(c.x);
    const Rational acy = Rational(a.y) - Rational(c.y);
    const Rational bcy = Rational(b.y) - Rational(c.y);
    return sign_of(acx * bcy - acy * bcx);
}

// x = a + b exactly as hi + lo (Knuth's TwoSum; exact unless it overflows).
void two_sum(double a, double b, double& hi, double& lo) {
    hi = a + b;
    const double bv = hi - a;
    lo = (a - (hi - bv)) + (b - bv);
}

// e (n components, nonoverlapping, increasing magnitude, no zeros) + b, the same way
// (Shewchuk's GROW-EXPANSION with zero elimination); returns the new length.
std::size_t grow_expansion(double* e, std::size_t n, double b) {
    std::size_t m = 0;
    double q = b;
    for (std::size_t i = 0; i < n; ++i) {
        double hi = 0.0, lo = 0.0;
        two_sum(q, e[i], hi, lo);
        if (lo != 0.0) e[m++] = lo;
        q = hi;
    }
    if (q != 0.0) e[m++] = q;
    return m;
}

// Every coordinate 0 or within [2^-200, 2^200] in magnitude: then every difference, product
// and product error of orient2d_expansion() is a multiple of 2^-504 and below 2^403, far from
// underflow and overflow, and its TwoSum/FMA steps are exact.
bool in_expansion_range(const Vec2& a, const Vec2& b, const Vec2& c) {
    for (const double v : {a.x, a.y, b.x, b.y, c.x, c.y}) {
        const double m = std::fabs(v);
        if (m != 0.0 && !(m >= 0x1p-200 && m <= 0x1p200)) return false;  // NaN: false
    }
    return true;
}

// Sign of (a - c) x (b - c), exact by floating-point expansions (the differences by TwoSum,
// their products by FMA, the 16 terms summed without error): the same sign as the rational
// arithmetic below, about two orders of magnitude faster.
int orient2d_expansion(const Vec2& a, const Vec2& b, const Vec2& c) {
    double ax[2], bx[2], ay[2], by[2];  // hi, lo
    two_sum(a.x, -c.x, ax[0], ax[1]);
    two_sum(b.x, -c.x, bx[0], bx[1]);
    two_sum(a.y, -c.y, ay[0], ay[1]);
    two_sum(b.y, -c.y, by[0], by[1]);
    double e[16];
    std::size_t n = 0;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
            const double p = ax[i] * by[j];  // + (ax by)
            n = grow_expansion(e, n, p);
            n = grow_expansion(e, n, std::fma(ax[i], by[j], -p));
            const double q = ay[i] * bx[j];  // - (ay bx)
            n = grow_expansion(e, n, -q);
            n = grow_expansion(e, n, -std::fma(ay[i], bx[j], -q));
        }
    // Nonoverlapping, increasing magnitude: the last component carries the sign.
    return n == 0 ? 0 : (e[n - 1] > 0.0 ? 1 : -1);
}

}  // namespace

int detail::orient2d_exact(const Vec2& a, const Vec2& b, const Vec2& c) {
    if (in_expansion_range(a, b, c)) return orient2d_expansion(a, b, c);
    return orient2d_rational(a, b, c);
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
