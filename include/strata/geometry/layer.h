#pragma once
/// @file One layer of a multi-layered shape: a polyline, open or closed, with its parameters.

#include "strata/core/types.h"

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace strata {

/// A layer: a planar polyline (open, or closed with an implicit closing segment) and the
/// physical parameters the untangling uses. Lengths are in scene units.
struct Layer {
    std::string name;             ///< Unique within a scene, non-empty.
    std::vector<Vec2> points;     ///< Vertices in order; >= 2 (open) or >= 3 (closed).
    bool closed = false;          ///< True: a segment joins the last point to the first.
    double thickness = 0.0;       ///< Cloth thickness, scene units, >= 0.
    double weight = 1.0;          ///< > 0; a larger weight is stiffer and moves less.
    std::optional<double> alpha;  ///< Shape-matching stiffness in [0, 1]; unset: the default.
    std::optional<double> beta;   ///< Shape-matching quadratic share in [0, 1]; unset: the default.
    /// Names of the layers directly outside this one. Unset (as opposed to empty) in every
    /// layer of a scene means the file order is one stack, innermost first.
    std::optional<std::vector<std::string>> outer;
    /// Keys of the input file that strata does not know, as JSON text, written back unchanged.
    std::map<std::string, std::string> extra;

    /// Number of segments: n - 1 when open, n when closed.
    std::size_t segment_count() const;
    /// First and second end of segment `i` (the closing segment of a closed layer ends at 0).
    Vec2 segment_start(std::size_t i) const { return points[i]; }
    Vec2 segment_end(std::size_t i) const { return points[(i + 1) % points.size()]; }
    /// Total length of the segments, scene units.
    double length() const;
    /// Bounding box of the points.
    Box2 bounds() const;
};

}  // namespace strata
