// strata untangle: global untangling of a scene that is already tangled.
#include "check_marks.h"
#include "cli_util.h"
#include "commands.h"
#include "reference.h"
#include "time_limit.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/io/atomic_file.h"
#include "strata/io/scene_io.h"
#include "strata/io/svg_io.h"
#include "strata/untangle/untangle.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace strata::cli {

namespace {

struct UntangleOptions {
    std::string input, output, svg, report, reference;
    double thickness = 0.0;
    double time_limit = 0.0;  // seconds, 0: none
    int threads = 0;          // 0: all cores
    bool no_shape_matching = false;
    bool no_finish = false;
    bool infer_sides = false;
    bool global_order = false;
    UntangleParams params;
};

}  // namespace

Run add_untangle_command(CLI::App& app) {
    auto opt = std::make_shared<UntangleOptions>();
    UntangleParams& p = opt->params;
    CLI::App* cmd = app.add_subcommand("untangle",
                                       "Untangle a scene whose layers cross or are too close (exit "
                                       "0 when the result is collision-free)");
    cmd->add_option("input", opt->input, "Scene file (.json or .svg)")->required();
    cmd->add_option("-o,--output", opt->output, "Untangled scene (.json or .svg)")->required();
    cmd->add_option("--svg", opt->svg,
                    "Picture: the result over the input (faint), what is left tangled marked in "
                    "red");
    cmd->add_option("--report", opt->report, "Report as JSON");
    cmd->add_option("--reference", opt->reference,
                    "Original scene (before decimation), layers matched by name: every vertex "
                    "keeps the side of the open layers it has there (a rolled or folded-over "
                    "part stays so); without it, the sides inferred per region (as --infer-sides) "
                    "where the input has rolled regions and that comes out clean, else the global "
                    "order, else the clean other reading of those regions that moves least");
    cmd->add_flag("--infer-sides", opt->infer_sides,
                  "Without the original: take the sides of the open layers from the input "
                  "itself, each region of a layer on the side most of its vertices are (a "
                  "rolled part stays so, a vertex a tangle put across takes its region's), "
                  "with no fallback to the global order")
        ->excludes("--reference");
    cmd->add_flag("--global-order", opt->global_order,
                  "The global order everywhere, also over a rolled part (which it pushes back)")
        ->excludes("--reference")
        ->excludes("--infer-sides");
    cmd->add_option("--thickness", opt->thickness,
                    "Thickness for layers whose thickness is 0 (scene units)")
        ->capture_default_str();
    add_backend_option(*cmd, p.field.backend);
    cmd->add_option("--alpha", p.alpha, "Shape-matching stiffness (layers without their own)")
        ->capture_default_str();
    cmd->add_option("--beta", p.beta, "Quadratic share of shape matching")->capture_default_str();
    cmd->add_option("--gradient-steps", p.gradient_steps,
                    "N_gd: projection steps per shape matching")
        ->capture_default_str();
    cmd->add_option("--tolerance", p.tolerance,
                    "epsilon: convergence speed, relative to the scene diagonal")
        ->capture_default_str();
    cmd->add_option("--max-rounds", p.max_rounds, "Cap on rounds per pass")->capture_default_str();
    cmd->add_option("--max-passes", p.max_passes, "Field rebuilds when a pass ends tangled")
        ->capture_default_str();
    cmd->add_option("--voxel", p.field.voxel_size, "Grid voxel size (scene units; 0 = auto)")
        ->capture_default_str();
    cmd->add_option("--stiffer-closed", p.stiffer_closed,
                    "Without --reference, --infer-sides or --global-order, on a clean result "
                    "of a scene with closed and open layers: untangle once more by the same "
                    "sides with the closed layers' weights times this (e.g. 4), and keep the "
                    "result that moves the vertices less (<= 1: no)")
        ->capture_default_str();
    add_time_limit_option(*cmd, opt->time_limit, "the untangling");
    add_threads_option(*cmd, opt->threads);
    cmd->add_flag("--give-up-when-stalled", p.give_up_when_stalled,
                  "End a try early when its violation, extrapolated, would not fall enough by the "
                  "pass cap");
    cmd->add_flag("--no-shape-matching", opt->no_shape_matching,
                  "Pure projection (the paper's Fig. 2 artefacts)");
    cmd->add_flag("--no-finish", opt->no_finish,
                  "No finishing stage (exact separation constraints): the paper's method alone");
    return [opt]() {
        const TimeLimit limit(opt->time_limit);
        UntangleParams params = opt->params;
        if (opt->no_shape_matching) params.shape = ShapeMode::None;
        if (opt->no_finish) params.finish_separations = false;
        validate(params);
        const auto threads = thread_limit("untangle", opt->threads);
        check_outputs({opt->output, opt->svg, opt->report}, {opt->input, opt->reference});
        scene_format(opt->output);  // reject a bad extension before working
        const Scene input = with_default_thickness(read_scene(opt->input), opt->thickness);
        for (const std::string& note : input.diagnostics().notes)
            std::cerr << "strata: note: " << opt->input << ": " << note << '\n';
        // The original's sides of its open layers (or the input's own, per region), kept
        // where they are not the global order's.
        std::optional<Reference> reference;
        InputSides inferred;
        CheckParams check_params;
        if (!opt->reference.empty()) {
            reference = read_reference(opt->reference, input, 0.0, true, opt->thickness);
            params.outside_sides = reference->outside_sides;
            params.input_sides = &reference->sides;  // untangling keeps the vertex indices
        } else if (opt->infer_sides) {
            params.outside_sides = untangling_outside_sides(input);
            inferred = infer_input_sides(input, {}, params.outside_sides);
            params.input_sides = &inferred;
            params.open_cut_bends = false;  // inferred sides, in question at a cut bend
        }
        // Judged as untangle() judges: by the outside sides it untangles toward (the input's
        // when none are given), not by a fresh vote on the result.
        check_params.outside_sides =
            params.outside_sides.empty() ? untangling_outside_sides(input) : params.outside_sides;
        check_params.input_sides = params.input_sides;
        Scene scene = input;
        const auto start = std::chrono::steady_clock::now();
        // Without an original, or with one (whose sides are not in question: long rounds when
        // the first tries fail), the tries of untangle_inferring_sides(); --global-order and
        // --infer-sides: one untangle().
        const bool fallback = !opt->global_order && !opt->infer_sides;
        const ProgressFn progress = limit.around(terminal_progress());
        const UntangleReport r = limit.guard(opt->input, [&] {
            return fallback ? untangle_inferring_sides(scene, params, progress, &inferred)
                            : untangle(scene, params, progress);
        });
        end_progress_line();
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        // The input's rolled regions were kept, or the original's sides but those read at a
        // fold's other sheet (InputSides::off_other_sheets()): `inferred` holds them.
        if (r.inferred_sides || r.sides_left_out > 0) {
            params.input_sides = &inferred;
            check_params.input_sides = &inferred;
        }
        // (Vertices closer than untangle() allows are listed for the picture.)
        check_params.separation_tolerance = params.separation_tolerance;
        const CheckReport after = check_scene(scene, check_params);

        write_scene(scene, opt->output);
        if (!opt->svg.empty()) {
            // What is left when the result is not clean, marked in red.
            SvgWriteParams svg = check_marks(scene, after, params.separation_tolerance);
            svg.underlay = &input;
            write_scene_svg(scene, opt->svg, svg);
        }
        if (!opt->report.empty()) {
            nlohmann::json j = {
                {"input", opt->input},
                {"output", opt->output},
                {"backend", backend_name(params.field.backend)},
                {"tries", r.tries},
                {"passes", r.passes},
                {"rounds", r.rounds},
                {"converged", r.converged},
                {"collision_free", r.collision_free},
                {"free_vertices", r.free_vertices},
                {"moved_vertices", r.moved_vertices},
                {"max_displacement", r.max_displacement},
                {"crossings_before", r.crossings_before},
                {"crossings_after", r.crossings_after},
                {"self_crossings_after", after.total_self_crossings()},
                {"nesting_violations_after", after.nesting_violation_count},
                {"min_separation_ratio_after", std::isfinite(r.min_separation_ratio_after)
                                                   ? nlohmann::json(r.min_separation_ratio_after)
                                                   : nlohmann::json(nullptr)},
                {"seconds",
                 {{"fields", r.seconds_fields},
                  {"untangle", r.seconds_untangle},
                  {"finish", r.seconds_finish},
                  {"check", r.seconds_check},
                  {"total", seconds}}},
                {"finishes", r.finishes},
                {"finish_moves", r.finish_moves},
                {"kept_simple", r.kept_simple},
                {"long_rounds", r.long_rounds},
                {"retry_passes", r.retry_passes},
                {"more_passes", r.more_passes},
                {"loop_reading", r.loop_reading},
                {"untwisted", r.untwisted},
                {"ends_retracted", r.ends_retracted},
                {"restarted", r.restarted},
                {"ends_by_nearest", r.ends_by_nearest},
                {"short_edges", r.short_edges},
                {"end_sides_dropped", r.end_sides_dropped},
                {"stiffer_closed", r.stiffer_closed},
                {"input_kept", r.input_kept},
                {"gave_up", r.gave_up}};
            if (params.input_sides)
                j["sides"] = {{"from", reference ? opt->reference : "inferred"},
                              {"rolled_vertices", r.rolled_vertices},
                              {"rolled_kept", r.rolled_kept},
                              {"reading", r.sides_reading}};
            if (reference) j["sides"]["left_out"] = r.sides_left_out;
            write_file_atomic(opt->report, json_report_text(j) + "\n");
        }
        std::printf("%s -> %s: %zu layers, %zu vertices\n", opt->input.c_str(), opt->output.c_str(),
                    scene.size(), scene.vertex_count());
        std::printf(
            "crossings between layers: %zu before, %zu after; nesting violations after: %zu\n",
            r.crossings_before, r.crossings_after, after.nesting_violation_count);
        if (params.input_sides) {
            std::string why;
            if (!r.collision_free && r.inferred_sides)
                why = r.sides_reading > 0 ? " (the least tangled try kept was by another reading "
                                            "of the regions, number " +
                                                std::to_string(r.sides_reading) + ")"
                                          : " (the least tangled try kept was by the inferred "
                                            "sides)";
            else if (r.end_sides_dropped)
                why =
                    " (the input's rolled regions as inferred did not come out clean: kept the "
                    "first other reading of those regions with no side around another layer's "
                    "end, tried before the global order)";
            else if (r.sides_reading > 0)
                why =
                    " (neither the input's rolled regions as inferred nor the global order "
                    "came out clean: kept another reading of those regions, number " +
                    std::to_string(r.sides_reading) + ", the clean one that moved least)";
            else if (r.inferred_sides && r.rolled_vertices > 0)
                why = " (the input has rolled regions)";
            else if (r.inferred_sides)
                why =
                    " (the global order did not come out clean: kept its sides but none for the "
                    "vertices around another layer's end, where only the distance counts)";
            else if (r.sides_left_out > 0)
                why = "; " + std::to_string(r.sides_left_out) +
                      " vertex sides read at the other sheet of a fold the decimation closed "
                      "left out (only the distance counts there)";
            std::printf(
                "sides %s %s: %zu vertices on a rolled side (the other side of an open layer "
                "than the global order), %zu kept it%s\n",
                reference ? "from" : "inferred from",
                reference ? opt->reference.c_str() : opt->input.c_str(), r.rolled_vertices,
                r.rolled_kept, why.c_str());
        }
        const std::string stiffer = r.stiffer_closed ? " (kept the result with the closed layers " +
                                                           short_number(params.stiffer_closed) +
                                                           "x stiffer: it moved the vertices less)"
                                                     : "";
        // A last resort that shortens layers: say so (UntangleReport::ends_retracted).
        const std::string retracted =
            r.ends_retracted > 0 ? " (" + std::to_string(r.ends_retracted) +
                                       (r.ends_retracted == 1 ? " end" : " ends") +
                                       " of open layers moved back along their end segments)"
                                 : "";
        std::printf(
            "min separation ratio after: %.4g; moved vertices: %zu of %zu; max displacement: "
            "%.4g%s%s\n",
            r.min_separation_ratio_after, r.moved_vertices, r.free_vertices, r.max_displacement,
            stiffer.c_str(), retracted.c_str());
        // Every try failed: the result is the least tangled of theirs, or the input.
        const char* kept = r.collision_free ? ""
                           : r.input_kept   ? " (no try less tangled: kept the input unchanged)"
                                            : " (kept the least tangled try)";
        std::printf(
            "tries: %d, passes: %d, rounds: %d, %s%s; time %.3f s (%sfields %.3f, untangle %.3f, "
            "finish %.3f, check %.3f)\n",
            r.tries, r.passes, r.rounds,
            r.collision_free ? "collision-free"
            : r.input_kept   ? "NOT collision-free"
            : r.gave_up      ? "NOT collision-free, gave up stalled"
            : r.converged    ? "converged, NOT collision-free"
                             : "NOT collision-free at the pass cap",
            kept, seconds,
            // Tries after a failed one can run two at a time: their phases can sum to more.
            r.tries > 1 ? "summed over the tries, " : "", r.seconds_fields, r.seconds_untangle,
            r.seconds_finish, r.seconds_check);
        if (!r.collision_free) {
            std::string why;
            if (!after.self_crossings.empty()) {
                const Crossing& c = after.self_crossings.front();
                const Layer& layer = scene.layer(c.layer_a);
                why = layer.closed && is_flat(layer.points)
                          ? "; layer '" + shown_text(layer.name) +
                                "' is flat: all its points are collinear"
                          : "; layer '" + shown_text(layer.name) + "' crosses itself (segments " +
                                std::to_string(c.segment_a) + " and " +
                                std::to_string(c.segment_b) + " at (" + format_number(c.point.x) +
                                ", " + format_number(c.point.y) + "))";
            }
            std::fprintf(stderr,
                         "strata: warning: the result is NOT collision-free (%zu self-crossings%s; "
                         "see 'strata check %s')\n",
                         after.total_self_crossings(), why.c_str(), opt->output.c_str());
        }
        return r.collision_free ? 0 : 1;
    };
}

}  // namespace strata::cli
