#pragma once
/// @file The outside sides of the open layers of a scene to untangle: which side of each open
/// layer is "over", read from a scene that may be tangled.

#include "strata/geometry/scene.h"

#include <vector>

namespace strata {

/// @brief The outside sides untangle() and untangle_inferring_sides() take when
/// params.outside_sides is empty (`strata untangle` judges its result by them too):
/// outside_side() of every layer, made consistent where a tangle split the votes. An open
/// layer directly over a closed one whose centroid (of its polygon's area, not of its vertices,
/// which a decimation can leave on one side) lies inside it, and that runs around
/// that centroid (the mean over its segments, weighted by length, of the sine between the
/// segment and the direction from the centroid beyond 0.8 either way), faces away from it (+1
/// counter-clockwise), whatever its vote (a tangled body's vertices can outvote it). One that
/// runs back in part (a fold at its end: the mean sine fails) faces away from the largest such
/// closed layer under it, directly or with layers between (bounding-box diagonal), when it sweeps
/// around its centroid by at least 120 degrees (the signed angles its segments subtend from there).
/// Two directly related open layers that run along each other (the mean cosine of their tangents at
/// 64 evenly spaced fractions of their lengths beyond 0.8 either way) must have the same outside
/// side when they travel the same way and opposite ones otherwise. Where the votes of a chain
/// of such layers disagree (in a scene tangled by decimation, a layer's vote counts the
/// neighbours' vertices scattered on both sides of it), every layer of the chain takes the sign
/// of all those neighbours' votes counted together (each vertex of a layer directly under or
/// over one of the chain's layers, by its recorded side, times the layer's parity in the chain;
/// a tie: the majority of the layers' votes, then its lowest-index layer's). Where they agree (an
/// untangled scene), they are returned as they are. Layers with a rolled part run along each
/// other less (0.38-0.65 on strata_bench_untangle's rolled families) and are left to their
/// own votes. First of all, an open layer with neighbours both under and over it whose
/// neighbours' recorded sides (record_input_sides()) under it and over it say opposite outsides
/// takes the sign of both counts together (a decimation that scatters one side's vertices
/// leaves the other's count standing). docs/untangle.md, "Outside sides of a tangled scene".
std::vector<int> untangling_outside_sides(const Scene& scene);

}  // namespace strata
