#pragma once
/// @file Untwisting: the self-crossings of a scene taken out one vertex move at a time. The
/// projection and the finishing stage do not aim at self-crossings (docs/untangle.md, "A second
/// try"); this is the last resorts' way (UntangleParams::untwist), before one more try from the
/// untwisted result. Internal to the untangle module.

#include "strata/geometry/scene.h"

namespace strata::detail {

/// Takes the self-crossings out of `scene` one vertex move at a time: for each self-crossing
/// of segments s and t of a layer, each end vertex of either may move straight across the
/// other's line to its far side, the layer's thickness beyond it (at least 1e-9 of the scene's
/// diagonal), or, on that line (a touch), off it to either side by as much; of the moves that
/// leave the vertex's two segments meeting fewer segments of their layer and no more of other
/// layers (exact), the shortest is made, until none is left or 4 moves per self-crossing of the
/// input, plus 4, are made. True when none is left; false otherwise (no such move left, or the
/// moves ran out), `scene` then holding the moves made.
bool untwist(Scene& scene);

}  // namespace strata::detail
