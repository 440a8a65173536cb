#pragma once
/// @file The last resort of simplify(): where the exact check of the whole result still finds
/// a crossing, a separation or a side the local checks could not see (a vertex that did not
/// move whose closest point on an open layer moved with that layer), the input comes back
/// around it: every input vertex within a radius of a violation is put back at its input
/// position, and the radius doubles until the result is clean. The whole input is the last
/// step, so a clean input always gives a clean result (simplify() keeps the result only when
/// it passes). Then the layers above their target lose vertices again where the exact check
/// still passes: first those the radius brought back, then the others, each cheapest first
/// (Visvalingam), a group at a time, the group halved where the check fails. Private to
/// src/simplify.

#include "simplify/detail/live_polylines.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <vector>

namespace strata::detail {

/// A result of restore_near_violations().
struct Restored {
    Scene scene;                                    ///< The result, vertices in input order.
    std::vector<std::vector<std::size_t>> origins;  ///< Per layer, the input id of each vertex.
    CheckReport check;                              ///< check_scene() of `scene`.
    /// Input vertices put back (and not taken out again), or moved back to their input place.
    std::size_t restored = 0;
    int steps = 0;             ///< Radii tried.
};

/// @brief Puts the input back around the violations of `check` (the report on `out`, the
/// scene of `live`) until the exact check passes. `params`: the check's parameters, whose
/// input_sides (if any) is replaced by `sides` renumbered to each candidate. The raised
/// separations of `input` carry over.
Restored restore_near_violations(const Scene& input, const LivePolylines& live, const Scene& out,
                                 const CheckReport& check, CheckParams params,
                                 const InputSides& sides);

/// @brief The layers of `result` (a scene that passes the exact check, with its origins and
/// check) above their target (`targets`) lose vertices while the exact check of the whole
/// scene still passes: inner vertices first, cheapest first (as after a restore); then, if
/// `trim_ends`, an open layer still above its target loses an end vertex, first the one whose
/// removal leaves the layer nearer its input layer (symmetric Hausdorff distance; its
/// neighbour becomes the end), and its inner vertices are tried again, until it is on its target or
/// neither end can go. A trimmed polyline is part of the one before, so it crosses nothing new and
/// keeps every gap: what the check can refuse is a side (a vertex of another layer whose closest
/// point was on the segment taken out). `params`: the check's parameters, whose input_sides is
/// replaced by `sides` renumbered to each candidate. Returns the end vertices taken out.
std::size_t meet_targets(const Scene& input, Restored& result,
                         const std::vector<std::size_t>& targets, CheckParams params,
                         const InputSides& sides, bool trim_ends);

/// Whether `report` passes: no crossing, nesting kept, separations within tolerance.
inline bool passes(const CheckReport& report) {
    return report.is_collision_free() && report.separations_hold();
}

}  // namespace strata::detail
