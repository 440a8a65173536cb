// Untangling with the original's sides (`strata untangle --reference`) where the naive random
// decimation cut a roll's bend to one sharp vertex, a hairpin, and left a vertex of another layer
// beyond its tip (UntangleParams::open_cut_bends, issue 19): the tip moves past that vertex
// rather than the projection dragging the vertex and its layer around the tip.

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/simplify/scene_families.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

using namespace strata;
using test::naive_decimation;

TEST_CASE("untangle with the original's sides opens a roll's bend the decimation cut",
          "[untangle][rolled]") {
    // The rolled families' `untangle --reference` runs (docs/untangle.md,
    // "Cut bends"): 600 points a layer, naive random decimation. Not clean before: the collar at
    // 90%, seed 2 (the cord beyond the tip of the collar's cut fold; the projection dragged it
    // and the body through the fold: 18 crossings, exit 1), and the shirt at 95%, seed 9 (the
    // jacket beyond the tip of the shirt's cut roll; clean by its own vertices' sides, but the
    // layers dragged up to 1.6 units, so that the shirt's roll lies where the original has its
    // main part: 4 nesting violations by the original matched by position).
    struct Case {
        SceneFamily family;
        double remove;
        unsigned seed;
    };
    for (const Case& c :
         {Case{SceneFamily::CollarWrap, 0.9, 2u}, Case{SceneFamily::ShirtRoll, 0.95, 9u}}) {
        INFO(family_name(c.family) << " at " << c.remove << ", seed " << c.seed);
        FamilyParams family;
        family.points = 600;
        const Scene input = make_scene(c.family, family);
        const Scene tangled = naive_decimation(input, c.remove, c.seed);
        REQUIRE(check_scene(tangled).crossing_count > 0);
        const InputSides recorded = record_input_sides(input);
        const InputSides sides = InputSides::matched(recorded, input, tangled);
        UntangleParams params;
        params.outside_sides = outside_sides(input);
        params.input_sides = &sides;
        // Judged as `strata check OUT --reference ORIG` judges: every vertex takes the sides of
        // the original's vertex nearest to where it ended.
        auto is_clean = [&](const Scene& out) {
            const InputSides judged = InputSides::matched(recorded, input, out);
            CheckParams scoring;
            scoring.outside_sides = params.outside_sides;
            scoring.input_sides = &judged;
            return check_scene(out, scoring).is_collision_free();
        };
        Scene out = tangled;
        const UntangleReport report = untangle(out, params);
        CHECK(report.collision_free);
        CHECK(is_clean(out));
        // Without opening the cut bend: not clean (what the test is for).
        UntangleParams before = params;
        before.open_cut_bends = false;
        Scene dragged = tangled;
        const UntangleReport old = untangle(dragged, before);
        CHECK_FALSE((old.collision_free && is_clean(dragged)));
        // The tries dragged the layers: further than with the bend opened, or (the collar)
        // into a result more tangled than the input, which is then kept unchanged.
        CHECK((old.input_kept || report.max_displacement < old.max_displacement));
    }
}
