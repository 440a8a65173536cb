// simplify(): the collision-free simplification driver. It wires the parts under detail/,
// each a file to read alone, in this order:
//   work_layer.h       a layer being decimated: its vertices, the alive ones linked in order
//   segment_grid.h     the spatial index of live segments
//   live_polylines.h   the layers being decimated, kept in step with their segment grid
//   separations.h      the distance every layer keeps from every other
//   untangle_job.h     one local untangling; the Overlay the checks read positions through
//   local_check.h      the exact test that a removal or an untangling keeps its region clean
//   job_runner.h       prepares, executes and applies untangling jobs
//   scheduler.h        the queue of removals, the deferred and immediate schedules, batches
// then checks the whole result exactly (check_scene()), and where that still fails
//   restore.h          puts the input back around what is wrong until it passes.
#include "strata/simplify/simplify.h"

#include "simplify/detail/job_runner.h"
#include "simplify/detail/live_polylines.h"
#include "simplify/detail/local_check.h"
#include "simplify/detail/restore.h"
#include "simplify/detail/scheduler.h"
#include "simplify/detail/separations.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_gaps.h"
#include "strata/simplify/decimator.h"
#include "untangle/detail/engine.h"

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

namespace strata {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// The vertex count each layer comes down to: `keep`, or the input's less `remove` of it, at
// least 3 on a closed layer and 2 on an open one.
std::vector<std::size_t> targets_of(const Scene& scene, const SimplifyParams& params) {
    std::vector<std::size_t> targets;
    for (std::size_t l = 0; l < scene.size(); ++l) {
        const Layer& in = scene.layer(l);
        const std::size_t m = in.points.size();
        const std::size_t floor_count = in.closed ? 3 : 2;
        const std::size_t target =
            params.keep > 0
                ? params.keep
                : m - static_cast<std::size_t>(std::floor(params.remove * static_cast<double>(m)));
        targets.push_back(std::max(std::min(target, m), floor_count));
    }
    return targets;
}

}  // namespace

void validate(const SimplifyParams& params) {
    if (!(params.remove >= 0.0 && params.remove <= 1.0))
        throw InvalidInput("simplify: params.remove must be in [0, 1] (got " +
                           format_number(params.remove) + ")");
    if (!(params.max_error >= 0.0) || !std::isfinite(params.max_error))
        throw InvalidInput("simplify: params.max_error must be >= 0 and finite (got " +
                           format_number(params.max_error) + ")");
    if (params.batch < 1) throw InvalidInput("simplify: params.batch must be >= 1 (got 0)");
    if (!(params.keep_input_gaps >= 0.0 && params.keep_input_gaps <= 1.0))
        throw InvalidInput("simplify: params.keep_input_gaps must be in [0, 1] (got " +
                           format_number(params.keep_input_gaps) + ")");
    make_decimator(params.decimator, params.seed);
    validate(params.untangling);
    // simplify() takes both from its input (record_input_sides(), outside_side()).
    if (!params.untangling.outside_sides.empty())
        throw InvalidInput("simplify: params.untangling.outside_sides must be empty (got " +
                           std::to_string(params.untangling.outside_sides.size()) +
                           " entries): the input's own are used");
    if (params.untangling.input_sides)
        throw InvalidInput(
            "simplify: params.untangling.input_sides must be null: the sides of the input are "
            "recorded and kept");
}

SimplifyReport simplify(Scene& scene, const SimplifyParams& params, const ProgressFn& progress) {
    validate(params);
    // The gap rule raises required separations on a copy: `scene` stays unchanged on throw.
    Scene input = scene;
    std::size_t raised = 0;
    if (params.untangle && params.keep_input_gaps > 0.0) {
        InputGapParams gap_params;
        // Gaps pass at required x (1 - separation_tolerance): ask for enough that the kept
        // share is keep_input_gaps, at most the whole gap.
        gap_params.fraction =
            std::min(1.0, params.keep_input_gaps / (1.0 - params.untangling.separation_tolerance));
        raised = keep_input_gaps(input, gap_params).raised;
    }

    detail::EngineSettings settings;
    if (params.untangle) settings = detail::resolve_settings(input, params.untangling);
    detail::LivePolylines live(input, targets_of(input, params));
    const detail::Separations separations =
        detail::separations_of(input, params.untangling.separation_tolerance);
    // The input's sides of the open layers near each vertex: what the local and the final
    // checks keep (a rolled part stays rolled). Outside sides resolved for the untangling, or
    // here when it does not run.
    const std::vector<int> outside_signs =
        settings.outside_signs.empty() ? outside_sides(input) : settings.outside_signs;
    // Found when asked for: by the local checks and the untanglings for the vertices they
    // move, by the final check for the vertices kept.
    const InputSides input_sides = record_input_sides(input);
    const detail::LocalCheck check(input, live, separations, outside_signs, input_sides);
    detail::JobRunner jobs(input, params, settings, live, separations, check, input_sides);
    detail::Scheduler scheduler(params, live, separations, check, jobs);
    SimplifyReport report = scheduler.run(progress);
    report.raised_separations = raised;
    Scene out = live.to_scene(input);
    for (const Scene::RaisedSeparation& r : input.raised_separations())
        out.raise_required_separation(r.a, r.b, r.value);

    auto start = Clock::now();
    CheckParams check_params;
    check_params.separation_tolerance = params.untangling.separation_tolerance;
    // The input's open-layer sides: vertex order is kept, and the vote of outside_side() is
    // unreliable on layers simplified to a few vertices. The input is the reference of the
    // local sides too: a nesting violation is a vertex that changed side.
    check_params.outside_sides = outside_signs;
    report.origins = live.origins();
    const InputSides output_sides = input_sides.renumbered(report.origins);
    report.rolled_vertices = output_sides.rolled_count(out, outside_signs);
    check_params.input_sides = &output_sides;
    CheckReport check_report = check_scene(out, check_params);
    if (params.untangle && !detail::passes(check_report)) {
        // What the local checks could not see: the input comes back around it.
        // Kept only when it passes: an input that is itself tangled never does, and then the
        // simplified result is returned as it is, reported not collision-free.
        detail::Restored restored = detail::restore_near_violations(input, live, out, check_report,
                                                                    check_params, input_sides);
        if (detail::passes(restored.check)) {
            out = std::move(restored.scene);
            report.origins = std::move(restored.origins);
            check_report = std::move(restored.check);
            report.restored = restored.restored;
            report.rolled_vertices =
                input_sides.renumbered(report.origins).rolled_count(out, outside_signs);
        }
    }
    bool above_target = false;
    for (std::size_t l = 0; l < out.size(); ++l)
        above_target = above_target || out.layer(l).points.size() > live.layer(l).target;
    // Not under max_error: the whole-scene removals do not bound the error (a layer then
    // stays above its target by design).
    if (params.untangle && params.max_error == 0.0 && above_target &&
        detail::passes(check_report)) {
        // Layers left above their target: removals the exact check of the whole scene allows
        // where the local ones refused, then end vertices of open layers (trim_ends).
        detail::Restored thinned{out, report.origins, check_report, 0, 0};
        std::vector<std::size_t> targets(input.size());
        for (std::size_t l = 0; l < input.size(); ++l) targets[l] = live.layer(l).target;
        report.trimmed_ends = detail::meet_targets(input, thinned, targets, check_params,
                                                   input_sides, params.trim_ends);
        out = std::move(thinned.scene);
        report.origins = std::move(thinned.origins);
        check_report = std::move(thinned.check);
        report.rolled_vertices =
            input_sides.renumbered(report.origins).rolled_count(out, outside_signs);
    }
    report.crossings = check_report.crossing_count;
    report.self_crossings = check_report.total_self_crossings();
    report.nesting_violations = check_report.nesting_violation_count;
    report.min_separation_ratio = check_report.min_separation_ratio;
    report.collision_free = check_report.is_collision_free() && check_report.separations_hold();
    const Vec2 size = scene.bounds().size();
    const double tolerance = 1e-6 * std::max(std::hypot(size.x, size.y), 1e-300);
    for (std::size_t l = 0; l < scene.size(); ++l) {
        LayerSimplifyReport& r = report.layers[l];
        const Layer& before = scene.layer(l);
        const Layer& after = out.layer(l);
        r.name = before.name;
        r.before = before.points.size();
        r.after = after.points.size();
        r.target = live.layer(l).target;
        for (std::size_t k = 0; k < after.points.size(); ++k)
            r.max_displacement = std::max(
                r.max_displacement,
                glm::distance(after.points[k], input.layer(l).points[report.origins[l][k]]));
        if (r.after > r.target) report.targets_met = false;
    }
    tbb::parallel_for(std::size_t{0}, scene.size(), [&](std::size_t l) {
        report.layers[l].hausdorff = hausdorff(out.layer(l), scene.layer(l), tolerance).symmetric();
    });
    report.seconds_check += seconds_since(start);
    scene = std::move(out);
    return report;
}

}  // namespace strata
