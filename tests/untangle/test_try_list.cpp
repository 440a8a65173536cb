// The tries of a list run two at a time (src/untangle/detail/try_list.h): results taken in
// order up to the first clean one, the progress calls passed on from the calling thread in the
// order of the tries, cancel and exceptions; and untangle_inferring_sides() the same with one
// thread as with two.

#include "strata/core/error.h"
#include "strata/io/scene_io.h"
#include "strata/untangle/untangle.h"
#include "support/fixtures.h"
#include "support/require.h"
#include "untangle/detail/try_list.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

using namespace strata;

namespace {

using Calls = std::vector<std::pair<std::string, double>>;

// A list of `count` synthetic tries: try i makes `rounds` progress calls ("try i", round), each
// after `pause` (later tries pause less, so they tend to end first), and is clean where
// `clean(i)`; it throws std::runtime_error where `throws(i)`. It counts the tries running at
// once.
struct Synthetic {
    std::size_t count = 6;
    int rounds = 4;
    std::chrono::milliseconds pause{5};
    std::function<bool(std::size_t)> clean = [](std::size_t) { return false; };
    std::function<bool(std::size_t)> throws = [](std::size_t) { return false; };
    std::atomic<int> running{0}, most{0};
    std::atomic<bool> started_two_ahead{false};

    detail::TryResult run(std::size_t i, const ProgressFn& progress) {
        struct Count {
            std::atomic<int>& running;
            Count(std::atomic<int>& r, std::atomic<int>& peak) : running(r) {
                const int now = ++running;
                int seen = peak.load();
                while (now > seen && !peak.compare_exchange_weak(seen, now)) {
                }
            }
            ~Count() { --running; }
        } count_running(running, most);
        if (throws(i)) throw std::runtime_error("try " + std::to_string(i));
        for (int r = 0; r < rounds; ++r) {
            std::this_thread::sleep_for(pause * static_cast<int>(count - i));
            if (!progress("try " + std::to_string(i), r)) throw Cancelled();
        }
        detail::TryResult result{Scene{}, {}};
        result.report.collision_free = clean(i);
        result.report.tries = static_cast<int>(i);
        return result;
    }

    // Runs the list; `taken` receives the tries taken, `calls` the progress calls passed on.
    std::size_t list(
        bool until_clean, bool ahead, std::vector<std::size_t>& taken, Calls& calls,
        const std::function<bool()>& go_on = [] { return true; }) {
        const std::thread::id caller = std::this_thread::get_id();
        return detail::run_try_list(
            count, until_clean, ahead,
            [this](std::size_t i, const ProgressFn& p) { return run(i, p); },
            [&](std::size_t i, detail::TryResult&& r) {
                CHECK(std::this_thread::get_id() == caller);
                CHECK(r.report.tries == static_cast<int>(i));
                taken.push_back(i);
            },
            [&](std::string_view stage, double fraction) {
                CHECK(std::this_thread::get_id() == caller);
                calls.emplace_back(std::string(stage), fraction);
                return go_on();
            });
    }
};

// The progress calls of tries 0 to n - 1 run one at a time.
Calls calls_of(std::size_t n, int rounds) {
    Calls calls;
    for (std::size_t i = 0; i < n; ++i)
        for (int r = 0; r < rounds; ++r) calls.emplace_back("try " + std::to_string(i), r);
    return calls;
}

}  // namespace

TEST_CASE("run_try_list takes the tries in order up to the first clean one", "[untangle]") {
    for (const bool ahead : {false, true}) {
        Synthetic s;
        s.clean = [](std::size_t i) { return i == 3 || i == 5; };
        std::vector<std::size_t> taken;
        Calls calls;
        INFO("ahead " << ahead);
        CHECK(s.list(true, ahead, taken, calls) == 4);
        CHECK(taken == std::vector<std::size_t>{0, 1, 2, 3});
        CHECK(calls == calls_of(4, s.rounds));  // as one at a time: try 4 and 5 are not seen
        // Two at a time where the arena has a second thread (not for the first try).
        if (tbb::this_task_arena::max_concurrency() >= 2) CHECK(s.most == 2);
    }
}

TEST_CASE("run_try_list runs one try at a time with one thread", "[untangle]") {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    Synthetic s;
    s.clean = [](std::size_t i) { return i == 4; };
    std::vector<std::size_t> taken;
    Calls calls;
    CHECK(s.list(true, true, taken, calls) == 5);
    CHECK(s.most == 1);
    CHECK(calls == calls_of(5, s.rounds));
}

TEST_CASE("run_try_list without until_clean takes every try", "[untangle]") {
    Synthetic s;
    s.clean = [](std::size_t i) { return i % 2 == 1; };
    std::vector<std::size_t> taken;
    Calls calls;
    CHECK(s.list(false, true, taken, calls) == s.count);
    CHECK(taken == std::vector<std::size_t>{0, 1, 2, 3, 4, 5});
    CHECK(calls == calls_of(s.count, s.rounds));
}

TEST_CASE("run_try_list stops every try when the progress callback says so", "[untangle]") {
    for (const int stop_at : {1, 5, 9, 14}) {
        Synthetic s;
        std::vector<std::size_t> taken;
        Calls calls;
        int k = 0;
        INFO("stopped at call " << stop_at);
        CHECK_THROWS_AS(s.list(true, true, taken, calls, [&] { return ++k < stop_at; }), Cancelled);
        CHECK(s.running == 0);  // nothing runs once it has thrown
        const Calls all = calls_of(s.count, s.rounds);
        CHECK(calls == Calls(all.begin(), all.begin() + stop_at));  // none after the false
        CHECK(taken.size() <= static_cast<std::size_t>((stop_at - 1) / s.rounds));
    }
}

TEST_CASE("run_try_list rethrows the exception of a try it takes", "[untangle]") {
    Synthetic s;
    s.throws = [](std::size_t i) { return i == 2; };
    std::vector<std::size_t> taken;
    Calls calls;
    CHECK_THROWS_WITH(s.list(true, true, taken, calls), "try 2");
    CHECK(taken == std::vector<std::size_t>{0, 1});
    CHECK(s.running == 0);
    // A try after the first clean one is not taken, nor is what it throws.
    Synthetic after;
    after.clean = [](std::size_t i) { return i == 1; };
    after.throws = [](std::size_t i) { return i == 2; };
    taken.clear();
    calls.clear();
    CHECK(after.list(true, true, taken, calls) == 2);
    CHECK(taken == std::vector<std::size_t>{0, 1});
}

TEST_CASE("untangle_inferring_sides gives the same result with one thread and two", "[untangle]") {
    // The folded stack at 95% (tests/data/SOURCES.md) with one pass a try: its tries fail one
    // after the other, so that from the second on they run two at a time.
    const Scene input = read_scene(test::test_data("folded_stack_tangled_95.json"));
    UntangleParams params;
    params.give_up_when_stalled = true;
    params.max_passes = 1;
    auto run = [&](std::size_t threads, Scene& scene, Calls& calls) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        scene = input;
        return untangle_inferring_sides(scene, params, [&](std::string_view stage, double f) {
            calls.emplace_back(std::string(stage), f);
            return true;
        });
    };
    Scene one, two;
    Calls calls_one, calls_two;
    const UntangleReport a = run(1, one, calls_one);
    const UntangleReport b = run(2, two, calls_two);
    REQUIRE(a.tries > 6);
    test::require_same_scene(one, two, true);
    CHECK(calls_one == calls_two);  // the same calls, "try N" included, in the same order
    CHECK(a.tries == b.tries);
    CHECK(a.passes == b.passes);
    CHECK(a.finish_moves == b.finish_moves);
    CHECK(a.collision_free == b.collision_free);
    CHECK(a.crossings_after == b.crossings_after);
    CHECK(a.min_separation_ratio_after == b.min_separation_ratio_after);
    CHECK(a.max_displacement == b.max_displacement);
    CHECK(a.inferred_sides == b.inferred_sides);
    CHECK(a.sides_reading == b.sides_reading);
}
