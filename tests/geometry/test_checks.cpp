#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

using namespace strata;
using Catch::Matchers::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;

Layer make_layer(std::string name, std::vector<Vec2> points, bool closed = false) {
    Layer layer;
    layer.name = std::move(name);
    layer.points = std::move(points);
    layer.closed = closed;
    return layer;
}

Layer circle(std::string name, Vec2 center, double r, std::size_t n,
             std::optional<std::vector<std::string>> outer = std::nullopt) {
    Layer layer;
    layer.name = std::move(name);
    layer.closed = true;
    layer.outer = std::move(outer);
    for (std::size_t i = 0; i < n; ++i) {
        const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        layer.points.push_back(center + r * Vec2(std::cos(t), std::sin(t)));
    }
    return layer;
}

// Reads a slice file {"layers": [{"name", "closed", "points", "outer"}]} (the JSON reader of
// strata_io is tested on its own; this keeps the geometry tests independent of it).
Scene read_slice(const std::string& file) {
    std::ifstream in(test::test_data("slices/" + file));
    REQUIRE(in.good());
    const nlohmann::json json = nlohmann::json::parse(in);
    std::vector<Layer> layers;
    for (const auto& entry : json.at("layers")) {
        Layer layer;
        layer.name = entry.at("name").get<std::string>();
        layer.closed = entry.value("closed", false);
        layer.thickness = entry.value("thickness", 0.0);
        for (const auto& p : entry.at("points"))
            layer.points.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
        if (entry.contains("outer"))
            layer.outer = entry.at("outer").get<std::vector<std::string>>();
        layers.push_back(std::move(layer));
    }
    return Scene(std::move(layers));
}

}  // namespace

TEST_CASE("validate(CheckParams) names the field and the value", "[checks]") {
    CHECK_NOTHROW(validate(CheckParams{}));
    CheckParams params;
    params.separation_tolerance = 1.5;
    CHECK_THROWS_WITH(validate(params),
                      "check: params.separation_tolerance must be in [0, 1) (got 1.5)");
    CHECK_THROWS_AS(check_scene(test::crossing_pair(1), params), InvalidInput);
    params = {};
    params.near_distance = -2.0;
    CHECK_THROWS_WITH(validate(params), Contains("params.near_distance") && Contains("-2"));
    params.near_distance = std::nan("");
    CHECK_THROWS_WITH(validate(params), Contains("params.near_distance") && Contains("nan"));
}

TEST_CASE("crossings between layers are counted exactly", "[checks]") {
    const CheckReport report = check_scene(test::crossing_pair(5));
    CHECK(report.crossing_count == 5);
    CHECK(report.touch_count == 0);
    REQUIRE(report.crossings.size() == 5);
    for (std::size_t k = 0; k < 5; ++k) {
        const Crossing& c = report.crossings[k];
        CHECK(c.layer_a == 0);
        CHECK(c.layer_b == 1);
        CHECK(c.segment_a == 0);
        CHECK(c.segment_b == k);
        CHECK_FALSE(c.is_touch);
        CHECK(c.point.x == Approx(static_cast<double>(k) + 1.0));
        CHECK(c.point.y == Approx(0.0).margin(1e-12));
    }
    CHECK(report.total_self_crossings() == 0);
    CHECK_FALSE(report.is_collision_free());
    REQUIRE(report.pairs.size() == 1);
    CHECK(report.pairs[0].gap == 0.0);

    SECTION("listing is capped, counting is not") {
        CheckParams params;
        params.max_listed = 2;
        const CheckReport capped = check_scene(test::crossing_pair(40), params);
        CHECK(capped.crossing_count == 40);
        CHECK(capped.crossings.size() == 2);
    }
}

TEST_CASE("touches count once per contact location", "[checks]") {
    SECTION("two squares sharing a corner") {
        const CheckReport report = check_scene(test::touching_pair());
        CHECK(report.crossing_count == 1);
        CHECK(report.touch_count == 1);
        REQUIRE(report.crossings.size() == 1);
        CHECK(report.crossings[0].is_touch);
        CHECK(report.crossings[0].point == Vec2(1, 1));
        CHECK(report.nesting_violation_count == 0);
        CHECK(report.total_self_crossings() == 0);
        CHECK_FALSE(report.is_collision_free());
    }
    SECTION("a vertex lying on the interior of another layer's segment") {
        Layer a = make_layer("a", {{0, 0}, {4, 0}});
        Layer b = make_layer("b", {{1, 1}, {2, 0}, {3, 1}});
        a.outer = std::vector<std::string>{};
        b.outer = std::vector<std::string>{};
        const CheckReport report = check_scene(Scene({a, b}));
        CHECK(report.crossing_count == 1);
        CHECK(report.touch_count == 1);
        REQUIRE(report.crossings.size() == 1);
        CHECK(report.crossings[0].point == Vec2(2, 0));
        CHECK(report.crossings[0].segment_b == 0);
    }
    SECTION("a collinear overlap and a proper crossing") {
        Layer a = make_layer("a", {{0, 0}, {4, 0}});
        Layer b = make_layer("b", {{-1, 0}, {1, 0}, {1, 1}, {3, -1}});
        a.outer = std::vector<std::string>{};
        b.outer = std::vector<std::string>{};
        const CheckReport report = check_scene(Scene({a, b}));
        // Overlap [0, 1] x {0} (segments a0-b0, and b1 starting on a0 at (1, 0): two
        // locations (0, 0) and (1, 0)), plus b2 crossing a0 at (2, 0).
        CHECK(report.crossing_count == 3);
        CHECK(report.touch_count == 2);
    }
}

TEST_CASE("nested circles: no contact, exact gaps", "[checks]") {
    const std::size_t n = 64;
    const Scene scene = test::nested_circles(3, n);
    CheckParams params;
    params.near_distance = 1.0;
    const CheckReport report = check_scene(scene, params);
    CHECK(report.crossing_count == 0);
    CHECK(report.total_self_crossings() == 0);
    CHECK(report.nesting_violation_count == 0);
    CHECK(report.is_collision_free());
    CHECK(report.near_distance == 1.0);
    REQUIRE(report.pairs.size() == 3);
    const double c = std::cos(kPi / static_cast<double>(n));
    const double expected[3] = {0.25 * c, 0.5 * c, 0.25 * c};  // (0,1), (0,2), (1,2)
    const std::size_t pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (std::size_t k = 0; k < 3; ++k) {
        const PairSeparation& pair = report.pairs[k];
        CHECK(pair.layer_a == pairs[k][0]);
        CHECK(pair.layer_b == pairs[k][1]);
        CHECK(pair.relation == Relation::Under);
        CHECK(pair.gap == Approx(expected[k]).epsilon(1e-13));
        CHECK(glm::length(pair.at_a - pair.at_b) == Approx(pair.gap).epsilon(1e-13));
        CHECK(pair.required == 0.0);
        CHECK(std::isinf(pair.ratio()));
    }
    CHECK(std::isinf(report.min_separation_ratio));
    CHECK(report.separations_hold());

    SECTION("automatic near distance: 5% of the diagonal, pairs farther are left out") {
        const CheckReport automatic = check_scene(scene);
        CHECK(automatic.near_distance == Approx(0.05 * std::sqrt(2.0) * 3.0));
        CHECK(automatic.near_distance == automatic_near_distance(scene));
        CHECK(automatic.pairs.empty());
    }
}

TEST_CASE("separation violations with thickness", "[checks]") {
    const std::size_t n = 64;
    const double gap = 0.25 * std::cos(kPi / static_cast<double>(n));  // ~0.249699
    SECTION("inner vertices closer than required, outer ones not") {
        // Required 0.2498: the inner polygon's vertices are 0.249699 from the outer one; the
        // outer polygon's vertices are 0.25 from the inner one.
        const Scene scene = test::nested_circles(2, n, 1.0, 0.25, 0.2498);
        const CheckReport report = check_scene(scene);
        CHECK(report.near_distance == Approx(2.0 * 0.2498));
        REQUIRE(report.pairs.size() == 1);
        CHECK(report.pairs[0].required == Approx(0.2498));
        CHECK(report.min_separation_ratio == Approx(gap / 0.2498));
        CHECK(report.separation_violation_count == n);
        CHECK_FALSE(report.separations_hold());
        REQUIRE(report.separation_violations.size() == n);
        for (const SeparationViolation& v : report.separation_violations) {
            CHECK(v.layer == 0);
            CHECK(v.other == 1);
            CHECK(v.distance == Approx(gap).epsilon(1e-12));
            CHECK(v.required == Approx(0.2498));
        }
        CHECK(report.is_collision_free());  // separations are not collisions
    }
    SECTION("every vertex when the thickness is larger") {
        const CheckReport report = check_scene(test::nested_circles(2, n, 1.0, 0.25, 0.4));
        CHECK(report.separation_violation_count == 2 * n);
    }
    SECTION("the tolerance lets them pass") {
        CheckParams params;
        params.separation_tolerance = 0.01;  // threshold 0.2498 * 0.99 = 0.2473 < gap
        const CheckReport report =
            check_scene(test::nested_circles(2, n, 1.0, 0.25, 0.2498), params);
        CHECK(report.separation_violation_count == 0);
        CHECK(report.min_separation_ratio == Approx(gap / 0.2498));
    }
    SECTION("enough room") {
        const CheckReport report = check_scene(test::nested_circles(2, n, 1.0, 0.25, 0.2));
        CHECK(report.separation_violation_count == 0);
        CHECK(report.min_separation_ratio > 1.0);
    }
}

TEST_CASE("nesting violations", "[checks]") {
    const std::size_t n = 16;
    SECTION("a circle moved out of the circle it must stay under") {
        const Scene scene({circle("in", {5, 0}, 1.0, n, std::vector<std::string>{"out"}),
                           circle("out", {0, 0}, 2.0, 24, std::vector<std::string>{})});
        const CheckReport report = check_scene(scene);
        CHECK(report.crossing_count == 0);
        CHECK(report.nesting_violation_count == n);
        REQUIRE(report.nesting_violations.size() == n);
        for (std::size_t k = 0; k < n; ++k) {
            CHECK(report.nesting_violations[k].layer == 0);
            CHECK(report.nesting_violations[k].vertex == k);
            CHECK(report.nesting_violations[k].other == 1);
            CHECK(report.nesting_violations[k].expected == Relation::Under);
        }
        CHECK_FALSE(report.is_collision_free());
    }
    SECTION("the stack order reversed: under outside, over inside") {
        const Scene scene({circle("big", {0, 0}, 2.0, 24), circle("small", {0, 0}, 1.0, n)});
        const CheckReport report = check_scene(scene);
        CHECK(report.crossing_count == 0);
        CHECK(report.nesting_violation_count == 24 + n);
    }
    SECTION("a side-by-side loop put inside another") {
        const Scene scene({circle("a", {0.5, 0}, 1.0, n, std::vector<std::string>{}),
                           circle("b", {0, 0}, 3.0, 32, std::vector<std::string>{})});
        const CheckReport report = check_scene(scene);
        CHECK(report.crossing_count == 0);
        CHECK(report.nesting_violation_count == n);
        REQUIRE(!report.nesting_violations.empty());
        CHECK(report.nesting_violations[0].expected == Relation::SideBySide);
        CHECK(report.nesting_violations[0].other == 1);
    }
    SECTION("side-by-side loops apart are fine") {
        const Scene scene({circle("a", {-2, 0}, 1.0, n, std::vector<std::string>{}),
                           circle("b", {2, 0}, 1.0, n, std::vector<std::string>{})});
        const CheckReport report = check_scene(scene);
        CHECK(report.is_collision_free());
        CHECK(report.pairs.empty());  // 2 apart, near distance 5% of ~6.3
    }
    SECTION("a vertex exactly on the other layer is a touch, not a nesting violation") {
        Layer inner = make_layer("in", {{0, 0}, {1, -0.5}, {1, 0.5}}, true);  // (0,0) on outer
        inner.outer = std::vector<std::string>{"out"};
        Layer outer = make_layer("out", {{0, -1}, {2, -1}, {2, 1}, {0, 1}}, true);
        outer.outer = std::vector<std::string>{};
        const CheckReport report = check_scene(Scene({inner, outer}));
        CHECK(report.crossing_count == 1);
        CHECK(report.touch_count == 1);
        CHECK(report.nesting_violation_count == 0);
    }
}

TEST_CASE("nesting against open layers uses their outside side", "[checks]") {
    SECTION("outside_side of closed layers is the orientation") {
        const Scene scene({make_layer("ccw", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, true),
                           make_layer("cw", {{3, 0}, {3, 1}, {4, 1}, {4, 0}}, true)});
        CHECK(outside_side(scene, 0) == 1);
        CHECK(outside_side(scene, 1) == -1);
    }
    SECTION("stacked open curves: away from the inner ones, towards the outer ones") {
        const Scene scene = test::stacked_sines(2, 100, 0.3, 0.5);
        CHECK(outside_side(scene, 1) == -1);  // travelling +x, the layer under is on the right
        CHECK(outside_side(scene, 0) == -1);  // the layer over is on the left
        const Scene far = test::stacked_sines(2, 100, 0.3, 1.0);
        CHECK(outside_side(far, 1, 2.0) == -1);
        // Nothing within the automatic near distance: the second vote, within 3 x that.
        CHECK(outside_side(far, 1) == -1);
        CHECK(outside_side(far, 1, 0.1) == 1);  // nothing within 0.3 either: +1
        Layer top = far.layer(1);
        std::reverse(top.points.begin(), top.points.end());
        const Scene reversed({far.layer(0), top});
        CHECK(outside_side(reversed, 1, 2.0) == 1);
    }
    SECTION("a stack of open curves is collision-free") {
        const CheckReport report = check_scene(test::stacked_sines(3, 100, 0.3, 0.5));
        CHECK(report.is_collision_free());
        CHECK(report.pairs.size() == 2);  // sine_0 and sine_2 are 0.96 apart, not near
    }
    SECTION("the top curve moved below the bottom one") {
        Scene scene = test::stacked_sines(3, 100, 0.3, 1.0);
        std::vector<Vec2> moved = scene.layer(2).points;
        for (Vec2& p : moved) p.y -= 3.0;  // now at y = -1 + 0.3 sin x
        scene.set_points(2, moved);
        CheckParams params;
        params.near_distance = 1.5;
        const CheckReport report = check_scene(scene, params);
        CHECK(report.crossing_count == 0);
        // Over sine_0, whose outside is up (towards sine_1); every vertex of the moved curve
        // whose closest point on sine_0 is not an end is on the wrong side.
        CHECK(report.nesting_violation_count >= 90);
        CHECK(report.nesting_violation_count <= 100);
        for (const NestingViolation& v : report.nesting_violations) {
            CHECK(v.layer == 2);
            CHECK(v.other == 0);
            CHECK(v.expected == Relation::Over);
        }
        CHECK_FALSE(report.is_collision_free());
    }
    SECTION("outside sides given by the caller replace the vote") {
        const Scene scene = test::stacked_sines(3, 100, 0.3, 0.5);
        CheckParams params;
        params.outside_sides = {outside_side(scene, 0), outside_side(scene, 1),
                                outside_side(scene, 2)};
        CHECK(check_scene(scene, params).is_collision_free());
        params.outside_sides[1] = -params.outside_sides[1];  // sine_1 upside down
        const CheckReport flipped = check_scene(scene, params);
        CHECK(flipped.crossing_count == 0);
        CHECK(flipped.nesting_violation_count > 0);
        for (const NestingViolation& v : flipped.nesting_violations) CHECK(v.other == 1);
        params.outside_sides = {1, 1};
        CHECK_THROWS_WITH(check_scene(scene, params),
                          Catch::Contains("outside_sides has 2 entries for 3 layers"));
        params.outside_sides = {1, 0, 1};
        CHECK_THROWS_WITH(check_scene(scene, params),
                          Catch::Contains("outside_sides[1] (layer 'sine_1') must be +1 or -1"));
    }
}

TEST_CASE("self-crossings", "[checks]") {
    SECTION("figure eight") {
        const Scene scene({make_layer("eight", {{0, 0}, {1, 1}, {1, 0}, {0, 1}}, true)});
        const CheckReport report = check_scene(scene);
        REQUIRE(report.self_crossing_count.size() == 1);
        CHECK(report.self_crossing_count[0] == 1);
        CHECK(report.total_self_crossings() == 1);
        REQUIRE(report.self_crossings.size() == 1);
        CHECK(report.self_crossings[0].segment_a == 0);
        CHECK(report.self_crossings[0].segment_b == 2);
        CHECK_FALSE(report.self_crossings[0].is_touch);
        CHECK(report.self_crossings[0].point.x == Approx(0.5));
        CHECK(report.self_crossings[0].point.y == Approx(0.5));
        CHECK_FALSE(report.is_collision_free());
    }
    SECTION("simple closed and open layers have none (the closing segment is adjacent)") {
        const Scene scene({make_layer("tri", {{0, 0}, {1, 0}, {0, 1}}, true),
                           make_layer("path", {{5, 0}, {6, 0}, {6, 1}, {5, 1}})});
        const CheckReport report = check_scene(scene);
        CHECK(report.total_self_crossings() == 0);
        CHECK(check_scene(test::spiral(3.0, 400)).total_self_crossings() == 0);
    }
    SECTION("an open fold-back") {
        const Scene scene({make_layer("fold", {{0, 0}, {2, 0}, {1, 0}})});
        const CheckReport report = check_scene(scene);
        CHECK(report.self_crossing_count[0] == 1);
        REQUIRE(report.self_crossings.size() == 1);
        CHECK(report.self_crossings[0].is_touch);
        CHECK(report.self_crossings[0].segment_a == 0);
        CHECK(report.self_crossings[0].segment_b == 1);
        CHECK(report.self_crossings[0].point == Vec2(1, 0));
    }
    SECTION("a straight continuation is no fold-back") {
        const Scene scene({make_layer("line", {{0, 0}, {1, 0}, {2, 0}})});
        CHECK(check_scene(scene).total_self_crossings() == 0);
    }
    SECTION("a fold-back across the closing vertex") {
        // The closing segment (2,0)-(0,0) runs back over segment 0, and through vertex (1, 0):
        // two contact locations, (0, 0) (fold-back of segments 4 and 0) and (1, 0) (segment 4
        // against segment 1).
        const Scene scene({make_layer("loop", {{0, 0}, {1, 0}, {1, 1}, {2, 1}, {2, 0}}, true)});
        const CheckReport report = check_scene(scene);
        CHECK(report.self_crossing_count[0] == 2);
        REQUIRE(report.self_crossings.size() == 2);
        CHECK(report.self_crossings[0].segment_a == 0);
        CHECK(report.self_crossings[0].segment_b == 4);
        CHECK(report.self_crossings[0].point == Vec2(0, 0));
        CHECK(report.self_crossings[1].segment_a == 1);
        CHECK(report.self_crossings[1].segment_b == 4);
    }
    SECTION("a vertex on a non-adjacent segment counts once") {
        // (1, 0) ends segment 2 and starts segment 3, and lies on segment 0.
        const Scene scene({make_layer("hook", {{0, 0}, {2, 0}, {2, 1}, {1, 0}, {1, -1}})});
        const CheckReport report = check_scene(scene);
        CHECK(report.self_crossing_count[0] == 1);
        REQUIRE(report.self_crossings.size() == 1);
        CHECK(report.self_crossings[0].point == Vec2(1, 0));
    }
    SECTION("zero-length segments left by set_points do not count") {
        Scene scene({make_layer("dup", {{0, 0}, {1, 0}, {2, 1}})});
        scene.set_points(0, {{0, 0}, {1, 0}, {1, 0}, {1, 0}, {2, 1}});
        CHECK(check_scene(scene).total_self_crossings() == 0);
    }
}

TEST_CASE("every real slice is collision-free", "[checks][slices]") {
    const char* files[] = {
        "cipc_multilayer_y+0.00.json",  "cipc_multilayer_y-0.15.json",
        "cipc_multilayer_y-0.30.json",  "mh_casualsuit03_y+1.50.json",
        "mh_casualsuit03_y+4.00.json",  "mh_casualsuit05_y+4.00.json",
        "mh_elegantsuit01_y+0.50.json", "mh_elegantsuit01_y+1.50.json",
    };
    for (const char* file : files) {
        INFO(file);
        const Scene scene = read_slice(file);
        const CheckReport report = check_scene(scene);
        CHECK(report.crossing_count == 0);
        CHECK(report.total_self_crossings() == 0);
        CHECK(report.nesting_violation_count == 0);
        CHECK(report.is_collision_free());
        for (const PairSeparation& pair : report.pairs) CHECK(pair.gap > 0.0);
    }
}
