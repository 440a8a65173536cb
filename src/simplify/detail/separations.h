#pragma once
/// @file The separations the simplification driver keeps between layers: the scene's required
/// separations with the check's tolerance applied, and the sizes derived from them. Private to
/// src/simplify.

#include "strata/geometry/scene.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace strata::detail {

struct Separations {
    /// need[a][b]: the distance layer a keeps from layer b, scene units (0 on the diagonal).
    std::vector<std::vector<double>> need;
    std::vector<double> reach;  ///< reach[a]: the largest need[a][b] over b.
    /// nest_thickness[a]: the thickness of a and of every layer nested with it (not side by
    /// side), which sizes the region of an untangling on a.
    std::vector<double> nest_thickness;
    double max_reach = 0.0;  ///< The largest reach: largest separation between two layers.
};

/// `tolerance`: UntangleParams::separation_tolerance (a gap passes at required x (1 - it)).
inline Separations separations_of(const Scene& scene, double tolerance) {
    const std::size_t n = scene.size();
    Separations s;
    s.need.assign(n, std::vector<double>(n, 0.0));
    s.reach.assign(n, 0.0);
    s.nest_thickness.assign(n, 0.0);
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b) {
            if (a == b) continue;
            s.need[a][b] = scene.required_separation(a, b) * (1.0 - tolerance);
            s.reach[a] = std::max(s.reach[a], s.need[a][b]);
            if (scene.relation(a, b) != Relation::SideBySide)
                s.nest_thickness[a] += scene.layer(b).thickness;
        }
    for (std::size_t a = 0; a < n; ++a) s.nest_thickness[a] += scene.layer(a).thickness;
    for (double r : s.reach) s.max_reach = std::max(s.max_reach, r);
    return s;
}

}  // namespace strata::detail
