#include "strata/geometry/predicates.h"

#include <catch2/catch.hpp>

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/multiprecision/cpp_int.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace strata;

namespace {

// The textbook evaluation (b - a) x (c - a) in doubles, for comparison.
int naive_orient(const Vec2& a, const Vec2& b, const Vec2& c) {
    const double det = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    return (det > 0.0) - (det < 0.0);
}

double next_up(double x) {
    return std::nextafter(x, std::numeric_limits<double>::infinity());
}
double next_down(double x) {
    return std::nextafter(x, -std::numeric_limits<double>::infinity());
}

// The sign of (a - c) x (b - c) in exact rationals, as a reference.
int rational_orient(const Vec2& a, const Vec2& b, const Vec2& c) {
    using R = boost::multiprecision::cpp_rational;
    const R d = (R(a.x) - R(c.x)) * (R(b.y) - R(c.y)) - (R(a.y) - R(c.y)) * (R(b.x) - R(c.x));
    return d > 0 ? 1 : (d < 0 ? -1 : 0);
}

}  // namespace

TEST_CASE("orient2d's exact stage agrees with rational arithmetic near degeneracy",
          "[predicates]") {
    // Points on a line, a few ulps off it, at scales from 1e-70 to 1e70 (the floating-point
    // expansions and, outside their range, the rationals decide them): the filter cannot.
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::uniform_int_distribution<int> ulps(-3, 3), exponent(-70, 70);
    int zeros = 0, signs = 0;
    for (int i = 0; i < 20000; ++i) {
        const double scale = std::pow(10.0, exponent(rng));
        const Vec2 a(unit(rng) * scale, unit(rng) * scale);
        const Vec2 d(unit(rng) * scale, unit(rng) * scale);
        const double t = unit(rng) * 3.0;
        Vec2 b = a + d, c = a + t * d;
        for (int k = ulps(rng); k != 0; k += k > 0 ? -1 : 1)
            c.y = k > 0 ? next_up(c.y) : next_down(c.y);
        if (i % 5 == 0) c = a + 0.5 * (b - a);  // often exactly on the line (dyadic midpoint)
        const int want = rational_orient(a, b, c);
        REQUIRE(detail::orient2d_exact(a, b, c) == want);
        REQUIRE(detail::orient2d_exact(b, c, a) == want);
        REQUIRE(orient2d(c, b, a) == -want);
        (want == 0 ? zeros : signs) += 1;
    }
    CHECK(zeros > 500);  // both outcomes were exercised
    CHECK(signs > 1000);
}

TEST_CASE("orient2d gives the sign of the triangle area", "[predicates]") {
    CHECK(orient2d({0, 0}, {1, 0}, {0, 1}) == 1);
    CHECK(orient2d({0, 0}, {0, 1}, {1, 0}) == -1);
    CHECK(orient2d({0, 0}, {1, 1}, {2, 2}) == 0);
    CHECK(orient2d({0, 0}, {0, 0}, {2, 2}) == 0);
    // Huge coordinates whose products overflow: decided exactly.
    CHECK(orient2d({-1e300, -1e300}, {1e300, -1e300}, {0, 1e300}) == 1);
    // Tiny coordinates whose products underflow.
    CHECK(orient2d({0, 0}, {1e-200, 0}, {0, 1e-200}) == 1);
    CHECK(orient2d({0, 0}, {1e-200, 1e-200}, {2e-200, 2e-200}) == 0);
}

TEST_CASE("orient2d is exact where the naive evaluation gets the sign wrong", "[predicates]") {
    // Shewchuk's example: a point one ulp-step off the line through (12, 12) and (24, 24).
    const Vec2 a(0.5 + std::ldexp(41.0, -53), 0.5 + std::ldexp(48.0, -53));
    const Vec2 b(12.0, 12.0), c(24.0, 24.0);
    // Exactly, (b - a) x (c - a) = 12 (a.y - a.x) > 0; the doubles say otherwise.
    CHECK(orient2d(a, b, c) == 1);
    CHECK(naive_orient(a, b, c) == -1);
    // Every rotation and reflection agrees.
    CHECK(orient2d(b, c, a) == 1);
    CHECK(orient2d(c, a, b) == 1);
    CHECK(orient2d(b, a, c) == -1);

    // Exactly collinear points that doubles cannot represent "nicely".
    CHECK(orient2d({0.1, 0.1}, {0.2, 0.2}, {0.3, 0.3}) == 0);
    // One-ulp perturbations of a point on y = x.
    CHECK(orient2d({0, 0}, {1, 1}, {0.3, next_up(0.3)}) == 1);
    CHECK(orient2d({0, 0}, {1, 1}, {0.3, next_down(0.3)}) == -1);
    CHECK(orient2d({0.1, 0.1}, {1e10, 1e10}, {0.7, next_up(0.7)}) == 1);
    CHECK(orient2d({0.1, 0.1}, {1e10, 1e10}, {0.7, 0.7}) == 0);
}

TEST_CASE("segment_contact classifies exactly", "[predicates]") {
    using SC = SegmentContact;
    SECTION("proper crossing") {
        CHECK(segment_contact({0, 0}, {2, 2}, {0, 2}, {2, 0}) == SC::Proper);
    }
    SECTION("disjoint") {
        CHECK(segment_contact({0, 0}, {1, 0}, {0, 1}, {1, 1}) == SC::None);  // parallel
        CHECK(segment_contact({0, 0}, {1, 1}, {2, 0}, {3, -5}) == SC::None);
        CHECK(segment_contact({0, 0}, {1, 0}, {2, 0}, {3, 0}) == SC::None);  // collinear apart
        CHECK(segment_contact({0, 0}, {2, 2}, {1.5, 0}, {3, 1}) ==
              SC::None);  // lines cross outside
    }
    SECTION("touches") {
        CHECK(segment_contact({0, 0}, {2, 0}, {1, 0}, {1, 1}) == SC::Touch);  // T junction
        CHECK(segment_contact({0, 0}, {1, 1}, {1, 1}, {2, 0}) == SC::Touch);  // shared end
        CHECK(segment_contact({0, 0}, {2, 0}, {1, 0}, {3, 0}) == SC::Touch);  // overlap
        CHECK(segment_contact({0, 0}, {3, 0}, {1, 0}, {2, 0}) == SC::Touch);  // containment
        CHECK(segment_contact({0, 0}, {1, 0}, {1, 0}, {2, 0}) ==
              SC::Touch);  // collinear, end to end
        CHECK(segment_contact({0, 0}, {0, 2}, {0, 1}, {0, 3}) == SC::Touch);  // vertical overlap
    }
    SECTION("degenerate segments") {
        CHECK(segment_contact({1, 1}, {1, 1}, {0, 0}, {2, 2}) == SC::Touch);
        CHECK(segment_contact({1, 1}, {1, 1}, {0, 0}, {2, 2.5}) == SC::None);
        CHECK(segment_contact({1, 1}, {1, 1}, {1, 1}, {1, 1}) == SC::Touch);
        CHECK(segment_contact({1, 1}, {1, 1}, {1, 2}, {1, 2}) == SC::None);
        CHECK(segment_contact({3, 3}, {3, 3}, {0, 0}, {2, 2}) == SC::None);  // on the line, beyond
    }
    SECTION("near-degenerate: an end one ulp off the other segment") {
        const Vec2 q0(0.3, 0.3), q1(0.9, 0.9);
        const Vec2 on(0.5, 0.5);
        CHECK(segment_contact(on, {0.5, -1}, q0, q1) == SC::Touch);
        CHECK(segment_contact({0.5, next_down(0.5)}, {0.5, -1}, q0, q1) == SC::None);
        CHECK(segment_contact({0.5, next_up(0.5)}, {0.5, -1}, q0, q1) == SC::Proper);
    }
}

TEST_CASE("crossing_point of two crossing segments", "[predicates]") {
    const Vec2 p = crossing_point({0, 0}, {2, 2}, {0, 2}, {2, 0});
    CHECK(p.x == Approx(1.0));
    CHECK(p.y == Approx(1.0));
    const Vec2 q = crossing_point({0, 0}, {4, 0}, {1, -1}, {1, 3});
    CHECK(q.x == Approx(1.0));
    CHECK(q.y == Approx(0.0).margin(1e-15));
}

TEST_CASE("point_segment_distance", "[predicates]") {
    Vec2 c;
    CHECK(point_segment_distance({1, 1}, {0, 0}, {2, 0}, &c) == 1.0);
    CHECK(c == Vec2(1, 0));
    CHECK(point_segment_distance({-3, 4}, {0, 0}, {2, 0}, &c) == 5.0);
    CHECK(c == Vec2(0, 0));
    CHECK(point_segment_distance({5, 4}, {0, 0}, {2, 0}, &c) == 5.0);
    CHECK(c == Vec2(2, 0));
    // Zero-length segment.
    CHECK(point_segment_distance({4, 5}, {1, 1}, {1, 1}, &c) == 5.0);
    CHECK(c == Vec2(1, 1));
    CHECK(point_segment_distance({1, 1}, {1, 1}, {1, 1}) == 0.0);
    // A point on the segment.
    CHECK(point_segment_distance({0.5, 0.5}, {0, 0}, {1, 1}) == Approx(0.0).margin(1e-16));
}

namespace {

// Winding number of the closed polyline `k` around p, by winding_contribution().
int winding_of(const std::vector<Vec2>& k, const Vec2& p) {
    int w = 0;
    for (std::size_t i = 0; i < k.size(); ++i)
        w += winding_contribution(k[i], k[(i + 1) % k.size()], p);
    return w;
}

}  // namespace

TEST_CASE("winding_contribution sums to the winding number", "[predicates]") {
    const std::vector<Vec2> ccw{{0, 0}, {4, 0}, {4, 3}, {0, 3}};
    const std::vector<Vec2> cw(ccw.rbegin(), ccw.rend());
    CHECK(winding_of(ccw, {1, 1}) == 1);
    CHECK(winding_of(cw, {1, 1}) == -1);
    CHECK(winding_of(ccw, {5, 1}) == 0);
    CHECK(winding_of(ccw, {-1, 1}) == 0);
    CHECK(winding_of(ccw, {2, 0.0}) == 1);  // on the bottom edge: half-open rule, counted in
    CHECK(winding_of(ccw, {2, 3.0}) == 0);  // on the top edge: out
    // A loop going twice around.
    const std::vector<Vec2> twice{{0, 0},     {4, 0},     {4, 3},     {0, 3},
                                  {0.5, 0.5}, {3.5, 0.5}, {3.5, 2.5}, {0.5, 2.5}};
    CHECK(winding_of(twice, {2, 1}) == 2);
    CHECK(winding_of(twice, {0.2, 1}) == 1);
}

TEST_CASE("winding_change_across gives the winding change along a path", "[predicates]") {
    CHECK(winding_change_across({2, 1}, {0, 1}, {1, 0}, {1, 2}) == 1);  // right to left of a->b
    CHECK(winding_change_across({0, 1}, {2, 1}, {1, 0}, {1, 2}) == -1);
    CHECK(winding_change_across({0, 1}, {0.5, 1}, {1, 0}, {1, 2}) == 0);
    CHECK_FALSE(winding_change_across({0, 1}, {1, 1}, {1, 0}, {1, 2}).has_value());  // ends on it
    CHECK_FALSE(
        winding_change_across({0, 0}, {2, 0}, {1, 0}, {1, 2}).has_value());  // through a's end

    // The identity the simplification driver's local nesting check relies on: when a stretch
    // of a closed polyline K0 moves (K1) and a point moves from p0 to p1,
    //   winding(K1, p1) - winding(K0, p0)
    //     = sum over the changed segments of [contribution(new, p0) - contribution(old, p0)]
    //     + sum over the segments of K1 of winding_change_across(p0, p1, segment),
    // where only the changed segments and those of K1 near the path take part.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    constexpr double kPi = 3.14159265358979323846;
    int decided = 0, changed = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const std::size_t n = 12 + static_cast<std::size_t>(trial % 9);
        std::vector<Vec2> k0;
        const bool clockwise = trial % 2 == 1;
        for (std::size_t i = 0; i < n; ++i) {
            double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
            if (clockwise) t = -t;
            const double r = 1.0 + 0.3 * u(rng);
            k0.emplace_back(r * std::cos(t), r * std::sin(t));
        }
        // Move a stretch of 1-4 consecutive vertices (and, half the time, drop one of them).
        std::vector<Vec2> k1 = k0;
        const std::size_t first = static_cast<std::size_t>(trial) % n;
        const std::size_t count = 1 + static_cast<std::size_t>(trial / 7) % 4;
        std::vector<char> moved(n, 0);
        for (std::size_t c = 0; c < count; ++c) {
            const std::size_t i = (first + c) % n;
            k1[i] += 0.6 * Vec2(u(rng), u(rng));
            moved[i] = 1;
        }
        // Changed segments: those with a moved end (old and new versions).
        int delta = 0;
        const Vec2 p0(1.2 * u(rng), 1.2 * u(rng));
        const Vec2 p1 = trial % 3 == 0 ? p0 : p0 + 0.8 * Vec2(u(rng), u(rng));
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t j = (i + 1) % n;
            if (!moved[i] && !moved[j]) continue;
            delta +=
                winding_contribution(k1[i], k1[j], p0) - winding_contribution(k0[i], k0[j], p0);
        }
        bool degenerate = false;
        if (p1 != p0)
            for (std::size_t i = 0; i < n; ++i) {
                const auto c = winding_change_across(p0, p1, k1[i], k1[(i + 1) % n]);
                if (!c) {
                    degenerate = true;
                    break;
                }
                delta += *c;
            }
        if (degenerate) continue;
        ++decided;
        const int expected = winding_of(k1, p1) - winding_of(k0, p0);
        if (expected != 0) ++changed;
        INFO("trial " << trial);
        REQUIRE(delta == expected);
    }
    CHECK(decided > 3900);
    CHECK(changed > 400);  // the identity is tested where the winding number changes, too
}

TEST_CASE("point_in_closed_triangle: closed, exact, and flat triangles by their box",
          "[predicates]") {
    auto in = [](const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& p) {
        Box2 box;
        box.extend(a);
        box.extend(b);
        box.extend(c);
        return point_in_closed_triangle(box, a, b, c, p);
    };
    const Vec2 a(0, 0), b(4, 0), c(0, 4);
    CHECK(in(a, b, c, {1, 1}));
    CHECK(in(c, b, a, {1, 1}));  // either orientation
    CHECK(in(a, b, c, {2, 2}));  // on the hypotenuse
    CHECK(in(a, b, c, a));       // a corner
    CHECK_FALSE(in(a, b, c, {2.0, 2.0 + 1e-15}));
    CHECK_FALSE(in(a, b, c, {-1e-300, 1}));
    // A flat triangle holds its segment, not the rest of its line.
    CHECK(in(a, {2, 2}, {4, 4}, {3, 3}));
    CHECK_FALSE(in(a, {2, 2}, {4, 4}, {5, 5}));
    CHECK_FALSE(in(a, {2, 2}, {4, 4}, {3, 3.5}));
}
