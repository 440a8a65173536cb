#pragma once
// One untangling of a set of pieces, the core of untangle(), untangle_inferring_sides() and
// untangle_local(). Internal to the untangle module.

#include "strata/core/progress.h"
#include "strata/geometry/checks.h"
#include "strata/untangle/localize.h"
#include "strata/untangle/untangle.h"

#include <vector>

namespace strata::detail {

// `region`: the vertices that may move (the free vertices of `pieces`) stay in this box, with
// their neighbours, or the check is of the whole scene; the checks then look only near it
// (RegionCheck), with the same verdicts as whole ones. nullptr: whole checks.
// `keep_simple`: EngineSettings::keep_simple (no vertex move that makes a self-crossing).
// `ends_by_nearest`: EngineSettings::ends_by_nearest (an open layer left out past its ends
// only where its nearest feature is the end).
UntangleReport run_untangling(Scene& scene, const std::vector<Piece>& pieces,
                              const UntangleParams& params, const ProgressFn& progress,
                              bool keep_simple = false, const Box2* region = nullptr,
                              bool ends_by_nearest = false);

// The check that judges run_untangling()'s results with `params`: the outside sides
// `outside_signs` (EngineSettings::outside_signs of the scene untangled), params' separation
// tolerance and input sides, if any.
CheckParams judge_params(const UntangleParams& params, const std::vector<int>& outside_signs);

// report.max_displacement and moved_vertices of `result` against `from` (the same layers and
// vertex counts): the largest vertex move, and the vertices moved by more than 1e-12 x the
// diagonal of `from`'s bounds.
void measure_displacement(const Scene& result, const Scene& from, UntangleReport& report);

}  // namespace strata::detail
