// strata simplify: collision-free simplification of one scene, a demo, or a batch of slices.
#include "check_marks.h"
#include "cli_util.h"
#include "commands.h"
#include "simplify_batch.h"
#include "time_limit.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/io/atomic_file.h"
#include "strata/io/scene_io.h"
#include "strata/io/svg_io.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <sys/resource.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

namespace strata::cli {

namespace {

namespace fs = std::filesystem;

void print_summary(const std::string& name, const SimplifyReport& r, const SimplifyReport* naive) {
    std::printf("%-22s %8s %8s %8s %8s %9s %12s\n", "layer", "before", "after", "target", "refused",
                "untangled", "hausdorff");
    for (const LayerSimplifyReport& l : r.layers)
        std::printf("%-22s %8zu %8zu %8zu %8zu %9zu %12.4g\n", shown_name(l.name).c_str(), l.before,
                    l.after, l.target, l.refused, l.untangled, l.hausdorff);
    std::size_t before = 0, after = 0;
    for (const LayerSimplifyReport& l : r.layers) {
        before += l.before;
        after += l.after;
    }
    std::printf(
        "%s: vertices %zu -> %zu; crossings naive %s, strata %zu; nesting violations naive %s, "
        "strata %zu\n",
        name.c_str(), before, after, naive ? std::to_string(naive->crossings).c_str() : "-",
        r.crossings, naive ? std::to_string(naive->nesting_violations).c_str() : "-",
        r.nesting_violations);
    std::printf(
        "min separation ratio %.4g; max Hausdorff %.4g; removals %zu, set aside %zu, untangled "
        "%zu in %zu batches, refused %zu (%zu gave up early); time %.3f s (decimate %.3f, fields "
        "%.3f, untangle %.3f, finish %.3f, check %.3f); peak memory %.0f MiB\n",
        r.min_separation_ratio, max_hausdorff(r), r.removed, r.deferred, r.untangle_calls,
        r.batches, r.refused, r.gave_up, r.seconds_total, r.seconds_decimate, r.seconds_fields,
        r.seconds_untangle, r.seconds_finish, r.seconds_check, peak_memory_mib());
    if (r.raised_separations > 0)
        std::printf(
            "gap rule: %zu pairs of layers without thickness keep their share of the "
            "input gap (--keep-gaps)\n",
            r.raised_separations);
    if (r.restored > 0)
        std::printf(
            "last resort: the exact check of the result failed where the local checks could "
            "not see; %zu input vertices came back around it\n",
            r.restored);
    if (r.trimmed_ends > 0)
        std::printf(
            "budget: %zu end vertices of open layers taken out to meet their target "
            "(--no-trim-ends keeps them)\n",
            r.trimmed_ends);
    if (r.rolled_vertices > 0)
        std::printf(
            "local sides: %zu output vertices lie on the other side of an open layer than the "
            "global order (rolled or folded over), as in the input\n",
            r.rolled_vertices);
    if (!r.collision_free)
        std::fprintf(
            stderr,
            "strata: warning: %s: the result is NOT collision-free (%zu crossings, %zu nesting "
            "violations)\n",
            name.c_str(), r.crossings, r.nesting_violations);
    if (!r.targets_met)
        std::fprintf(
            stderr,
            "strata: warning: %s: %zu removals refused; some layers stay above their target "
            "(see the table)\n",
            name.c_str(), r.refused);
}

int run_demo(const SimplifyOptions& opt) {
    const fs::path dir = opt.output.empty() ? fs::path("strata-demo") : fs::path(opt.output);
    fs::create_directories(dir);
    const Scene input = demo_scene();
    Scene result, naive;
    SimplifyOptions demo = opt;
    demo.compare_naive = true;  // the demo shows what naive decimation does
    const Outcome o = run_one(input, demo, terminal_progress(), result, &naive);
    write_scene(input, dir / "input.json");
    write_scene(naive, dir / "naive.json");
    write_scene(result, dir / "strata.json");
    SvgWriteParams svg;
    svg.width_px = 1000.0;
    write_file_atomic(
        dir / "compare.svg",
        panels_to_svg(
            {{"input (" + std::to_string(input.vertex_count()) + " vertices)", &input, nullptr, {}},
             {"naive decimation: layers cross (red)", &naive, &input,
              contact_marks(naive, check_scene(naive))},
             {"strata: collision-free", &result, &input, {}}},
            svg));
    nlohmann::json j = report_json(*o.report, &*o.naive);
    j["peak_memory_mib"] = peak_memory_mib();
    write_file_atomic(dir / "report.json", json_report_text(j) + "\n");
    std::printf(
        "demo: 5 stacked cloth-like layers, %zu vertices; outputs in %s/ (input.json, naive.json, "
        "strata.json, compare.svg, report.json)\n",
        input.vertex_count(), dir.string().c_str());
    print_summary("demo", *o.report, &*o.naive);
    return o.report->collision_free ? 0 : 1;
}

int run_batch(const SimplifyOptions& opt, const std::vector<std::string>& files) {
    if (opt.output.empty()) throw InvalidInput("simplify: several inputs need -o FOLDER");
    if (!fs::is_directory(opt.output)) fs::create_directories(opt.output);
    std::vector<Outcome> outcomes(files.size());
    tbb::parallel_for(std::size_t(0), files.size(), [&](std::size_t i) {
        outcomes[i] = simplify_slice(files[i], batch_output(opt.output, files[i]), opt);
    });
    std::fputs(batch_header().c_str(), stdout);
    BatchTotals totals;
    nlohmann::json all = nlohmann::json::array();
    for (const Outcome& o : outcomes) {
        totals.add(o);
        std::fputs(batch_row(o).c_str(), stdout);
        all.push_back(batch_entry(o));
    }
    std::fputs(batch_footer(totals, peak_memory_mib()).c_str(), stdout);
    if (!opt.report.empty()) write_file_atomic(opt.report, json_report_text(all) + "\n");
    return totals.exit_code();
}

}  // namespace

Run add_simplify_command(CLI::App& app) {
    auto opt = std::make_shared<SimplifyOptions>();
    SimplifyParams& p = opt->params;
    UntangleParams& u = p.untangling;
    CLI::App* cmd = app.add_subcommand("simplify",
                                       "Collision-free simplification. No input: the built-in "
                                       "demo, outputs in strata-demo/ (or -o FOLDER). "
                                       "Several inputs or a folder: a batch into -o FOLDER.");
    cmd->add_option("inputs", opt->inputs, "Scene files (.json, .svg) or folders");
    cmd->add_option("-o,--output", opt->output,
                    "Output scene (one input), or folder (demo, batch)");
    cmd->add_option("--remove", p.remove, "Fraction of each layer's vertices to remove")
        ->capture_default_str();
    add_count_option(*cmd, "--keep", p.keep, "Vertices to keep per layer (instead of --remove)");
    cmd->add_option("--max-error", p.max_error,
                    "Never leave an input vertex farther than this (scene units)");
    CLI::Option* decimator =
        cmd->add_option("--decimator", p.decimator,
                        "random | visvalingam | max-error (demo: random, as in the paper)")
            ->capture_default_str();
    cmd->add_option("--seed", p.seed, "Seed of the random decimator")->capture_default_str();
    add_count_option(*cmd, "--untangle-batch", p.batch,
                     "Untanglings run side by side when their regions keep apart (1: one at a "
                     "time, the paper's order)",
                     1);
    add_count_option(*cmd, "--n-out", p.n_out, "N_out: fixed collar vertices around each piece");
    static const std::map<std::string, UntangleSchedule> schedules{
        {"deferred", UntangleSchedule::Deferred}, {"immediate", UntangleSchedule::Immediate}};
    add_choice_option(*cmd, "--schedule", p.schedule, schedules,
                      "deferred: removals that need untangling wait until a layer cannot reach "
                      "its target otherwise (fast); immediate: untangle after every such "
                      "removal (the paper's Algorithm 1)",
                      "deferred");
    add_backend_option(*cmd, u.field.backend);
    cmd->add_option("--alpha", u.alpha, "Shape-matching stiffness")->capture_default_str();
    cmd->add_option("--beta", u.beta, "Quadratic share of shape matching")->capture_default_str();
    cmd->add_option("--gradient-steps", u.gradient_steps, "N_gd")->capture_default_str();
    cmd->add_option("--tolerance", u.tolerance, "epsilon, relative to the scene diagonal")
        ->capture_default_str();
    cmd->add_option("--max-rounds", u.max_rounds, "Rounds per untangling pass")
        ->capture_default_str();
    cmd->add_option("--thickness", opt->thickness,
                    "Thickness for layers whose thickness is 0 (scene units)");
    cmd->add_option("--keep-gaps", p.keep_input_gaps,
                    "Pairs of layers whose thicknesses require nothing keep this share of their "
                    "smallest input gap (0: off)")
        ->capture_default_str();
    add_threads_option(*cmd, opt->threads);
    add_time_limit_option(*cmd, opt->time_limit,
                          "each input (a slice of a batch on its own clock)");
    cmd->add_flag("--global", p.global,
                  "Untangle the whole scene after each tangling removal (slow; comparison)");
    cmd->add_flag("--no-untangle", opt->naive, "Naive decimation only");
    cmd->add_flag_callback(
        "--no-trim-ends", [opt] { opt->params.trim_ends = false; },
        "Open layers keep both ends even when that leaves them above their target");
    cmd->add_flag("--compare-naive", opt->compare_naive,
                  "Also run the naive decimation, for its numbers (the demo always does)");
    static const std::map<std::string, InputCrossings> crossing_modes{
        {"untangle", InputCrossings::Untangle},
        {"skip", InputCrossings::Skip},
        {"fail", InputCrossings::Fail}};
    add_choice_option(*cmd, "--input-crossings", opt->input_crossings, crossing_modes,
                      "An input that already crosses: untangle it first (global untangling), "
                      "skip it (batch; one input: exit 1, nothing written) or fail (exit 2)",
                      "untangle");
    cmd->add_flag("--no-shape-matching", opt->no_shape_matching, "Pure projection");
    cmd->add_flag("--no-finish", opt->no_finish,
                  "Untangle without the finishing stage (exact separation constraints)");
    cmd->add_option("--svg", opt->svg,
                    "Picture: input / strata, with --compare-naive input / naive / strata (one "
                    "input)");
    cmd->add_option("--report", opt->report, "Report as JSON");
    return [opt, decimator]() {
        SimplifyOptions o = *opt;
        if (o.inputs.empty() && decimator->count() == 0) o.params.decimator = "random";
        if (o.no_shape_matching) o.params.untangling.shape = ShapeMode::None;
        if (o.no_finish) o.params.untangling.finish_separations = false;
        validate(o.params);
        const auto threads = thread_limit("simplify", o.threads);
        if (o.inputs.empty()) return run_demo(o);
        const std::vector<std::string> files = expand_inputs(o.inputs);
        if (files.size() > 1 || fs::is_directory(o.inputs.front())) return run_batch(o, files);

        if (o.output.empty()) throw InvalidInput("simplify: -o OUT is required with one input");
        check_outputs({o.output, o.svg, o.report}, files);
        scene_format(o.output);
        const Scene input = with_default_thickness(read_scene(files.front()), o.thickness);
        for (const std::string& note : input.diagnostics().notes)
            std::cerr << "strata: note: " << files.front() << ": " << note << '\n';
        const std::string name = fs::path(files.front()).filename().string();
        std::optional<InputUntangling> untangled;
        const TimeLimit deadline(o.time_limit);
        const ProgressFn progress = deadline.around(terminal_progress());
        // Stopped at the time limit: nothing written, exit 1 (main()). A bar left unfinished is
        // ended before anything else is printed.
        const std::optional<Scene> prepared = deadline.guard(files.front(), [&] {
            return prepare_input(input, files.front(), o.input_crossings, o.params, untangled,
                                 progress);
        });
        end_progress_line();
        if (!prepared) {
            std::fprintf(stderr,
                         "strata: %s: the input crosses; skipped (--input-crossings skip), "
                         "nothing written\n",
                         files.front().c_str());
            return 1;
        }
        if (untangled)
            std::printf(
                "%s: the input crossed (%zu crossings, %zu nesting violations): untangled first "
                "(%zu vertices moved, at most %.4g; gap ratio %.4g; %d passes%s)\n",
                name.c_str(), untangled->crossings, untangled->nesting_violations,
                untangled->report.moved_vertices, untangled->report.max_displacement,
                untangled->report.min_separation_ratio_after, untangled->report.passes,
                untangled->report.inferred_sides
                    ? "; it has rolled regions: the sides of open layers inferred per region "
                      "of the input, as 'strata untangle' does"
                    : "");
        Scene result, naive;
        const Outcome out = deadline.guard(
            files.front(), [&] { return run_one(*prepared, o, progress, result, &naive); });
        end_progress_line();
        write_scene(result, o.output);
        const SimplifyReport* naive_report = out.naive ? &*out.naive : nullptr;
        if (!o.svg.empty()) {
            SvgWriteParams svg;
            svg.width_px = 1000.0;
            // Where the input and the naive decimation cross, marked in red.
            auto crossings = [](const Scene& s) { return contact_marks(s, check_scene(s)); };
            std::vector<SvgPanel> panels{{untangled ? "input (crossing)" : "input", &input, nullptr,
                                          untangled ? crossings(input) : std::vector<SvgMark>{}}};
            if (untangled) panels.push_back({"input untangled", &*prepared, &input, {}});
            if (naive_report && !o.naive)
                panels.push_back({"naive decimation", &naive, &input, crossings(naive)});
            panels.push_back({o.naive ? "naive decimation" : "strata", &result, &input,
                              o.naive ? crossings(result) : std::vector<SvgMark>{}});
            write_file_atomic(o.svg, panels_to_svg(panels, svg));
        }
        if (!o.report.empty()) {
            nlohmann::json j = report_json(*out.report, naive_report);
            if (untangled) j["input_untangled"] = untangling_json(*untangled);
            j["peak_memory_mib"] = peak_memory_mib();
            write_file_atomic(o.report, json_report_text(j) + "\n");
        }
        print_summary(name, *out.report, naive_report);
        return out.report->collision_free ? 0 : 1;
    };
}

}  // namespace strata::cli
