#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/simplify/scene_families.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

using namespace strata;

TEST_CASE("every generated family is a valid, untangled scene with its gaps", "[families]") {
    for (SceneFamily family : all_scene_families()) {
        for (double gap : {0.5, 2.0, 4.0}) {
            INFO(family_name(family) << " gap " << gap);
            FamilyParams params;
            params.points = 200;
            params.layers = family == SceneFamily::Folded ? 4 : 6;
            params.gap = gap;
            const Scene scene = make_scene(family, params);
            const CheckReport check = check_scene(scene);
            CHECK(check.crossing_count == 0);
            CHECK(check.total_self_crossings() == 0);
            // The rolled families break the global order on purpose (the roll lies on top),
            // and keep it against their own sides.
            if (!is_rolled(family)) {
                CHECK(check.nesting_violation_count == 0);
                CHECK(check.min_separation_ratio >= 0.9);
            } else {
                CHECK(check.nesting_violation_count > 0);
                const InputSides sides = record_input_sides(scene);
                CheckParams own;
                own.input_sides = &sides;
                const CheckReport kept = check_scene(scene, own);
                CHECK(kept.nesting_violation_count == 0);
                CHECK(kept.min_separation_ratio >= 0.9);
            }
        }
    }
}

TEST_CASE("the unrolled counterparts keep the global order with as many vertices", "[families]") {
    std::size_t rolled_families = 0;
    for (SceneFamily family : all_scene_families()) {
        if (!is_rolled(family)) continue;
        ++rolled_families;
        for (double gap : {0.5, 2.0, 4.0}) {
            INFO(family_name(family) << " gap " << gap);
            FamilyParams params;
            params.points = 300;
            params.gap = gap;
            const Scene rolled = make_scene(family, params);
            params.unrolled = true;
            const Scene unrolled = make_scene(family, params);
            REQUIRE(unrolled.size() == rolled.size());
            for (std::size_t l = 0; l < rolled.size(); ++l) {
                CHECK(unrolled.layer(l).name == rolled.layer(l).name);
                CHECK(unrolled.layer(l).closed == rolled.layer(l).closed);
                const double n = static_cast<double>(rolled.layer(l).points.size());
                CHECK(std::abs(static_cast<double>(unrolled.layer(l).points.size()) - n) <=
                      0.02 * n + 1.0);
            }
            const CheckReport check = check_scene(unrolled);
            CHECK(check.crossing_count == 0);
            CHECK(check.total_self_crossings() == 0);
            CHECK(check.nesting_violation_count == 0);
            CHECK(check.min_separation_ratio >= 0.9);
            CHECK(record_input_sides(unrolled).rolled_count(unrolled, outside_sides(unrolled)) ==
                  0);
            // The rolled one does break the global order (else the pair compares nothing).
            CHECK(check_scene(rolled).nesting_violation_count > 0);
        }
    }
    CHECK(rolled_families == 4);
}

TEST_CASE("generated families scale and shift exactly", "[families]") {
    FamilyParams params;
    params.points = 60;
    const Scene unit = make_scene(SceneFamily::Loops, params);
    params.scale = 1e3;
    params.offset = Vec2(1e6, -2e6);
    const Scene big = make_scene(SceneFamily::Loops, params);
    REQUIRE(big.size() == unit.size());
    CHECK(big.layer(1).thickness == Approx(1e3 * unit.layer(1).thickness));
    CHECK(big.layer(2).points[7].x == Approx(1e3 * unit.layer(2).points[7].x + 1e6));
    CHECK(check_scene(big).is_collision_free());
}

TEST_CASE("naive decimation tangles the generated families", "[families]") {
    for (SceneFamily family : {SceneFamily::Stack, SceneFamily::Loops, SceneFamily::Folded}) {
        INFO(family_name(family));
        FamilyParams params;
        params.layers = 4;
        Scene scene = make_scene(family, params);
        SimplifyParams naive;
        naive.decimator = "random";
        naive.remove = 0.95;
        naive.untangle = false;
        simplify(scene, naive);
        CHECK(check_scene(scene).crossing_count > 0);
    }
}

TEST_CASE("bad family parameters are rejected by name", "[families]") {
    FamilyParams params;
    params.gap = 0.0;
    CHECK_THROWS_WITH(make_scene(SceneFamily::Stack, params), Catch::Contains("gap"));
    params = {};
    params.points = 2;
    CHECK_THROWS_WITH(make_scene(SceneFamily::Loops, params), Catch::Contains("points"));
    params = {};
    params.scale = -1.0;
    CHECK_THROWS_WITH(make_scene(SceneFamily::Legs, params), Catch::Contains("scale"));
}

TEST_CASE("small tangled instances of every family untangle clean", "[families][untangle]") {
    // Naive random decimation at 90%, then the global untangling with its defaults; clean as
    // strata_bench_untangle scores it: no crossing, nesting kept, gap >= 0.9 x min(1, the
    // input's ratio). The rolled families are left out: a roll breaks the global order, which
    // the untangling restores (it unrolls the roll), so the result cannot keep it.
    for (SceneFamily family : all_scene_families()) {
        if (is_rolled(family)) continue;
        for (double scale : {1e-3, 1.0, 1e3}) {
            INFO(family_name(family) << " x" << scale);
            FamilyParams params;
            params.layers = 4;
            params.points = 120;
            params.scale = scale;
            const Scene input = make_scene(family, params);
            Scene scene = input;
            SimplifyParams naive;
            naive.decimator = "random";
            naive.remove = 0.9;
            naive.untangle = false;
            simplify(scene, naive);
            const UntangleReport report = untangle(scene);
            CHECK(report.collision_free);
            const CheckReport after = check_scene(scene);
            CHECK(after.is_collision_free());
            CHECK(after.min_separation_ratio >=
                  0.9 * std::min(1.0, check_scene(input).min_separation_ratio));
        }
    }
}
