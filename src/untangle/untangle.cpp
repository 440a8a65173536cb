#include "strata/untangle/untangle.h"

#include "geometry/detail/region_check.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "untangle/detail/engine.h"
#include "untangle/detail/run.h"

#include <tbb/task_group.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace strata {

namespace {

// Throws InvalidInput when params.outside_sides or params.input_sides do not fit `scene`.
void validate_sides(const Scene& scene, const UntangleParams& params) {
    const std::vector<int>& outside = params.outside_sides;
    if (!outside.empty() && outside.size() != scene.size())
        throw InvalidInput("untangle: params.outside_sides has " + std::to_string(outside.size()) +
                           " entries for " + std::to_string(scene.size()) + " layers");
    for (std::size_t i = 0; i < outside.size(); ++i)
        if (!scene.layer(i).closed && outside[i] != 1 && outside[i] != -1)
            throw InvalidInput("untangle: params.outside_sides[" + std::to_string(i) +
                               "] (layer '" + shown_text(scene.layer(i).name) +
                               "') must be +1 or -1 (got " + std::to_string(outside[i]) + ")");
    const InputSides* sides = params.input_sides;
    if (sides && !sides->empty() && sides->size() != scene.size())
        throw InvalidInput("untangle: params.input_sides has " + std::to_string(sides->size()) +
                           " layers for " + std::to_string(scene.size()));
}

// The rolled vertices of `sides` (as InputSides::rolled_count() counts them) that are not
// listed among the nesting violations of `check`.
std::size_t rolled_kept(const Scene& scene, const InputSides& sides,
                        const std::vector<int>& outside_signs, std::size_t rolled,
                        const CheckReport& check) {
    std::size_t lost = 0;
    for (const NestingViolation& v : check.nesting_violations) {
        const int side = sides.side(v.layer, v.vertex, v.other);
        const int wanted = global_side(scene.relation(v.layer, v.other), outside_signs[v.other]);
        if (side != 0 && wanted != 0 && side != wanted) ++lost;
    }
    return rolled - std::min(rolled, lost);
}

}  // namespace

namespace detail {

void measure_displacement(const Scene& result, const Scene& from, UntangleReport& report) {
    const Vec2 size = from.bounds().size();
    const double diagonal =
        std::max(std::hypot(size.x, size.y), std::numeric_limits<double>::min());
    report.max_displacement = 0.0;
    report.moved_vertices = 0;
    for (std::size_t l = 0; l < result.size(); ++l)
        for (std::size_t v = 0; v < result.layer(l).points.size(); ++v) {
            const double d = glm::distance(result.layer(l).points[v], from.layer(l).points[v]);
            report.max_displacement = std::max(report.max_displacement, d);
            if (d > 1e-12 * diagonal) ++report.moved_vertices;
        }
}

CheckParams judge_params(const UntangleParams& params, const std::vector<int>& outside_signs) {
    CheckParams check;
    check.separation_tolerance = params.separation_tolerance;
    check.outside_sides = outside_signs;
    const bool has_sides = params.input_sides && !params.input_sides->empty();
    check.input_sides = has_sides ? params.input_sides : nullptr;
    return check;
}

UntangleReport run_untangling(Scene& scene, const std::vector<Piece>& pieces,
                              const UntangleParams& params, const ProgressFn& progress,
                              bool keep_simple, const Box2* region, bool ends_by_nearest) {
    validate(params);
    validate_sides(scene, params);
    UntangleReport report;
    report.tries = 1;
    const Scene original = scene;
    try {
        for (const Piece& piece : pieces)
            report.free_vertices +=
                static_cast<std::size_t>(std::count(piece.is_free.begin(), piece.is_free.end(), 1));
        // Orientation of open layers from the input, where the nesting is the intended one (or
        // from params.outside_sides): what the untangling pushes toward, and what its checks
        // judge by, with the sides given if any (a fresh vote on the result could flip a short
        // layer's outside and call a swapped order clean).
        detail::EngineSettings settings = detail::resolve_settings(scene, params);
        CheckParams check_params = judge_params(params, settings.outside_signs);
        // Short passes (UntangleParams' defaults): shape matching pulls toward the input.
        settings.rest_at_start = true;
        settings.keep_simple = keep_simple;
        settings.ends_by_nearest = ends_by_nearest;
        const bool has_sides = check_params.input_sides != nullptr;
        settings.open_cut_bends = has_sides && params.open_cut_bends;
        // `check`: the last whole check, if any; `counts`: the last check's counts. The check
        // of the input (the reference of the region checks) runs beside the engine's first
        // steps (the fields, the finishing stage, which do not use it); the first verdict
        // waits for it.
        std::optional<RegionCheck> region_check;
        CheckReport check;
        CheckCounts counts;
        tbb::task_group checking;
        bool is_checking = true;
        // With sides to keep, the input's nesting violations are all listed (rolled_kept_before).
        CheckParams input_check_params = check_params;
        if (has_sides) input_check_params.max_listed = std::numeric_limits<std::size_t>::max();
        checking.run([&] {
            if (region)
                check = region_check.emplace(original, check_params, *region).reference_report();
            else
                check = check_scene(original, input_check_params);
        });
        auto checked = [&] {
            if (!is_checking) return;
            is_checking = false;
            checking.wait();
            counts = counts_of(check);
            report.crossings_before = counts.crossing_count;
            report.self_crossings_before = counts.self_crossing_count;
            report.nesting_violations_before = counts.nesting_violation_count;
            report.min_separation_ratio_before = counts.min_separation_ratio;
            if (report.rolled_vertices > 0 && !region_check)
                report.rolled_kept_before =
                    rolled_kept(original, *params.input_sides, settings.outside_signs,
                                report.rolled_vertices, check);
        };
        // Waits for the check of the input before leaving (it reads `original`).
        struct Waiter {
            tbb::task_group& group;
            bool& is_running;
            ~Waiter() {
                if (!is_running) return;
                try {
                    group.wait();
                } catch (...) {  // leaving on another exception already
                }
            }
        } waiter{checking, is_checking};
        auto is_ok = [&](const Scene& s) {
            checked();
            if (region_check) {
                counts = region_check->check(s);
            } else {
                check = check_scene(s, check_params);
                counts = counts_of(check);
            }
            return counts.is_collision_free() && counts.separations_hold();
        };
        detail::RelationSource relations;
        relations.scene = &original;
        if (has_sides) {
            detail::take_input_sides(relations, original, *params.input_sides,
                                     settings.outside_signs);
            report.rolled_vertices =
                params.input_sides->rolled_count(original, settings.outside_signs);
        }
        const detail::EngineResult r =
            detail::run_engine(scene, pieces, params, relations, settings, is_ok, progress);
        checked();
        report.passes = r.passes;
        report.rounds = r.rounds;
        report.converged = r.converged;
        report.collision_free = r.ok;
        report.mean_speed = r.mean_speed;
        report.gave_up = r.gave_up;
        report.seconds_fields = r.seconds_fields;
        report.seconds_untangle = r.seconds_untangle;
        report.seconds_check = r.seconds_check;
        report.seconds_finish = r.seconds_finish;
        report.finishes = r.finishes;
        report.finish_moves = r.finish_moves;
        report.crossings_after = counts.crossing_count;
        report.self_crossings_after = counts.self_crossing_count;
        report.nesting_violations_after = counts.nesting_violation_count;
        report.min_separation_ratio_after = counts.min_separation_ratio;
        if (report.rolled_vertices > 0) {
            // The last check judged the final scene; list every violation if it did not (a
            // region check lists none).
            if (region_check || check.nesting_violations.size() < check.nesting_violation_count) {
                check_params.max_listed =
                    std::max(check_params.max_listed, counts.nesting_violation_count);
                check = check_scene(scene, check_params);
            }
            report.rolled_kept = rolled_kept(original, *params.input_sides, settings.outside_signs,
                                             report.rolled_vertices, check);
        }
        measure_displacement(scene, original, report);
    } catch (...) {
        scene = original;
        throw;
    }
    return report;
}

}  // namespace detail

void validate(const UntangleParams& params) {
    auto fail = [](const char* field, double value, const char* range) {
        throw InvalidInput(std::string("untangle: params.") + field + " must be " + range +
                           " (got " + format_number(value) + ")");
    };
    if (params.gradient_steps < 1) fail("gradient_steps", params.gradient_steps, ">= 1");
    if (!(params.step > 0.0 && params.step <= 1.0)) fail("step", params.step, "in (0, 1]");
    if (!(params.max_step_fraction > 0.0 && params.max_step_fraction <= 1.0))
        fail("max_step_fraction", params.max_step_fraction, "in (0, 1]");
    if (!(params.short_edge_fraction >= 0.0) || !std::isfinite(params.short_edge_fraction))
        fail("short_edge_fraction", params.short_edge_fraction, ">= 0 and finite");
    if (!(params.retry_short_edge_fraction >= 0.0) ||
        !std::isfinite(params.retry_short_edge_fraction))
        fail("retry_short_edge_fraction", params.retry_short_edge_fraction, ">= 0 and finite");
    if (params.edge_samples < 0) fail("edge_samples", params.edge_samples, ">= 0");
    if (!(params.sample_spacing >= 0.0) || !std::isfinite(params.sample_spacing))
        fail("sample_spacing", params.sample_spacing, ">= 0 and finite");
    if (!(params.alpha >= 0.0 && params.alpha <= 1.0)) fail("alpha", params.alpha, "in [0, 1]");
    if (!(params.beta >= 0.0 && params.beta <= 1.0)) fail("beta", params.beta, "in [0, 1]");
    if (!(params.tolerance > 0.0) || !std::isfinite(params.tolerance))
        fail("tolerance", params.tolerance, "> 0");
    if (params.max_rounds < 1) fail("max_rounds", params.max_rounds, ">= 1");
    if (params.max_passes < 1) fail("max_passes", params.max_passes, ">= 1");
    if (!std::isfinite(params.retry_passes_factor))
        fail("retry_passes_factor", params.retry_passes_factor, "finite");
    if (!std::isfinite(params.stiffer_closed))
        fail("stiffer_closed", params.stiffer_closed, "finite");
    if (!(params.min_separation >= 0.0) || !std::isfinite(params.min_separation))
        fail("min_separation", params.min_separation, ">= 0 and finite");
    if (!(params.separation_tolerance >= 0.0 && params.separation_tolerance < 1.0))
        fail("separation_tolerance", params.separation_tolerance, "in [0, 1)");
    validate(params.field);
    validate(params.composition);
}

UntangleReport untangle_local(Scene& scene, const Box2& box, std::size_t n_out,
                              const UntangleParams& params, const ProgressFn& progress) {
    const std::vector<Piece> pieces = localize(scene, box, n_out);
    // The checks look near the pieces (free vertices and collars), with room for the free
    // vertices to move by half the pieces' extent; a move beyond is checked whole.
    Box2 region;
    for (const Piece& piece : pieces)
        for (std::size_t v : piece.vertices) region.extend(scene.layer(piece.layer).points[v]);
    const Vec2 size = region.size();
    region = region.inflated(0.5 * std::max(size.x, size.y));
    return detail::run_untangling(scene, pieces, params, progress, false, &region);
}

}  // namespace strata
