// Retracting ends (src/untangle/detail/retract_ends.h), a last resort for an open layer's end
// that pokes through another layer or lies on its wrong side: built scenes checked exactly
// before and after (the end moved back along its own end segment, nothing else moved, the
// scene collision-free), and a scene with nothing at its ends left as it is.

#include "strata/geometry/checks.h"
#include "untangle/detail/retract_ends.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

using namespace strata;

namespace {

Layer open_layer(const char* name, std::vector<Vec2> points, const char* outer = nullptr) {
    Layer layer;
    layer.name = name;
    layer.points = std::move(points);
    layer.thickness = 0.1;
    if (outer) layer.outer = {outer};
    return layer;
}

// `p` lies on segment (a, b), strictly between its ends (up to rounding).
bool strictly_between(const Vec2& p, const Vec2& a, const Vec2& b) {
    const Vec2 e = b - a;
    const double t = glm::dot(p - a, e) / glm::dot(e, e);
    const double off = std::abs(e.x * (p.y - a.y) - e.y * (p.x - a.x)) / glm::length(e);
    return t > 0.0 && t < 1.0 && off < 1e-12 * glm::length(e);
}

// Every vertex of `a` but vertex `v` of layer `l` where it is in `b`.
bool only_moved(const Scene& a, const Scene& b, std::size_t l, std::size_t v) {
    for (std::size_t i = 0; i < a.size(); ++i)
        for (std::size_t k = 0; k < a.layer(i).points.size(); ++k)
            if ((i != l || k != v) && a.layer(i).points[k] != b.layer(i).points[k]) return false;
    return a.layer(l).points[v] != b.layer(l).points[v];
}

}  // namespace

TEST_CASE("retract_ends: an end poking through the layer over it is cut back before the crossing",
          "[retract_ends]") {
    // "under" runs along y = 0 and its last segment turns up through "over" (y = 1).
    Scene scene({open_layer("under", {{0, 0}, {4, 0}, {8, 0}, {9, 2}}, "over"),
                 open_layer("over", {{0, 1}, {5, 1}, {10, 1}})});
    const Scene before = scene;
    REQUIRE(check_scene(before).crossing_count == 1);

    REQUIRE(detail::retract_ends(scene, CheckParams{}) == 1);
    const CheckReport after = check_scene(scene);
    CHECK(after.is_collision_free());
    CHECK(after.separations_hold());
    CHECK(only_moved(before, scene, 0, 3));
    // Halfway between the inner vertex and the crossing at (8.5, 1).
    const Vec2 end = scene.layer(0).points[3];
    CHECK(strictly_between(end, {8, 0}, {8.5, 1}));
    CHECK(glm::distance(end, Vec2(8.25, 0.5)) < 1e-12);
}

TEST_CASE("retract_ends: an end on the wrong side of a corner moves back along its segment",
          "[retract_ends]") {
    // "over" runs left along y = 1, then turns down-left at (0, 1); "under" goes around that
    // turn's end and comes back above it, its end closest to the corner, on the side away
    // from the turn: the wrong side for a layer under "over" (whose outside is up, by the
    // vertices of "under" below it). No segment crosses.
    Scene scene(
        {open_layer("under", {{-0.1, 1.3}, {-5, 1.3}, {-5, -3}, {5, -3}, {5, 0.5}, {9, 0.5}},
                    "over"),
         open_layer("over", {{10, 1}, {5, 1}, {0, 1}, {-3, -2}})});
    const Scene before = scene;
    const CheckReport check = check_scene(before);
    REQUIRE(check.crossing_count == 0);
    REQUIRE(check.nesting_violation_count == 1);
    REQUIRE(check.nesting_violations[0].layer == 0);
    REQUIRE(check.nesting_violations[0].vertex == 0);

    REQUIRE(detail::retract_ends(scene, CheckParams{}) == 1);
    CHECK(check_scene(scene).is_collision_free());
    CHECK(only_moved(before, scene, 0, 0));
    // The smallest of the moves tried (to 3/4 of the segment from its inner vertex).
    CHECK(glm::distance(scene.layer(0).points[0], Vec2(-1.325, 1.3)) < 1e-12);
}

TEST_CASE("retract_ends: a scene whose ends are clean is left as it is", "[retract_ends]") {
    // A crossing away from the ends of both layers, and clean ends: nothing to retract.
    Scene scene({open_layer("a", {{0, 0}, {4, 0}, {5, 2}, {6, 0}, {10, 0}}, "b"),
                 open_layer("b", {{0, 1}, {2, 1}, {8, 1}, {10, 1}})});
    const Scene before = scene;
    REQUIRE(check_scene(before).crossing_count == 2);
    CHECK(detail::retract_ends(scene, CheckParams{}) == 0);
    for (std::size_t l = 0; l < scene.size(); ++l)
        CHECK(scene.layer(l).points == before.layer(l).points);
}
