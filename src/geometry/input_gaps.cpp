// The gap rule for layers without thickness (input_gaps.h).
#include "strata/geometry/input_gaps.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"

#include <algorithm>
#include <cmath>

namespace strata {

void validate(const InputGapParams& params) {
    if (!(params.fraction >= 0.0 && params.fraction <= 1.0))
        throw InvalidInput("keep_input_gaps: params.fraction must be in [0, 1] (got " +
                           format_number(params.fraction) + ")");
    if (!(std::isfinite(params.near_distance) && params.near_distance >= 0.0))
        throw InvalidInput("keep_input_gaps: params.near_distance must be finite and >= 0 (got " +
                           format_number(params.near_distance) + ")");
}

InputGapReport keep_input_gaps(Scene& scene, const InputGapParams& params) {
    validate(params);
    InputGapReport report;
    if (params.fraction == 0.0 || scene.size() < 2) return report;
    // Only pairs that require nothing are raised: without one, no check is needed.
    bool any_free_pair = false;
    for (std::size_t a = 0; a < scene.size() && !any_free_pair; ++a)
        for (std::size_t b = a + 1; b < scene.size() && !any_free_pair; ++b)
            any_free_pair = !(scene.required_separation(a, b) > 0.0);
    if (!any_free_pair) return report;
    CheckParams check_params;
    check_params.near_distance = params.near_distance;
    check_params.max_listed = 0;
    const CheckReport check = check_scene(scene, check_params);
    for (const PairSeparation& pair : check.pairs) {
        if (pair.required > 0.0 || !(pair.gap > 0.0)) continue;
        scene.raise_required_separation(pair.layer_a, pair.layer_b, params.fraction * pair.gap);
        ++report.raised;
        report.smallest_gap = std::min(report.smallest_gap, pair.gap);
    }
    return report;
}

}  // namespace strata
