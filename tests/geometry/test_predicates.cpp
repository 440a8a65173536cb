#include "strata/geometry/predicates.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

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

}  // namespace

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
