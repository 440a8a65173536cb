// UntangleParams::retry_ends_by_nearest: when every try of untangle_inferring_sides() fails,
// a last retry leaves an open layer out of the composition past one of its ends only where
// its nearest feature is that end (EngineSettings::ends_by_nearest).

#include "strata/geometry/checks.h"
#include "strata/untangle/untangle.h"

#include <catch2/catch.hpp>

#include <vector>

using namespace strata;

namespace {

// `n` + 1 points evenly spaced from (x0, y) to (x1, y), appended to `out`.
void sheet(std::vector<Vec2>& out, double y, double x0, double x1, int n) {
    for (int i = 0; i <= n; ++i) out.emplace_back(x0 + (x1 - x0) * i / n, y);
}

// Two layers folded over themselves as the out-of-sample folded stack (an S: the inner layer
// wraps the outer one at the right, the outer wraps the inner one at the left), both starting
// at x = 0 at the bottom. The decimation cut the outer layer's left fold to one chord at
// x ~ 0.1 and left one vertex of the inner layer's left fold at x = -0.5, 0.6 beyond the
// chord: past the line through the outer layer's start (x = 0), where the border field
// leaves the outer layer out, though its nearest feature there is the chord.
Scene cut_fold() {
    std::vector<Vec2> inner, outer;
    sheet(inner, 0.2, 0.0, 4.0, 12);
    inner.emplace_back(4.1, 0.35);
    sheet(inner, 0.49, 4.0, 0.0, 12);
    inner.emplace_back(-0.5, 1.17);
    inner.emplace_back(-0.26, 1.51);
    sheet(inner, 1.58, 0.1, 4.0, 12);
    sheet(outer, 0.3, 0.0, 4.0, 12);
    outer.emplace_back(4.05, 0.35);
    sheet(outer, 0.39, 4.0, 0.13, 12);
    sheet(outer, 1.68, 0.07, 4.0, 12);
    Layer a, b;
    a.name = "inner";
    a.points = inner;
    a.thickness = 0.049;
    b.name = "outer";
    b.points = outer;
    b.thickness = 0.049;
    return Scene({a, b});
}

}  // namespace

TEST_CASE("untangle_inferring_sides: a last retry with the ends read by the nearest feature",
          "[untangle]") {
    const Scene tangled = cut_fold();
    REQUIRE(check_scene(tangled).crossing_count == 2);
    UntangleParams params;
    params.max_passes = 8;
    params.long_rounds_factor = 1;  // the last retry alone
    params.retry_passes_factor = 1.0;
    params.more_passes_factor = 1;
    params.other_readings = 0;
    params.loop_readings = params.untwist = params.retract_ends = params.restart =
        false;                                                       // nor the last resorts
    params.retry_short_edge_fraction = 0.0;                          // nor the retry after them
    UntangleParams without = params;
    without.retry_ends_by_nearest = false;
    Scene failed = tangled;
    const UntangleReport before = untangle_inferring_sides(failed, without);
    CHECK_FALSE(before.collision_free);
    CHECK_FALSE(before.ends_by_nearest);
    CHECK(before.crossings_after > 0);

    Scene out = tangled;
    const UntangleReport report = untangle_inferring_sides(out, params);
    CHECK(report.collision_free);
    CHECK(report.ends_by_nearest);
    CHECK(report.tries > before.tries);  // the failed tries count too
    CheckParams judge;
    judge.separation_tolerance = params.separation_tolerance;
    const CheckReport c = check_scene(out, judge);
    CHECK(c.is_collision_free());
    CHECK(c.separations_hold());
    CHECK(c.total_self_crossings() == 0);

    // A scene that a try cleans never gets the retry: the outer layer's chord left of the
    // inner layer's tip (no crossing).
    Scene whole = tangled;
    std::vector<Vec2> outer = whole.layer(1).points;
    for (Vec2& p : outer)
        if (p.x < 0.2) p.x = -0.7;
    whole.set_points(1, outer);
    REQUIRE(check_scene(whole).crossing_count == 0);
    const UntangleReport clean = untangle_inferring_sides(whole, params);
    CHECK(clean.collision_free);
    CHECK_FALSE(clean.ends_by_nearest);
}
