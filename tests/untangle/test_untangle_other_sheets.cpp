// Untangling with the original's sides (`strata untangle --reference`) where the naive random
// decimation closed a fold of an open layer, so that a vertex lies nearer the fold's other sheet
// (running the other way) than its own: its recorded side, read at that sheet, asks for the
// wrong side of the whole fold (InputSides::off_other_sheets(), issue 19).

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/simplify/scene_families.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

#include <cstddef>
#include <optional>

using namespace strata;
using test::naive_decimation;

TEST_CASE("untangle with the original's sides leaves out a side read at a fold's other sheet",
          "[untangle][rolled]") {
    // Out of sample with --reference (300 points a layer, seeds 49-96). The shirt at 90%, seed
    // 76: the shirt's roll, decimated, lies over its main part; body vertices 23-25 are 0.038
    // from the roll's return chord and 0.041 from the main part, so their side "under the
    // shirt", read at the return chord, pushed them through the fold: clean by the tries' own
    // vertices' sides but moved 1.85 (the body collapsed into the fold), 3 nesting violations
    // by the original matched by position. The collar at 95%, seed 64: exit 1 (4 crossings).
    struct Case {
        SceneFamily family;
        double remove;
        unsigned seed;
        std::size_t off;  // vertices whose side is left out
    };
    for (const Case& c :
         {Case{SceneFamily::ShirtRoll, 0.9, 76u, 3}, Case{SceneFamily::CollarWrap, 0.95, 64u, 2}}) {
        INFO(family_name(c.family) << " at " << c.remove << ", seed " << c.seed);
        FamilyParams family;
        family.points = 300;
        const Scene input = make_scene(c.family, family);
        const Scene tangled = naive_decimation(input, c.remove, c.seed);
        REQUIRE(check_scene(tangled).crossing_count > 0);
        const InputSides recorded = record_input_sides(input);
        const InputSides sides = InputSides::matched(recorded, input, tangled);
        const InputSides kept = sides.off_other_sheets(tangled);
        std::size_t off = 0, changed = 0;
        for (std::size_t a = 0; a < tangled.size(); ++a)
            for (std::size_t b = 0; b < tangled.size(); ++b)
                for (std::size_t k = 0; k < tangled.layer(a).points.size(); ++k) {
                    if (kept.beyond_end(a, k, b) && sides.side(a, k, b) != 0) ++off;
                    if (kept.side(a, k, b) != sides.side(a, k, b) ||
                        kept.beyond_end(a, k, b) != sides.beyond_end(a, k, b))
                        ++changed;
                }
        CHECK(off == c.off);
        CHECK(changed == off);  // nothing else changes
        UntangleParams params;
        params.outside_sides = outside_sides(input);
        // Judged as `strata check OUT --reference ORIG` judges: every vertex takes the sides of
        // the original's vertex nearest to where it ended.
        auto is_clean = [&](const Scene& out) {
            return test::check_by_original(out, input).is_collision_free();
        };
        params.input_sides = &kept;
        Scene out = tangled;
        const UntangleReport report = untangle_inferring_sides(out, params);
        CHECK(report.collision_free);
        CHECK(is_clean(out));
        CHECK(report.max_displacement < 1.5);
        // Given every matched side, untangle_inferring_sides() leaves those out first: the same
        // result, the sides left out counted and handed back.
        params.input_sides = &sides;
        Scene given = tangled;
        InputSides handed;
        const UntangleReport r = untangle_inferring_sides(given, params, {}, &handed);
        CHECK(r.collision_free);
        CHECK(r.sides_left_out == c.off);
        for (std::size_t l = 0; l < given.size(); ++l)
            CHECK(given.layer(l).points == out.layer(l).points);
        std::size_t differ = 0;
        for (std::size_t a = 0; a < tangled.size(); ++a)
            for (std::size_t b = 0; b < tangled.size(); ++b)
                for (std::size_t k = 0; k < tangled.layer(a).points.size(); ++k)
                    differ += handed.side(a, k, b) != kept.side(a, k, b);
        CHECK(differ == 0);
        // untangle() with every matched side (its two tries): not clean (what the sides left
        // out are for).
        Scene before = tangled;
        const UntangleReport old = untangle(before, params);
        CHECK_FALSE((old.collision_free && is_clean(before)));
    }
}
