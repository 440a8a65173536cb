#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_gaps.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace strata;

namespace {

Layer line(const char* name, double y, double thickness = 0.0, double x0 = 0.0) {
    Layer l;
    l.name = name;
    l.points = {{x0, y}, {x0 + 1.0, y}, {x0 + 2.0, y}};
    l.thickness = thickness;
    return l;
}

}  // namespace

TEST_CASE("raise_required_separation raises one pair, both orders, and is remembered",
          "[input_gaps]") {
    Scene s({line("a", 0.0), line("b", 0.1), line("c", 0.2)});
    CHECK(s.required_separation(0, 1) == 0.0);
    s.raise_required_separation(1, 0, 0.05);
    CHECK(s.required_separation(0, 1) == 0.05);
    CHECK(s.required_separation(1, 0) == 0.05);
    CHECK(s.required_separation(0, 2) == 0.0);
    s.raise_required_separation(0, 1, 0.01);  // lower: no change, not recorded
    CHECK(s.required_separation(0, 1) == 0.05);
    REQUIRE(s.raised_separations().size() == 1);
    CHECK(s.raised_separations()[0].a == 0);
    CHECK(s.raised_separations()[0].b == 1);
    CHECK(s.raised_separations()[0].value == 0.05);
    const Scene copy = s;
    CHECK(copy.required_separation(0, 1) == 0.05);
    CHECK_THROWS_AS(s.raise_required_separation(1, 1, 0.1), InvalidInput);
    CHECK_THROWS_AS(s.raise_required_separation(0, 3, 0.1), InvalidInput);
    CHECK_THROWS_AS(s.raise_required_separation(0, 1, -1.0), InvalidInput);
    CHECK_THROWS_AS(s.raise_required_separation(0, 1, std::nan("")), InvalidInput);
}

TEST_CASE("keep_input_gaps: pairs without thickness require a share of their gap", "[input_gaps]") {
    // One stack a < b < c: a, b 0.1 apart without thickness; c with thickness, so b-c and a-c
    // already require 0.02 (half-thickness sums along the chain).
    Scene s({line("a", 0.0), line("b", 0.1), line("c", 0.2, 0.04)});
    CHECK(s.required_separation(1, 2) == Approx(0.02));
    const InputGapReport r = keep_input_gaps(s);
    CHECK(s.required_separation(0, 1) == Approx(0.09));  // 0.9 x 0.1
    CHECK(s.required_separation(1, 2) == Approx(0.02));  // thickness asks: left alone
    CHECK(s.required_separation(0, 2) == Approx(0.02));
    CHECK(r.raised == 1);
    CHECK(s.raised_separations().size() == 1);
    CHECK(r.smallest_gap == Approx(0.1));
    // The input keeps its own rule, and the check sees the raised value.
    const CheckReport c = check_scene(s);
    CHECK(c.separations_hold());
    CHECK(c.min_separation_ratio == Approx(1.0 / 0.9));

    // A layer touching another (its end on it), and one far away: left alone.
    Layer d;
    d.name = "d";
    d.points = {{2.0, 0.0}, {2.5, 0.5}};
    Scene touching({line("a", 0.0), d});
    CHECK(keep_input_gaps(touching).raised == 0);
    CHECK(touching.required_separation(0, 1) == 0.0);
    Scene far({line("a", 0.0), line("e", 0.0, 0.0, 40.0)});
    CHECK(keep_input_gaps(far).raised == 0);
    CHECK(far.required_separation(0, 1) == 0.0);
    InputGapParams wide;
    wide.near_distance = 50.0;  // within reach now: 38 apart
    CHECK(keep_input_gaps(far, wide).raised == 1);
    CHECK(far.required_separation(0, 1) == Approx(0.9 * 38.0));

    Scene off({line("a", 0.0), line("b", 0.1)});
    InputGapParams none;
    none.fraction = 0.0;
    CHECK(keep_input_gaps(off, none).raised == 0);
    CHECK(off.required_separation(0, 1) == 0.0);
    InputGapParams bad;
    bad.fraction = 1.5;
    CHECK_THROWS_AS(keep_input_gaps(off, bad), InvalidInput);
    bad = InputGapParams{};
    bad.near_distance = -1.0;
    CHECK_THROWS_AS(validate(bad), InvalidInput);
}
