#pragma once
/// @file Catch2 assertions on scenes shared by the tests of several modules (header only: it
/// expands CHECK/REQUIRE in the including test).

#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"

#include <catch2/catch.hpp>

#include <vector>

namespace strata::test {

/// Exact equality of two scenes: names, flags, parameters, nesting and bit-exact points; with
/// `with_unknown_keys`, also the kept unknown keys (formats that carry them, like JSON).
inline void require_same_scene(const Scene& a, const Scene& b, bool with_unknown_keys) {
    REQUIRE(a.size() == b.size());
    CHECK(a.units() == b.units());
    CHECK(a.is_implicit_stack() == b.is_implicit_stack());
    if (with_unknown_keys) CHECK(a.metadata == b.metadata);
    for (std::size_t i = 0; i < a.size(); ++i) {
        const Layer& la = a.layer(i);
        const Layer& lb = b.layer(i);
        CHECK(la.name == lb.name);
        CHECK(la.closed == lb.closed);
        CHECK(la.thickness == lb.thickness);
        CHECK(la.weight == lb.weight);
        CHECK(la.alpha == lb.alpha);
        CHECK(la.beta == lb.beta);
        CHECK(la.outer == lb.outer);
        CHECK(a.outer_of(i) == b.outer_of(i));
        if (with_unknown_keys) CHECK(la.extra == lb.extra);
        CHECK(la.points == lb.points);  // bit-exact
    }
}

/// check_scene() finds no crossing, self-crossing, nesting violation or separation shortfall
/// beyond the relative tolerance `tol`.
inline void require_collision_free(const Scene& scene, double tol) {
    CheckParams params;
    params.separation_tolerance = tol;
    const CheckReport check = check_scene(scene, params);
    CHECK(check.crossing_count == 0);
    CHECK(check.total_self_crossings() == 0);
    CHECK(check.nesting_violation_count == 0);
    CHECK(check.separation_violation_count == 0);
}

/// check_scene() of `scene` as simplify() and untangle() judge their results: the open layers'
/// outside sides `outside` (outside_sides() of the scene it comes from), the sides `sides`
/// recorded there and carried onto `scene`'s vertices (nullptr: the global order), the
/// separation tolerance `tol`.
inline CheckReport check_with_sides(const Scene& scene, const std::vector<int>& outside, double tol,
                                    const InputSides* sides) {
    CheckParams params;
    params.outside_sides = outside;
    params.separation_tolerance = tol;
    params.input_sides = sides;
    return check_scene(scene, params);
}

/// `check` finds no crossing, self-crossing or nesting violation, and every gap is at least
/// `min_ratio` x required.
inline void require_sides_kept(const CheckReport& check, double min_ratio) {
    CHECK(check.crossing_count == 0);
    CHECK(check.total_self_crossings() == 0);
    CHECK(check.nesting_violation_count == 0);
    CHECK(check.min_separation_ratio >= min_ratio);
}

}  // namespace strata::test
