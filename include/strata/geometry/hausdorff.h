#pragma once
/// @file The Hausdorff distance between two polylines (the shape error strata reports).

#include "strata/geometry/layer.h"

namespace strata {

/// One-sided and symmetric Hausdorff distances between two polylines, scene units.
struct HausdorffDistance {
    double a_to_b = 0.0;  ///< max over points of a of the distance to b.
    double b_to_a = 0.0;  ///< max over points of b of the distance to a.
    double symmetric() const { return a_to_b > b_to_a ? a_to_b : b_to_a; }
};

/// Hausdorff distances over the whole polylines (not only vertices), computed by branch and
/// bound on segments with the 1-Lipschitz bound, to within `tolerance` scene units (> 0).
/// An interval [p0, p1] of a segment is bounded by (d0 + d1 + |p1 - p0|) / 2 and by
/// max(d(p0, s), d(p1, s)) for the segments s of the other polyline nearest to p0 and p1
/// (the distance to one segment is convex along a line), and split until within tolerance.
/// Nearest queries use a uniform grid of the other polyline's segments.
///
/// Each returned value is a lower bound that is achieved (the distance of an evaluated point
/// of one polyline to the other); the true value is at most that plus `tolerance`. Vertices
/// are always evaluated, so polylines whose farthest points are vertices come out exact.
/// `a` and `b` need not belong to a scene; a single point is allowed.
/// @throws InvalidInput tolerance not finite or <= 0, a layer without points, non-finite points.
HausdorffDistance hausdorff(const Layer& a, const Layer& b, double tolerance);

}  // namespace strata
