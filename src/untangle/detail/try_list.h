#pragma once
/// @file A list of tries run two at a time. The tries of a whole-scene untangling
/// (untangle_tries.cpp) come in lists whose tries all start from the same input and do not
/// depend on one another: untangle()'s first and second tries, the inferred sides and the
/// global order, the other readings. Where a scene needs many of them, the projection of its
/// few free vertices keeps one core busy and leaves the other idle; run_try_list() runs the
/// next try of the list there. Each try is deterministic whatever the threads, so the results
/// taken, and the result kept, are those of the tries run one at a time.

#include "strata/core/progress.h"
#include "strata/geometry/scene.h"
#include "strata/untangle/untangle.h"

#include <cstddef>
#include <functional>

namespace strata::detail {

/// The result of one try: the scene it left and its report.
struct TryResult {
    Scene scene;
    UntangleReport report;
};

/// Try i of a list. `progress` queues the try's calls for the caller's progress and returns
/// false once the try is no longer wanted (or the caller cancelled). Must be safe to call
/// from two threads at once.
using RunTry = std::function<TryResult(std::size_t i, const ProgressFn& progress)>;

/// Receives the result of try i, on the calling thread, in the order of i. It must not change
/// what the tries read.
using TakeTry = std::function<void(std::size_t i, TryResult&& result)>;

/// Runs tries 0 to count - 1 and hands their results to `take` in order. With `until_clean`
/// the list ends at the first try whose report is collision-free (no later try is taken);
/// without, every try runs. Returns the number of tries taken.
///
/// With `ahead`, or once a try has been taken, the next try runs on an idle TBB worker while
/// the calling thread runs one: two at a time, none where the workers are busy or the
/// parallelism is limited to one thread. A try started ahead that the list no longer needs
/// (a clean one came before it) stops at its next progress call and is not taken.
/// `progress` is called from the calling thread only, with the calls of the tries taken in the
/// order of the tries (those of one try at a time, as when they run one at a time); when it
/// returns false, every try stops and Cancelled is thrown.
/// @throws Cancelled; what a taken try throws, once the other try has stopped.
std::size_t run_try_list(std::size_t count, bool until_clean, bool ahead, const RunTry& run,
                         const TakeTry& take, const ProgressFn& progress);

}  // namespace strata::detail
