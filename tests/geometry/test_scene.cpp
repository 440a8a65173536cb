#include "strata/core/error.h"
#include "strata/geometry/scene.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace strata;
using Catch::Matchers::Contains;

namespace {

Layer make_layer(std::string name, std::vector<Vec2> points, bool closed = false,
                 double thickness = 0.0) {
    Layer layer;
    layer.name = std::move(name);
    layer.points = std::move(points);
    layer.closed = closed;
    layer.thickness = thickness;
    return layer;
}

Layer with_outer(Layer layer, std::vector<std::string> outer) {
    layer.outer = std::move(outer);
    return layer;
}

const std::vector<Vec2> kTriangle{{0, 0}, {1, 0}, {0, 1}};

}  // namespace

TEST_CASE("a scene without outer links is one stack in file order", "[scene]") {
    const Scene scene = test::nested_circles(4, 16, 1.0, 0.25, 0.1);
    REQUIRE(scene.is_implicit_stack());
    CHECK(scene.outer_of(0) == std::vector<std::size_t>{1});
    CHECK(scene.inner_of(3) == std::vector<std::size_t>{2});
    CHECK(scene.relation(0, 3) == Relation::Under);
    CHECK(scene.relation(3, 0) == Relation::Over);
    CHECK(scene.relation(2, 2) == Relation::Same);
    // Separation sums half thicknesses along the chain: 3 links of (0.1 + 0.1) / 2.
    CHECK(scene.required_separation(0, 1) == Approx(0.1));
    CHECK(scene.required_separation(0, 3) == Approx(0.3));
    CHECK(scene.required_separation(3, 0) == Approx(0.3));
    CHECK(scene.vertex_count() == 64);
}

TEST_CASE("outer links give a DAG with side-by-side layers", "[scene]") {
    // Two legs inside one skirt tier, which is inside a coat.
    const Scene scene({with_outer(make_layer("leg_l", kTriangle, true, 0.2), {"skirt"}),
                       with_outer(make_layer("leg_r", kTriangle, true, 0.4), {"skirt"}),
                       with_outer(make_layer("skirt", kTriangle, true, 0.1), {"coat"}),
                       with_outer(make_layer("coat", kTriangle, true, 0.3), {})});
    REQUIRE_FALSE(scene.is_implicit_stack());
    CHECK(scene.relation(0, 1) == Relation::SideBySide);
    CHECK(scene.relation(1, 3) == Relation::Under);
    CHECK(scene.required_separation(0, 1) == Approx(0.3));         // (0.2 + 0.4) / 2
    CHECK(scene.required_separation(1, 2) == Approx(0.25));        // (0.4 + 0.1) / 2
    CHECK(scene.required_separation(1, 3) == Approx(0.25 + 0.2));  // + (0.1 + 0.3) / 2
}

TEST_CASE("separation along several chains takes the longest one", "[scene]") {
    // a -> b -> d and a -> c -> d, with c thick.
    const Scene scene({with_outer(make_layer("a", kTriangle, true, 0.0), {"b", "c"}),
                       with_outer(make_layer("b", kTriangle, true, 0.0), {"d"}),
                       with_outer(make_layer("c", kTriangle, true, 1.0), {"d"}),
                       with_outer(make_layer("d", kTriangle, true, 0.0), {})});
    CHECK(scene.required_separation(0, 3) == Approx(1.0));  // 0.5 + 0.5 through c
    CHECK(scene.required_separation(0, 1) == Approx(0.0));
    CHECK(scene.relation(1, 2) == Relation::SideBySide);
}

TEST_CASE("exact consecutive duplicates are removed and counted", "[scene]") {
    const Scene scene({make_layer("a", {{0, 0}, {0, 0}, {1, 0}, {1, 0}, {1, 0}, {2, 1}}),
                       make_layer("b", {{0, 1}, {1, 1}, {1, 2}, {0, 1}}, true)});
    CHECK(scene.layer(0).points.size() == 3);
    CHECK(scene.layer(1).points.size() == 3);  // the closing duplicate of a closed layer too
    CHECK(scene.diagnostics().removed_duplicates == 4);
    REQUIRE(scene.diagnostics().notes.size() == 2);
    CHECK_THAT(scene.diagnostics().notes[0], Contains("'a'") && Contains("removed 3"));
}

TEST_CASE("bad layers are rejected naming layer, point and value", "[scene]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(Scene({make_layer("a", {{0, 0}, {1, nan}, {2, 0}})}),
                      Contains("layer 'a'") && Contains("point 1") && Contains("nan"));
    CHECK_THROWS_WITH(Scene({make_layer("a", {{0, 0}, {0, 0}})}),
                      Contains("layer 'a'") && Contains("at least 2") && Contains("got 1"));
    CHECK_THROWS_WITH(Scene({make_layer("a", {{0, 0}, {1, 0}}, true)}),
                      Contains("closed") && Contains("at least 3") && Contains("got 2"));
    CHECK_THROWS_WITH(Scene({make_layer("a", kTriangle, false, -1.0)}),
                      Contains("thickness") && Contains("got -1"));
    Layer heavy = make_layer("w", kTriangle);
    heavy.weight = 0.0;
    CHECK_THROWS_WITH(Scene({heavy}), Contains("weight") && Contains("got 0"));
    Layer stiff = make_layer("s", kTriangle);
    stiff.alpha = 1.5;
    CHECK_THROWS_WITH(Scene({stiff}), Contains("alpha") && Contains("got 1.5"));
    CHECK_THROWS_WITH(Scene({make_layer("", kTriangle)}), Contains("name must not be empty"));
    CHECK_THROWS_WITH(Scene({make_layer("a", kTriangle), make_layer("a", kTriangle)}),
                      Contains("'a'") && Contains("already used"));
    CHECK_THROWS_AS(Scene({make_layer("a", kTriangle, false, std::nan(""))}), InvalidInput);
}

TEST_CASE("outer names must exist and form no cycle", "[scene]") {
    CHECK_THROWS_WITH(Scene({with_outer(make_layer("a", kTriangle), {"ghost"})}),
                      Contains("layer 'a'") && Contains("'ghost'") && Contains("not a layer"));
    CHECK_THROWS_WITH(Scene({with_outer(make_layer("a", kTriangle), {"b"}),
                             with_outer(make_layer("b", kTriangle), {"c"}),
                             with_outer(make_layer("c", kTriangle), {"a"})}),
                      Contains("cycle") && Contains("'a'") && Contains("'b'") && Contains("'c'"));
    CHECK_THROWS_WITH(Scene({with_outer(make_layer("self", kTriangle), {"self"})}),
                      Contains("cycle: 'self' -> 'self'"));
}

TEST_CASE("set_points validates and leaves the scene unchanged on throw", "[scene]") {
    Scene scene = test::nested_circles(2, 8);
    const auto before = scene.layer(0).points;
    CHECK_THROWS_AS(scene.set_points(0, {{0, 0}, {1, 0}}), InvalidInput);
    CHECK(scene.layer(0).points == before);
    scene.set_points(0, {{0, 0}, {1, 0}, {0, 1}});
    CHECK(scene.layer(0).points.size() == 3);
}
