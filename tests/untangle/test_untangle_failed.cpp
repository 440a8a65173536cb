// When every try of untangle() or untangle_inferring_sides() fails, the result kept is the
// least tangled of the tries' results and the input (docs/untangle.md, "When every try fails").

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/scene_io.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"
#include "untangle/detail/run.h"

#include <catch2/catch.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cstddef>
#include <tuple>

using namespace strata;

namespace {

// How tangled a scene is, as untangle() orders its failed results (smaller is less tangled):
// crossings between layers plus self-crossings, nesting violations, the larger min separation
// ratio, the smaller max displacement from `input`.
using Tangle = std::tuple<std::size_t, std::size_t, double, double>;

double max_displacement(const Scene& scene, const Scene& input) {
    double d = 0.0;
    for (std::size_t l = 0; l < scene.size(); ++l)
        for (std::size_t v = 0; v < scene.layer(l).points.size(); ++v)
            d = std::max(d, glm::distance(scene.layer(l).points[v], input.layer(l).points[v]));
    return d;
}

Tangle tangle_of(const Scene& scene, const Scene& input, const CheckReport& c) {
    return {c.crossing_count + c.total_self_crossings(), c.nesting_violation_count,
            -c.min_separation_ratio, max_displacement(scene, input)};
}

// check_scene() as the untangling judges: by the input's outside sides and `sides`, if any.
CheckReport judged(const Scene& scene, const Scene& input, const InputSides* sides = nullptr) {
    CheckParams params;
    params.outside_sides = untangling_outside_sides(input);
    params.input_sides = sides;
    return check_scene(scene, params);
}

// The report's counts are those of the scene kept.
void check_report(const UntangleReport& r, const Scene& out, const Scene& input,
                  const CheckReport& c) {
    CHECK(r.crossings_after == c.crossing_count);
    CHECK(r.self_crossings_after == c.total_self_crossings());
    CHECK(r.nesting_violations_after == c.nesting_violation_count);
    CHECK(r.min_separation_ratio_after == c.min_separation_ratio);
    CHECK(r.max_displacement == max_displacement(out, input));
    CHECK(r.input_kept == (r.moved_vertices == 0));
}

// The global order's first try alone (what untangle_inferring_sides() kept before).
Scene global_first_try(const Scene& input, const UntangleParams& params) {
    Scene s = input;
    UntangleParams p = params;
    p.outside_sides = untangling_outside_sides(input);
    const UntangleReport r = detail::run_untangling(s, whole_scene_pieces(s), p, {});
    REQUIRE_FALSE(r.collision_free);
    return s;
}

}  // namespace

TEST_CASE(
    "untangle_inferring_sides and untangle keep the least tangled result when every try fails",
    "[untangle]") {
    // The folded stack at 95% that no try cleans (tests/data/SOURCES.md); the tries give up
    // early (3 s instead of 25).
    const Scene input = read_scene(test::test_data("folded_stack_tangled_95.json"));
    UntangleParams params;
    params.give_up_when_stalled = true;
    const Tangle of_input = tangle_of(input, input, judged(input, input));
    const Scene first = global_first_try(input, params);
    const Tangle of_first = tangle_of(first, input, judged(first, input));
    SECTION("untangle_inferring_sides") {
        Scene out = input;
        InputSides kept;
        const UntangleReport r = untangle_inferring_sides(out, params, {}, &kept);
        REQUIRE_FALSE(r.collision_free);
        CHECK(r.tries > 2);
        const CheckReport c = judged(out, input, r.inferred_sides ? &kept : nullptr);
        const Tangle of_out = tangle_of(out, input, c);
        CHECK(of_out <= of_input);
        CHECK(of_out <= of_first);
        // The old result, the global order's first try: 16 crossings + self-crossings, more
        // than the input's 12.
        CHECK(std::get<0>(of_out) < std::get<0>(of_first));
        check_report(r, out, input, c);
    }
    SECTION("untangle") {
        Scene out = input;
        const UntangleReport r = untangle(out, params);
        REQUIRE_FALSE(r.collision_free);
        CHECK(r.tries == 2);
        const CheckReport c = judged(out, input);
        const Tangle of_out = tangle_of(out, input, c);
        CHECK(of_out <= of_input);
        CHECK(of_out <= of_first);
        check_report(r, out, input, c);
    }
}

TEST_CASE("untangle: the input is kept when no try is less tangled", "[untangle]") {
    // Two crossing layers, and tries that can barely move a vertex: each ends with the input's
    // crossings, moved a little, so the input (displacement 0) is less tangled.
    const Scene input = read_scene(test::test_data("crossing_pair.json"));
    UntangleParams params;
    params.step = 1e-9;
    params.max_passes = 1;
    params.finish_separations = false;
    Scene out = input;
    const UntangleReport r = untangle(out, params);
    REQUIRE_FALSE(r.collision_free);
    CHECK(r.input_kept);
    CHECK(r.tries == 2);
    CHECK(r.moved_vertices == 0);
    CHECK(r.crossings_after == r.crossings_before);
    CHECK(r.crossings_after > 0);
    for (std::size_t l = 0; l < input.size(); ++l)
        CHECK(out.layer(l).points == input.layer(l).points);
    check_report(r, out, input, judged(out, input));
}

TEST_CASE("untangle: a pass does not repeat a finishing run that moved nothing", "[untangle]") {
    // One try on the folded stack at 95% (one round a pass, no pass clean). The finishing stage
    // runs before the first check, at the end of every round and at the end of every pass; the
    // pass's run is left out where the round's run just before it moved nothing (it undid its
    // moves on that tangle), since it would start from the same scene and end the same.
    const Scene input = read_scene(test::test_data("folded_stack_tangled_95.json"));
    UntangleParams params;
    params.outside_sides = untangling_outside_sides(input);
    REQUIRE(params.max_rounds == 1);
    Scene s = input;
    const UntangleReport r = detail::run_untangling(s, whole_scene_pieces(s), params, {});
    REQUIRE_FALSE(r.collision_free);
    REQUIRE(r.rounds == r.passes);
    CHECK(r.finishes < 1 + 2 * r.passes);
    CHECK(r.finishes > r.passes);
}
