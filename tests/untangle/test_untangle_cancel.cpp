// A progress callback that returns false cancels: untangle(), untangle_inferring_sides(),
// untangle_local() and simplify() throw Cancelled and leave the scene as it was, whichever
// round or try the callback stops (include/strata/untangle/untangle.h, simplify.h).

#include "strata/core/error.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"
#include "support/require.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <string_view>

using namespace strata;

namespace {

using Run = std::function<void(Scene&, const ProgressFn&)>;

// Runs `run` once to count its progress calls, then again cancelling at call 1, 2, 4, 8, ...
// and at the last one: every cancelled run throws Cancelled and leaves the scene as it was.
// Returns the number of calls of the whole run.
std::size_t check_cancelled(const Scene& input, const Run& run) {
    std::size_t calls = 0;
    Scene whole = input;
    run(whole, [&](std::string_view, double) {
        ++calls;
        return true;
    });
    for (std::size_t stop = 1; stop <= calls;
         stop = stop == calls ? calls + 1 : std::min(2 * stop, calls)) {
        Scene scene = input;
        std::size_t k = 0;
        const ProgressFn cancel = [&](std::string_view, double) { return ++k < stop; };
        INFO("cancelled at call " << stop << " of " << calls);
        CHECK_THROWS_AS(run(scene, cancel), Cancelled);
        test::require_same_scene(scene, input, true);
    }
    return calls;
}

}  // namespace

TEST_CASE("a cancelled untangling leaves the scene as it was", "[untangle]") {
    // The folded stack at 95% (tests/data/SOURCES.md) with one pass a try: its tries fail one
    // after the other, and the callback stops each of them somewhere.
    const Scene input = read_scene(test::test_data("folded_stack_tangled_95.json"));
    UntangleParams params;
    params.give_up_when_stalled = true;
    params.max_passes = 1;
    SECTION("untangle") {
        const std::size_t calls =
            check_cancelled(input, [&](Scene& s, const ProgressFn& p) { untangle(s, params, p); });
        CHECK(calls >= 2);  // both tries
    }
    SECTION("untangle_inferring_sides") {
        const std::size_t calls = check_cancelled(
            input, [&](Scene& s, const ProgressFn& p) { untangle_inferring_sides(s, params, p); });
        CHECK(calls > 6);
    }
    SECTION("untangle_local") {
        const Box2 box = input.bounds();
        const Box2 half{box.min, {0.5 * (box.min.x + box.max.x), box.max.y}};
        const std::size_t calls = check_cancelled(
            input, [&](Scene& s, const ProgressFn& p) { untangle_local(s, half, 7, params, p); });
        CHECK(calls > 0);
    }
}

TEST_CASE("a cancelled simplification leaves the scene as it was", "[untangle]") {
    const Scene input = folded_stack(4, 200);
    SimplifyParams params;
    params.remove = 0.95;
    const std::size_t calls =
        check_cancelled(input, [&](Scene& s, const ProgressFn& p) { simplify(s, params, p); });
    CHECK(calls > 5);
}
