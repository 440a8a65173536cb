// The last resorts of untangle_inferring_sides(), when every try has failed: the readings of a
// small loop read on both sides of an open layer (UntangleParams::loop_readings), the
// untwisting of the least tangled result's self-crossings (UntangleParams::untwist), its ends
// retracted (UntangleParams::retract_ends) and the tries once more from that result
// (UntangleParams::restart). docs/untangle.md, "When every try fails".

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/scene_families.h"
#include "strata/untangle/outside_sides.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <utility>
#include <vector>

using namespace strata;

namespace {

Scene last_resort_scene(const std::string& name) {
    return read_scene(test::test_data("last_resort/" + name + ".json"));
}

UntangleParams without_last_resorts() {
    UntangleParams params;
    params.loop_readings = false;
    params.untwist = false;
    params.retract_ends = false;
    params.restart = false;
    params.retry_short_edge_fraction = 0.0;  // the retry after the last resorts
    return params;
}

// untangle_inferring_sides() of `tangled` with `params`, then with the last resort `resort` on
// too (its result in `out`): the two reports, without and with.
std::pair<UntangleReport, UntangleReport> without_then_with(const Scene& tangled,
                                                            UntangleParams params,
                                                            bool UntangleParams::*resort,
                                                            Scene& out) {
    Scene failed = tangled;
    const UntangleReport without = untangle_inferring_sides(failed, params);
    params.*resort = true;
    out = tangled;
    return {without, untangle_inferring_sides(out, params)};
}

}  // namespace

TEST_CASE("untangle_inferring_sides: the least tangled result untwisted when every try fails",
          "[untangle]") {
    // The shirt at 95%, seed 75: the roll's return chord crosses the shirt's main part, a
    // self-crossing of the input that no try takes out; every try ends with it alone.
    const Scene tangled = last_resort_scene("shirt_roll-0.95-75");
    REQUIRE(check_scene(tangled).total_self_crossings() == 1);
    Scene out;
    const auto [before, report] =
        without_then_with(tangled, without_last_resorts(), &UntangleParams::untwist, out);
    CHECK_FALSE(before.collision_free);
    CHECK(before.self_crossings_after == 1);
    CHECK_FALSE(before.untwisted);
    CHECK(report.collision_free);
    CHECK(report.untwisted);
    CHECK(report.tries > before.tries);
    CHECK(report.max_displacement > 0.0);
    const CheckReport c = check_scene(out);
    CHECK(c.crossing_count == 0);
    CHECK(c.total_self_crossings() == 0);
    const CheckReport against =
        test::check_by_original(out, make_scene(SceneFamily::ShirtRoll, {}));
    CHECK(against.is_collision_free());
    CHECK(against.separations_hold());
}

TEST_CASE("untangle_inferring_sides: an input no try improves on is untwisted too", "[untangle]") {
    // A loop pinched at a point it passes twice (a slice through a saddle vertex of its mesh:
    // the body at x = 2.5 dm), inside another: no crossing between layers, one self-touch that
    // no try takes out. Every try ties with the input, which is kept; untwisting it (a vertex
    // moved off the other strand by a hair) and one more try from there is clean.
    Layer pinched;
    pinched.name = "pinched";
    pinched.points = {{0, 0}, {1, 1}, {2, 0}, {1, -1}, {0, 0}, {-1, -1}, {-2, 0}, {-1, 1}};
    pinched.closed = true;
    Layer around;
    around.name = "around";
    for (int k = 0; k < 32; ++k)
        around.points.emplace_back(4.0 * std::cos(k * M_PI / 16.0),
                                   4.0 * std::sin(k * M_PI / 16.0));
    around.closed = true;
    const Scene tangled({pinched, around});
    REQUIRE(check_scene(tangled).crossing_count == 0);
    REQUIRE(check_scene(tangled).total_self_crossings() == 1);
    Scene out;
    const auto [before, report] =
        without_then_with(tangled, without_last_resorts(), &UntangleParams::untwist, out);
    CHECK_FALSE(before.collision_free);
    CHECK(before.input_kept);
    CHECK(report.collision_free);
    CHECK(report.untwisted);
    CHECK(report.max_displacement < 1e-6);
    const CheckReport c = check_scene(out);
    CHECK(c.crossing_count == 0);
    CHECK(c.total_self_crossings() == 0);
}

TEST_CASE("untangle_inferring_sides: a small loop read on both sides of a layer read on one",
          "[untangle]") {
    // The collar at 95%, seed 57: by_region() reads the cord in the collar's fold `-+++-`
    // (three regions, each agreeing with itself; the original has `+++++`), and no other
    // reading changes it. Every try fails; the loop's majority side for all of it is clean.
    const Scene tangled = last_resort_scene("collar_wrap-0.95-57");
    const std::vector<int> outside = untangling_outside_sides(tangled);
    const InputSides inferred = infer_input_sides(tangled, {}, outside);
    const std::vector<InputSides> loops = inferred.loop_readings(tangled);
    REQUIRE(loops.size() == 2);  // the cord against the collar: + then -
    for (std::size_t k = 0; k < tangled.layer(1).points.size(); ++k) {
        CHECK(loops[0].side(1, k, 2) == 1);
        CHECK(loops[1].side(1, k, 2) == -1);
    }
    Scene out;
    const auto [before, report] =
        without_then_with(tangled, without_last_resorts(), &UntangleParams::loop_readings, out);
    CHECK_FALSE(before.collision_free);
    CHECK(report.collision_free);
    CHECK(report.loop_reading);
    CHECK(report.inferred_sides);
    CHECK(report.sides_reading == 1);
}

TEST_CASE("untangle_inferring_sides: the tries once more from the least tangled result",
          "[untangle]") {
    // The collar at 90%, seed 72, with the original's sides: every try fails (2 crossings of
    // the cord and the collar left at best); from that result the tries are clean.
    const Scene tangled = last_resort_scene("collar_wrap-0.9-72");
    const Scene original = make_scene(SceneFamily::CollarWrap, {});
    const InputSides recorded = record_input_sides(original);
    const InputSides sides = InputSides::matched(recorded, original, tangled);
    UntangleParams params = without_last_resorts();
    params.input_sides = &sides;
    params.outside_sides = untangling_outside_sides(original);
    Scene out;
    const auto [before, report] = without_then_with(tangled, params, &UntangleParams::restart, out);
    CHECK_FALSE(before.collision_free);
    CHECK_FALSE(before.restarted);
    CHECK(report.collision_free);
    CHECK(report.restarted);
    CHECK(report.tries > before.tries);
    const CheckReport against = test::check_by_original(out, original);
    CHECK(against.is_collision_free());
    CHECK(against.separations_hold());
}

TEST_CASE("untangle_inferring_sides: an end on the wrong side of a corner is retracted",
          "[untangle]") {
    // The folded stack at 90%, seed 97 (out of sample): the least tangled result of every try
    // has no crossing, but the first layer's start lies closest to a corner of the outermost
    // layer (its decimated bend), on the corner's wrong side. Every try fails from this scene
    // with the default params too (20 tries, 22 s); here they run short. Moving that end back
    // along its own segment is clean.
    const Scene tangled = last_resort_scene("folded-0.9-97-least-tangled");
    const CheckReport input = check_scene(tangled);
    REQUIRE(input.crossing_count == 0);
    REQUIRE(input.nesting_violation_count == 1);
    REQUIRE(input.nesting_violations[0].vertex == 0);
    UntangleParams params = without_last_resorts();
    params.max_passes = 1;
    params.gradient_steps = 1;
    params.other_readings = 0;
    params.long_rounds_factor = 1;
    params.more_passes_factor = 1;
    params.retry_passes_factor = 1.0;
    Scene out;
    const auto [before, report] =
        without_then_with(tangled, params, &UntangleParams::retract_ends, out);
    CHECK_FALSE(before.collision_free);
    CHECK(before.ends_retracted == 0);
    CHECK(report.collision_free);
    CHECK(report.ends_retracted == 1);
    FamilyParams folded;  // as strata_bench_untangle makes it
    folded.layers = 4;
    const CheckReport against =
        test::check_by_original(out, make_scene(SceneFamily::Folded, folded));
    CHECK(against.is_collision_free());
    CHECK(against.separations_hold());
    // The end moved back along its segment: by less than the segment's length.
    const std::vector<Vec2>& a = tangled.layer(0).points;
    const std::vector<Vec2>& b = out.layer(0).points;
    CHECK(glm::distance(a[0], b[0]) < glm::distance(a[0], a[1]));
}
