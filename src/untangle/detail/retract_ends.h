#pragma once
/// @file Retracting ends: an open layer's end that pokes through another layer, or lies on its
/// wrong side, moved back along its own end segment. The last resorts' way
/// (UntangleParams::retract_ends) with what neither the projection nor the finishing stage
/// takes out at an end (e.g. a decimated end whose closest feature on the other layer is a
/// corner, judged there by the corner's side), before one more try from the retracted result.
/// Internal to the untangle module.

#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"

#include <cstddef>

namespace strata::detail {

/// Retracts ends of open layers of `scene` along their end segments where that makes it less
/// tangled as check_scene() with `judge` counts it: fewer crossings between layers, then fewer
/// self-crossings, then fewer nesting violations, then fewer separation violations (compared
/// in that order). An end is tried when its end segment meets another segment or the end
/// vertex is a nesting or separation violation. A crossed end segment is cut back to halfway
/// between its inner vertex and the crossing nearest that vertex, so that it meets nothing it
/// did not meet before; otherwise the end moves to 3/4, then 1/2, then 1/4 of the segment's
/// length from the inner vertex, the first of these that is less tangled kept. The new end
/// segment lies on the old one, so that no crossing is made and no gap shrinks below the
/// old segment's. One pass over the ends, in (layer, first then last end) order, each checked
/// after the retractions kept before it. Returns the number of ends retracted (`scene`
/// unchanged when 0).
std::size_t retract_ends(Scene& scene, const CheckParams& judge);

}  // namespace strata::detail
