#pragma once
/// @file Catch2 assertions on scenes shared by the tests of several modules (header only: it
/// expands CHECK/REQUIRE in the including test).

#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"

#include <catch2/catch.hpp>

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

}  // namespace strata::test
