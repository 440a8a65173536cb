#include "strata/core/error.h"
#include "strata/geometry/checks.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace strata;

namespace {

constexpr double kPi = 3.14159265358979323846;

Layer make_layer(std::vector<Vec2> points, bool closed = false) {
    Layer layer;
    layer.name = "l";
    layer.points = std::move(points);
    layer.closed = closed;
    return layer;
}

Layer polygon(double r, std::size_t n) {
    Layer layer;
    layer.name = "polygon";
    layer.closed = true;
    for (std::size_t i = 0; i < n; ++i) {
        const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        layer.points.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return layer;
}

}  // namespace

TEST_CASE("hausdorff of concentric regular polygons", "[hausdorff]") {
    const double tolerance = 1e-9;
    for (std::size_t n : {6u, 64u, 500u}) {
        INFO("n = " << n);
        const Layer inner = polygon(1.0, n), outer = polygon(1.5, n);
        const HausdorffDistance d = hausdorff(inner, outer, tolerance);
        // Every point of the inner polygon is (r2 - r1) cos(pi / n) from the parallel edge
        // of the outer one; the outer vertices are r2 - r1 from the inner vertices.
        const double edge_gap = 0.5 * std::cos(kPi / static_cast<double>(n));
        CHECK(d.a_to_b >= edge_gap - 1e-12);
        CHECK(d.a_to_b <= edge_gap + tolerance);
        CHECK(d.b_to_a == Approx(0.5).epsilon(1e-12));
        CHECK(d.symmetric() == d.b_to_a);
        const HausdorffDistance swapped = hausdorff(outer, inner, tolerance);
        CHECK(swapped.a_to_b == d.b_to_a);
        CHECK(swapped.b_to_a == d.a_to_b);
    }
}

TEST_CASE("hausdorff of a segment and a shifted copy", "[hausdorff]") {
    const Layer a = make_layer({{0, 0}, {1, 0}});
    SECTION("shifted across") {
        const HausdorffDistance d = hausdorff(a, make_layer({{0, 1}, {1, 1}}), 1e-6);
        CHECK(d.a_to_b == 1.0);
        CHECK(d.b_to_a == 1.0);
    }
    SECTION("shifted diagonally: the far ends") {
        const HausdorffDistance d = hausdorff(a, make_layer({{0.5, 1}, {1.5, 1}}), 1e-6);
        CHECK(d.a_to_b == Approx(std::sqrt(1.25)).epsilon(1e-15));
        CHECK(d.b_to_a == Approx(std::sqrt(1.25)).epsilon(1e-15));
    }
    SECTION("shifted along itself") {
        const HausdorffDistance d = hausdorff(a, make_layer({{0.25, 0}, {1.25, 0}}), 1e-6);
        CHECK(d.a_to_b == 0.25);
        CHECK(d.b_to_a == 0.25);
    }
    SECTION("identical") {
        const HausdorffDistance d = hausdorff(a, a, 1e-6);
        CHECK(d.symmetric() == 0.0);
    }
}

TEST_CASE("hausdorff finds a maximum inside a segment", "[hausdorff]") {
    // Distance from (x, 0) to the U-shaped b is min(x, 0.7 - x) on [0, 0.7] and x - 0.7
    // beyond: the maximum 0.35 is at x = 0.35, not at a vertex of a (which give 0 and 0.3)
    // and not at a dyadic split point of [0, 1].
    const Layer a = make_layer({{0, 0}, {1, 0}});
    const Layer b = make_layer({{0, 0}, {0, 10}, {0.7, 10}, {0.7, 0}});
    for (double tolerance : {1e-3, 1e-6, 1e-9}) {
        INFO("tolerance = " << tolerance);
        const HausdorffDistance d = hausdorff(a, b, tolerance);
        CHECK(d.a_to_b <= 0.35 + 1e-15);  // a lower bound that is achieved
        CHECK(d.a_to_b >= 0.35 - tolerance);
        CHECK(d.b_to_a == 10.0);
    }
}

TEST_CASE("hausdorff handles points and rejects bad input", "[hausdorff]") {
    const Layer point = make_layer({{3, 4}});
    const Layer segment = make_layer({{0, 0}, {6, 0}});
    const HausdorffDistance d = hausdorff(point, segment, 1e-6);
    CHECK(d.a_to_b == 4.0);
    CHECK(d.b_to_a == Approx(5.0));
    CHECK_THROWS_AS(hausdorff(point, segment, 0.0), InvalidInput);
    CHECK_THROWS_AS(hausdorff(point, segment, -1.0), InvalidInput);
    CHECK_THROWS_AS(hausdorff(point, segment, std::nan("")), InvalidInput);
    CHECK_THROWS_AS(hausdorff(make_layer({}), segment, 1e-3), InvalidInput);
    CHECK_THROWS_AS(
        hausdorff(make_layer({{0, std::numeric_limits<double>::infinity()}}), segment, 1e-3),
        InvalidInput);
}
