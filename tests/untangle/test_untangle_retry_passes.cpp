// UntangleParams::retry_passes_factor (issue 13): when every try of untangle_inferring_sides()
// fails, long rounds included, they all run once more with max_passes x the factor.

#include "strata/geometry/checks.h"
#include "strata/simplify/scene_families.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

using namespace strata;

TEST_CASE("untangle_inferring_sides: every try once more with more passes when all fail",
          "[untangle]") {
    // The benchmark's folded stack (4 layers of 300 points), 95% removed at random, seed 19:
    // the global order's first try comes out clean after 9 passes. With a cap of 6 every try
    // fails; the retry with 1.5 x 6 = 9 passes cleans it.
    FamilyParams p;
    p.layers = 4;
    const Scene input = make_scene(SceneFamily::Folded, p);
    const Scene tangled = test::naive_decimation(input, 0.95, 19);
    REQUIRE(check_scene(tangled).crossing_count > 0);
    UntangleParams params;
    params.max_passes = 6;
    params.long_rounds_factor = 1;  // the retry alone
    params.more_passes_factor = 1;
    params.other_readings = 0;
    params.loop_readings = params.untwist = params.retract_ends = params.restart =
        false;  // the retry alone
    params.retry_short_edge_fraction = 0.0;
    UntangleParams without = params;
    without.retry_passes_factor = 1.0;
    without.retry_ends_by_nearest = false;  // which cleans it too, after every retry
    Scene failed = tangled;
    const UntangleReport before = untangle_inferring_sides(failed, without);
    CHECK_FALSE(before.collision_free);
    CHECK_FALSE(before.retry_passes);

    Scene out = tangled;
    const UntangleReport report = untangle_inferring_sides(out, params);
    CHECK(report.collision_free);
    CHECK(report.retry_passes);
    CHECK(report.tries > before.tries);  // the failed tries count too
    CHECK(report.passes > before.passes);
    const CheckReport c = test::check_against(out, input);
    CHECK(c.is_collision_free());
    CHECK(c.separations_hold());
    CHECK(c.total_self_crossings() == 0);

    // A scene that every try cleans within the cap never gets the retry.
    Scene first = tangled;
    UntangleParams enough = params;
    enough.max_passes = 64;
    const UntangleReport clean = untangle_inferring_sides(first, enough);
    CHECK(clean.collision_free);
    CHECK_FALSE(clean.retry_passes);
}
