#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/io/json_io.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"
#include "support/require.h"

#include <tbb/global_control.h>
#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

using namespace strata;

namespace {

constexpr double kPi = 3.14159265358979323846;

Layer circle(std::string name, Vec2 centre, double r, std::size_t n, double thickness = 0.0) {
    Layer layer;
    layer.name = std::move(name);
    layer.closed = true;
    layer.thickness = thickness;
    for (std::size_t i = 0; i < n; ++i) {
        const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        layer.points.push_back(centre + r * Vec2(std::cos(t), std::sin(t)));
    }
    return layer;
}

double max_move(const Scene& a, const Scene& b, std::size_t layer) {
    double d = 0.0;
    for (std::size_t v = 0; v < a.layer(layer).points.size(); ++v)
        d = std::max(d, glm::distance(a.layer(layer).points[v], b.layer(layer).points[v]));
    return d;
}

// Three open layers 0.15 apart, the middle one dented 0.25 down through the lower one over
// its 9 middle vertices: `segments` + 1 vertices a layer, 0.05 apart.
Scene dented_open_stack(int segments) {
    std::vector<Layer> open;
    for (int l = 0; l < 3; ++l) {
        Layer layer;
        layer.name = "open" + std::to_string(l);
        layer.thickness = 0.02;
        for (int i = 0; i <= segments; ++i) {
            const double x = 0.05 * i;
            const double dent = l == 1 && std::abs(2 * i - segments) < 10 ? 0.25 : 0.0;
            layer.points.emplace_back(x, 0.1 * std::sin(x) + 0.15 * l - dent);
        }
        open.push_back(std::move(layer));
    }
    return Scene(open);
}

UntangleParams exact_params() {
    UntangleParams params;
    params.field.backend = FieldBackend::ExactIndexed;
    return params;
}

}  // namespace

TEST_CASE("an inner circle poking out of its outer circle is pulled back in", "[untangle]") {
    for (FieldBackend backend :
         {FieldBackend::Grid, FieldBackend::ExactIndexed, FieldBackend::ExactBrute}) {
        Scene scene(
            {circle("inner", {0.3, 0.0}, 1.0, 64, 0.05), circle("outer", {0, 0}, 1.2, 64, 0.05)});
        REQUIRE(check_scene(scene).crossing_count == 2);
        UntangleParams params;
        params.field.backend = backend;
        const UntangleReport report = untangle(scene, params);
        CHECK(report.crossings_before == 2);
        CHECK(report.crossings_after == 0);
        CHECK(report.collision_free);
        test::require_collision_free(scene, 0.1);
    }
}

TEST_CASE("a much heavier layer barely moves", "[untangle]") {
    Scene light({circle("inner", {0.3, 0.0}, 1.0, 64), circle("outer", {0, 0}, 1.2, 64)});
    std::vector<Layer> layers = light.layers();
    layers[1].weight = 1000.0;
    Scene heavy(layers);
    const Scene before = heavy;
    untangle(light, exact_params());
    untangle(heavy, exact_params());
    test::require_collision_free(heavy, 0.1);
    CHECK(max_move(heavy, before, 1) < 0.05 * max_move(light, before, 1));
    CHECK(max_move(heavy, before, 0) > 0.09);  // the inner one made the room instead
}

TEST_CASE("stacked open layers keep order and separation", "[untangle]") {
    // Five stacked sines with thickness 0.1; the middle one is pushed down through two others.
    const Scene stack = test::stacked_sines(5, 120, 0.3, 0.25, 0.1);
    std::vector<Layer> layers = stack.layers();
    for (Vec2& p : layers[2].points)
        if (p.x > 4.0 && p.x < 7.0) p.y -= 0.6 * std::sin((p.x - 4.0) * kPi / 3.0);
    Scene scene(layers);
    REQUIRE(check_scene(scene).crossing_count > 0);
    const UntangleReport report = untangle(scene, exact_params());
    CHECK(report.collision_free);
    test::require_collision_free(scene, 0.1);
}

TEST_CASE("untangling gives the same result at 1 and 2 threads", "[untangle]") {
    // The projection steps run in parallel; sums are gathered in a fixed order.
    const Scene stack = test::stacked_sines(5, 120, 0.3, 0.25, 0.1);
    std::vector<Layer> layers = stack.layers();
    for (Vec2& p : layers[2].points)
        if (p.x > 4.0 && p.x < 7.0) p.y -= 0.6 * std::sin((p.x - 4.0) * kPi / 3.0);
    Scene one(layers), two(layers);
    UntangleReport r1, r2;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        r1 = untangle(one, exact_params());
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        r2 = untangle(two, exact_params());
    }
    CHECK(r1.collision_free);
    CHECK(r1.rounds == r2.rounds);
    for (std::size_t l = 0; l < one.size(); ++l) CHECK(one.layer(l).points == two.layer(l).points);
}

TEST_CASE("two loops side by side inside a third stay apart and inside", "[untangle]") {
    auto with_outer = [](Layer l, std::vector<std::string> outer) {
        l.outer = std::move(outer);
        return l;
    };
    Scene scene({with_outer(circle("leg_l", {-0.45, 0}, 0.6, 48, 0.02), {"skirt"}),
                 with_outer(circle("leg_r", {0.45, 0}, 0.6, 48, 0.02), {"skirt"}),
                 with_outer(circle("skirt", {0, 0}, 1.0, 96, 0.02), {})});
    const CheckReport before = check_scene(scene);
    REQUIRE(before.crossing_count > 0);  // the legs overlap each other and poke out
    const UntangleReport report = untangle(scene, exact_params());
    CHECK(report.collision_free);
    test::require_collision_free(scene, 0.1);
}

TEST_CASE("pure projection also untangles but does not keep the shape as well", "[untangle]") {
    Scene scene({circle("inner", {0.3, 0.0}, 1.0, 64), circle("outer", {0, 0}, 1.2, 64)});
    UntangleParams params = exact_params();
    params.shape = ShapeMode::None;
    const UntangleReport report = untangle(scene, params);
    CHECK(report.collision_free);
}

TEST_CASE("local untangling moves nothing outside the box", "[untangle][localize]") {
    Scene scene({circle("inner", {0.3, 0.0}, 1.0, 64), circle("outer", {0, 0}, 1.2, 64)});
    const Scene before = scene;
    const Box2 box{{0.8, -0.9}, {1.5, 0.9}};
    const UntangleReport report = untangle_local(scene, box, 7, exact_params());
    CHECK(report.collision_free);
    for (std::size_t l = 0; l < scene.size(); ++l)
        for (std::size_t v = 0; v < scene.layer(l).points.size(); ++v)
            if (!box.contains(before.layer(l).points[v]))
                CHECK(scene.layer(l).points[v] == before.layer(l).points[v]);
}

TEST_CASE("local untangling reports what a whole-scene check of its result says",
          "[untangle][localize]") {
    // Its checks look near the box only (RegionCheck): its report must still be the whole
    // scene's. Closed loops, and open layers with a dent pushed through the next one.
    std::vector<Scene> scenes;
    scenes.push_back(
        Scene({circle("inner", {0.3, 0.0}, 1.0, 64), circle("outer", {0, 0}, 1.2, 64)}));
    scenes.push_back(dented_open_stack(200));
    const std::vector<Box2> boxes = {Box2{{0.8, -0.9}, {1.5, 0.9}}, Box2{{4.6, -0.5}, {5.4, 0.6}}};
    for (std::size_t k = 0; k < scenes.size(); ++k) {
        Scene scene = scenes[k];
        const UntangleParams params = exact_params();
        CheckParams check;
        check.separation_tolerance = params.separation_tolerance;
        check.outside_sides = outside_sides(scenes[k]);
        const std::size_t before = check_scene(scenes[k], check).crossing_count;
        CHECK(before > 0);
        const UntangleReport report = untangle_local(scene, boxes[k], 7, params);
        const CheckReport after = check_scene(scene, check);
        CHECK(report.crossings_before == before);
        CHECK(report.crossings_after == after.crossing_count);
        CHECK(report.min_separation_ratio_after == after.min_separation_ratio);
        CHECK(report.collision_free == (after.is_collision_free() && after.separations_hold()));
        CHECK(report.collision_free);
    }
}

TEST_CASE("local untangling with grid fields of its box gives the whole grid's result",
          "[untangle][localize]") {
    // untangle_local() builds the grid only around its free vertices (FieldParams::region):
    // every sample it takes reads what the whole grid (a region over the whole scene) reads.
    const std::vector<Scene> scenes = {
        Scene({circle("inner", {0.3, 0.0}, 1.0, 256), circle("outer", {0, 0}, 1.2, 256)}),
        dented_open_stack(400)};
    const std::vector<Box2> boxes = {Box2{{0.8, -0.9}, {1.5, 0.9}}, Box2{{9.6, -0.5}, {10.4, 0.6}}};
    for (std::size_t k = 0; k < scenes.size(); ++k) {
        UntangleParams params;
        params.field.backend = FieldBackend::Grid;
        Scene part = scenes[k];
        const UntangleReport a = untangle_local(part, boxes[k], 7, params);
        params.field.region = scenes[k].bounds();
        Scene whole = scenes[k];
        const UntangleReport b = untangle_local(whole, boxes[k], 7, params);
        INFO("scene " << k);
        CHECK(a.collision_free);
        CHECK(a.crossings_before > 0);
        CHECK(a.rounds == b.rounds);
        for (std::size_t l = 0; l < part.size(); ++l)
            CHECK(part.layer(l).points == whole.layer(l).points);
    }
}

TEST_CASE("an untangling that cannot finish in its passes gives up early when asked",
          "[untangle]") {
    // Two straight layers 0.05 apart that must keep 0.2, with steps clamped to 0.05% of an
    // edge (0.25 mm here): 16 passes of 10 steps cannot move them 0.15 apart, and the worst
    // violation falls too slowly for the stall rule's extrapolation.
    const auto line = [](const char* name, double y) {
        Layer layer;
        layer.name = name;
        layer.thickness = 0.2;
        for (int i = 0; i <= 8; ++i) layer.points.emplace_back(0.5 * i, y);
        return layer;
    };
    const Scene input({line("lower", 0.0), line("upper", 0.05)});
    UntangleParams params = exact_params();
    params.gradient_steps = 10;
    params.max_rounds = 1;
    params.max_passes = 16;
    params.max_step_fraction = 0.0005;
    params.finish_separations = false;  // the finishing stage would push them apart at once
    Scene all_passes = input;
    const UntangleReport full = untangle(all_passes, params);
    CHECK_FALSE(full.collision_free);
    CHECK_FALSE(full.gave_up);
    CHECK(full.tries == 2);  // the second try (no self-crossing made) fails alike
    CHECK(full.passes == 2 * 16);
    params.give_up_when_stalled = true;
    Scene given_up = input;
    const UntangleReport early = untangle(given_up, params);
    CHECK_FALSE(early.collision_free);
    CHECK(early.gave_up);
    CHECK(early.tries == 2);
    CHECK(early.passes == 2 * 5);  // the rule looks from the fifth pass on
    // With steps of up to 0.2% of an edge the same untangling succeeds (in 8 passes), and the
    // rule does not give up on it.
    params.max_step_fraction = 0.002;
    Scene free_to_move = input;
    const UntangleReport ok = untangle(free_to_move, params);
    CHECK(ok.collision_free);
    CHECK_FALSE(ok.gave_up);
}

TEST_CASE("naive decimation of real slices is untangled", "[untangle][slices]") {
    for (const char* name : {"mh_elegantsuit01_y+0.50.json", "mh_casualsuit03_y+1.50.json",
                             "cipc_multilayer_y+0.00.json"}) {
        INFO(name);
        const Scene input = read_scene_json(test::test_data(std::string("slices/") + name));
        // Keep every third vertex (ends of open layers kept): a naive decimation.
        std::vector<Layer> layers = input.layers();
        for (Layer& l : layers) {
            std::vector<Vec2> kept;
            for (std::size_t i = 0; i < l.points.size(); ++i)
                if (i % 3 == 0 || (!l.closed && i + 1 == l.points.size()))
                    kept.push_back(l.points[i]);
            l.points = kept;
        }
        Scene scene(layers);
        const CheckReport naive = check_scene(scene);
        UNSCOPED_INFO("naive crossings " << naive.crossing_count << ", nesting "
                                         << naive.nesting_violation_count);
        const UntangleReport report = untangle(scene, exact_params());
        CHECK(report.collision_free);
        const CheckReport after = check_scene(scene);
        CHECK(after.crossing_count == 0);
        CHECK(after.nesting_violation_count == 0);
    }
}

TEST_CASE("real slices whose suit pieces cross side by side are untangled", "[untangle][slices]") {
    // Issues 13 and 15: open suit pieces side by side (no side asked of either) that the
    // input already crosses, near their ends. untangle() with its defaults must leave no
    // crossing or self-crossing, keep the nesting and keep the gaps (0.9 x the required
    // separation, or the input's own ratio when it is below that).
    for (const char* name : {"mh_casualsuit05_y+2.50.json", "mh_casualsuit05_y+6.00.json",
                             "mh_casualsuit05_y+6.50.json"}) {
        INFO(name);
        Scene scene = read_scene_json(test::test_data(std::string("crossing_slices/") + name));
        const double input_ratio = check_scene(scene).min_separation_ratio;
        REQUIRE_FALSE(check_scene(scene).is_collision_free());
        const UntangleReport report = untangle(scene);
        CHECK(report.collision_free);
        const CheckReport after = check_scene(scene);
        CHECK(after.crossing_count == 0);
        CHECK(after.total_self_crossings() == 0);
        CHECK(after.nesting_violation_count == 0);
        CHECK(after.min_separation_ratio >= 0.9 * std::min(1.0, input_ratio));
    }
}

TEST_CASE("bad untangle parameters are rejected by name", "[untangle]") {
    Scene scene = test::nested_circles(2, 16);
    UntangleParams params;
    params.step = 0.0;
    CHECK_THROWS_WITH(untangle(scene, params),
                      Catch::Contains("params.step") && Catch::Contains("got 0"));
    params = {};
    params.alpha = 2.0;
    CHECK_THROWS_WITH(untangle(scene, params), Catch::Contains("params.alpha"));
    params = {};
    params.short_edge_fraction = -0.1;
    CHECK_THROWS_WITH(untangle(scene, params), Catch::Contains("params.short_edge_fraction"));
}

TEST_CASE("a real armpit slice comes out clean by the first try", "[untangle][slices]") {
    // casualsuit05 at 6.55 dm: a sleeve piece threads through two torso pieces (5 crossings).
    // With the nesting strata slice wrote before its pieces-on-each-other's-outer-side rule
    // (suit_1 and suit_6 under suit_5), every try failed (53 tries, 93 s, 22 nesting
    // violations left); with the nesting it writes now the input's nesting holds and the
    // first try is clean.
    Scene scene = read_scene_json(test::test_data("mh_casualsuit05_y+6.55.json"));
    REQUIRE(check_scene(scene).crossing_count == 5);
    REQUIRE(check_scene(scene).nesting_violation_count == 0);
    const UntangleReport report = untangle_inferring_sides(scene);
    CHECK(report.collision_free);
    CHECK(report.tries == 1);
    const CheckReport after = check_scene(scene);
    CHECK(after.crossing_count == 0);
    CHECK(after.total_self_crossings() == 0);
    CHECK(after.nesting_violation_count == 0);
}

TEST_CASE("nearly coincident vertices do not hold each other still", "[untangle][slices]") {
    // A slice of the Codim-IPC skirt at 0.69 m: the tip of a thin closed band (two vertices
    // 3.6e-5 m apart, the median segment 3.3e-3 m) pokes into the next tier's loop, side by
    // side, about 1e-3 m deep. Bounded by their 3.6e-5 m edge (UntangleParams::
    // short_edge_fraction 0, the default), the tip's steps cannot get it out; past that edge
    // they do.
    const Scene input = read_scene_json(test::test_data("cipc_multilayer_y+0.69.json"));
    REQUIRE(check_scene(input).crossing_count == 2);
    Scene held = input;
    CHECK_FALSE(untangle(held).collision_free);

    UntangleParams passed;
    passed.short_edge_fraction = 0.1;
    Scene scene = input;
    const UntangleReport report = untangle(scene, passed);
    CHECK(report.collision_free);
    const CheckReport after = check_scene(scene);
    CHECK(after.crossing_count == 0);
    CHECK(after.total_self_crossings() == 0);
    CHECK(after.nesting_violation_count == 0);
    // Only the tip moves far: no vertex by more than a few times the poke's depth.
    CHECK(report.max_displacement < 0.005);
}

TEST_CASE("untangle_inferring_sides: the short edges passed when everything else fails",
          "[untangle][slices]") {
    // The same slice: every try fails with the default short_edge_fraction (0); the last retry
    // passes the short edges (retry_short_edge_fraction). The other retries and last resorts
    // are off here to keep the test short: they fail on this slice too (19 tries).
    const Scene input = read_scene_json(test::test_data("cipc_multilayer_y+0.69.json"));
    UntangleParams params;
    params.other_readings = 0;
    params.long_rounds_factor = 1;
    params.retry_passes_factor = 1.0;
    params.more_passes_factor = 1;
    params.retry_ends_by_nearest = params.loop_readings = false;
    params.untwist = params.retract_ends = params.restart = false;
    UntangleParams without = params;
    without.retry_short_edge_fraction = 0.0;
    Scene failed = input;
    const UntangleReport before = untangle_inferring_sides(failed, without);
    CHECK_FALSE(before.collision_free);
    CHECK_FALSE(before.short_edges);

    Scene scene = input;
    const UntangleReport report = untangle_inferring_sides(scene, params);
    CHECK(report.collision_free);
    CHECK(report.short_edges);
    CHECK(report.tries == before.tries + 1);
    CHECK(check_scene(scene).is_collision_free());
    CHECK(report.crossings_before == 2);
}