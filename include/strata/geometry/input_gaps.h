#pragma once
/// @file The gap rule for layers without thickness: a pair of layers whose thicknesses ask
/// for no separation is required to keep a share of the gap it has in the input, so that a
/// simplification does not bring a suit 3 mm off the body down to touching it.

#include "strata/geometry/scene.h"

#include <cstddef>
#include <limits>

namespace strata {

/// Parameters of keep_input_gaps(). Lengths are in scene units.
struct InputGapParams {
    /// Share of a near pair's smallest input gap that becomes its required separation, for
    /// pairs whose thicknesses require nothing (Scene::required_separation() == 0). [0, 1];
    /// 0 = the rule is off.
    double fraction = 0.9;
    /// Pairs farther apart than this keep requiring nothing (CheckParams::near_distance of
    /// the check that measures the gaps). 0 = automatic: 5% of the scene's bounding-box
    /// diagonal. >= 0.
    double near_distance = 0.0;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const InputGapParams& params);

/// What keep_input_gaps() did.
struct InputGapReport {
    std::size_t raised = 0;  ///< Pairs whose required separation was raised.
    /// Smallest gap among the raised pairs (scene units); +inf when none was.
    double smallest_gap = std::numeric_limits<double>::infinity();
};

/// @brief Measures the smallest gap of every near pair of layers of `scene` (check_scene()),
/// and raises the required separation of each pair that requires nothing and does not touch to
/// params.fraction x that gap (Scene::raise_required_separation()). Pairs that meet or cross in
/// the input (gap 0) are left alone.
/// @throws InvalidInput bad params.
InputGapReport keep_input_gaps(Scene& scene, const InputGapParams& params = {});

}  // namespace strata
