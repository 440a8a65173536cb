// What `strata simplify` does to one scene and to each slice of a batch (simplify_batch.h).
#include "simplify_batch.h"

#include "cli_util.h"
#include "time_limit.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_gaps.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/atomic_file.h"
#include "strata/io/scene_io.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <new>

namespace strata::cli {

namespace {

namespace fs = std::filesystem;

// printf into a std::string.
__attribute__((format(printf, 1, 2))) std::string format(const char* fmt, ...) {
    va_list args;
    va_start(args, fmt);
    va_list copy;
    va_copy(copy, args);
    const int n = std::vsnprintf(nullptr, 0, fmt, copy);
    va_end(copy);
    std::string out(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
    if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
    va_end(args);
    return out;
}

}  // namespace

nlohmann::json finite_or_null(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json report_json(const SimplifyReport& r, const SimplifyReport* naive) {
    nlohmann::json layers = nlohmann::json::array();
    for (const LayerSimplifyReport& l : r.layers)
        layers.push_back({{"name", l.name},
                          {"before", l.before},
                          {"after", l.after},
                          {"target", l.target},
                          {"refused", l.refused},
                          {"untangled", l.untangled},
                          {"hausdorff", l.hausdorff},
                          {"max_displacement", l.max_displacement}});
    nlohmann::json j = {{"layers", layers},
                        {"removed", r.removed},
                        {"untangle_calls", r.untangle_calls},
                        {"refused", r.refused},
                        {"gave_up", r.gave_up},
                        {"chord_shifts", r.chord_shifts},
                        {"shape_refused", r.shape_refused},
                        {"deferred", r.deferred},
                        {"rounds", r.rounds},
                        {"batches", r.batches},
                        {"batch_reruns", r.batch_reruns},
                        {"targets_met", r.targets_met},
                        {"raised_separations", r.raised_separations},
                        {"rolled_vertices", r.rolled_vertices},
                        {"restored", r.restored},
                        {"trimmed_ends", r.trimmed_ends},
                        {"crossings", r.crossings},
                        {"self_crossings", r.self_crossings},
                        {"nesting_violations", r.nesting_violations},
                        {"min_separation_ratio", finite_or_null(r.min_separation_ratio)},
                        {"collision_free", r.collision_free},
                        {"seconds",
                         {{"decimate", r.seconds_decimate},
                          {"fields", r.seconds_fields},
                          {"untangle", r.seconds_untangle},
                          {"finish", r.seconds_finish},
                          {"check", r.seconds_check},
                          {"total", r.seconds_total}}}};
    if (naive)
        j["naive"] = {{"crossings", naive->crossings},
                      {"self_crossings", naive->self_crossings},
                      {"nesting_violations", naive->nesting_violations},
                      {"min_separation_ratio", finite_or_null(naive->min_separation_ratio)}};
    return j;
}

double peak_memory_mib() {
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: KiB
}

double max_hausdorff(const SimplifyReport& r) {
    double h = 0.0;
    for (const LayerSimplifyReport& l : r.layers) h = std::max(h, l.hausdorff);
    return h;
}

std::string tangle_summary(const Scene& scene, const CheckReport& check) {
    std::string text = std::to_string(check.crossing_count) + " crossings between layers, " +
                       std::to_string(check.total_self_crossings()) + " self-crossings, " +
                       std::to_string(check.nesting_violation_count) + " nesting violations";
    if (!check.crossings.empty()) {
        const Crossing& c = check.crossings.front();
        text += "; first: layer '" + shown_text(scene.layer(c.layer_a).name) + "' segment " +
                std::to_string(c.segment_a) + " x layer '" +
                shown_text(scene.layer(c.layer_b).name) + "' segment " +
                std::to_string(c.segment_b) + " at (" + format_number(c.point.x) + ", " +
                format_number(c.point.y) + ")";
    } else if (!check.self_crossings.empty()) {
        const Crossing& c = check.self_crossings.front();
        const Layer& layer = scene.layer(c.layer_a);
        if (layer.closed && is_flat(layer.points)) {
            text += "; first: layer '" + shown_text(layer.name) +
                    "' is flat: all its points are collinear (a closed layer needs an area)";
            return text;
        }
        text += "; first: layer '" + shown_text(layer.name) + "' crosses itself (segments " +
                std::to_string(c.segment_a) + " and " + std::to_string(c.segment_b) + " at (" +
                format_number(c.point.x) + ", " + format_number(c.point.y) + "))";
    } else if (!check.nesting_violations.empty()) {
        const NestingViolation& v = check.nesting_violations.front();
        text += "; first: layer '" + shown_text(scene.layer(v.layer).name) + "' point " +
                std::to_string(v.vertex) + " on the wrong side of layer '" +
                shown_text(scene.layer(v.other).name) + "'";
    }
    return text;
}

// The untangling of a crossing input, from `start` (the input, perhaps with raised
// separations), as `strata untangle` does it without an original: by the sides inferred per
// region where the input has rolled regions, else by the global order
// (untangle_inferring_sides()). `after`:
// the check of the result (against the inferred sides when they were taken).
Scene untangle_input(const Scene& start, const UntangleParams& u, InputUntangling& info,
                     CheckReport& after, const ProgressFn& progress) {
    Scene scene = start;
    InputSides inferred;
    info.report = untangle_inferring_sides(scene, u, progress, &inferred);
    CheckParams check_params;
    if (info.report.inferred_sides) {
        check_params.outside_sides = untangling_outside_sides(start);
        check_params.input_sides = &inferred;  // untangling keeps the vertex indices
    }
    after = check_scene(scene, check_params);
    return scene;
}

std::optional<Scene> prepare_input(const Scene& input, const std::string& name, InputCrossings mode,
                                   const SimplifyParams& params,
                                   std::optional<InputUntangling>& untangled,
                                   const ProgressFn& progress) {
    // The input is its own reference for the sides of open layers (a rolled part lies on the
    // other side of the global order): only crossings, self-crossings and the nesting of
    // closed layers can make it tangled.
    // Recorded only when the global order finds nesting violations (recording costs about
    // as much as the check): an input without rolls passes on the first check.
    CheckReport before = check_scene(input);
    if (before.is_collision_free()) return input;
    if (before.nesting_violation_count > 0) {
        const InputSides own_sides = record_input_sides(input);
        CheckParams own;
        own.input_sides = &own_sides;
        before = check_scene(input, own);
        if (before.is_collision_free()) return input;
    }
    const std::string what = tangle_summary(input, before);
    if (mode == InputCrossings::Skip) return std::nullopt;
    if (mode == InputCrossings::Fail || before.total_self_crossings() > 0)
        throw InvalidInput(name + ": the input is not collision-free (" + what + ")" +
                           (mode == InputCrossings::Fail
                                ? "; not simplified (--input-crossings untangle mends it first)"
                                : "; a layer that crosses itself cannot be untangled"));
    UntangleParams u = params.untangling;
    // The global untangling's own pass structure (untangle()'s defaults), the driver's field
    // and shape settings.
    const UntangleParams defaults;
    u.gradient_steps = defaults.gradient_steps;
    u.max_rounds = defaults.max_rounds;
    u.max_passes = defaults.max_passes;
    u.give_up_when_stalled = false;
    InputUntangling info;
    info.crossings = before.crossing_count;
    info.nesting_violations = before.nesting_violation_count;
    // The gap rule first, on the input as read: the pairs that do not cross keep their share
    // of the gaps they have there through the untangling too (simplify() measures no gap
    // again for a pair with a required separation). Without it when the untangling then
    // fails (the gaps can ask for more room than a tangled region has).
    std::vector<Scene> starts;
    if (params.untangle && params.keep_input_gaps > 0.0) {
        Scene gapped = input;
        InputGapParams gap_params;
        gap_params.fraction =
            std::min(1.0, params.keep_input_gaps / (1.0 - params.untangling.separation_tolerance));
        if (keep_input_gaps(gapped, gap_params).raised > 0) starts.push_back(std::move(gapped));
    }
    starts.push_back(input);
    Scene scene;
    CheckReport after;
    for (std::size_t i = 0; i < starts.size(); ++i) {
        // The other readings of the input's regions (a last resort, up to 8 more tries), the
        // retry with more passes and the last resorts only on the last start: the gapped one
        // fails fast where the gaps ask for more room.
        const bool last = i + 1 == starts.size();
        u.other_readings = last ? defaults.other_readings : 0;
        u.retry_passes_factor = last ? defaults.retry_passes_factor : 1.0;
        u.loop_readings = last && defaults.loop_readings;
        u.untwist = last && defaults.untwist;
        u.retract_ends = last && defaults.retract_ends;
        u.restart = last && defaults.restart;
        scene = untangle_input(starts[i], u, info, after, progress);
        if (after.is_collision_free()) break;
    }
    if (!after.is_collision_free())
        throw InvalidInput(name + ": the input is not collision-free (" + what +
                           ") and untangling it left " + tangle_summary(scene, after) +
                           "; not simplified");
    untangled = info;
    return scene;
}

nlohmann::json untangling_json(const InputUntangling& u) {
    return {{"crossings", u.crossings},
            {"nesting_violations", u.nesting_violations},
            {"moved_vertices", u.report.moved_vertices},
            {"max_displacement", u.report.max_displacement},
            {"min_separation_ratio_after", finite_or_null(u.report.min_separation_ratio_after)},
            {"passes", u.report.passes},
            {"sides", u.report.inferred_sides ? "inferred" : "global"},
            {"seconds", u.report.seconds_fields + u.report.seconds_untangle +
                            u.report.seconds_finish + u.report.seconds_check}};
}

Outcome run_one(const Scene& input, const SimplifyOptions& opt, const ProgressFn& progress,
                Scene& result, Scene* naive_result) {
    Outcome out;
    if (opt.compare_naive || opt.naive) {
        SimplifyParams naive_params = opt.params;
        naive_params.untangle = false;
        Scene naive = input;
        out.naive = simplify(naive, naive_params);
        if (naive_result) *naive_result = naive;
        if (opt.naive) {
            result = naive;
            out.report = out.naive;
            return out;
        }
    }
    result = input;
    out.report = simplify(result, opt.params, progress);
    return out;
}

std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
    std::vector<std::string> files;
    for (const std::string& in : inputs) {
        if (fs::is_directory(in)) {
            std::vector<std::string> found;
            for (const auto& entry : fs::directory_iterator(in))
                if (entry.is_regular_file() &&
                    (entry.path().extension() == ".json" || entry.path().extension() == ".svg"))
                    found.push_back(entry.path().string());
            std::sort(found.begin(), found.end());
            files.insert(files.end(), found.begin(), found.end());
        } else {
            files.push_back(in);
        }
    }
    return files;
}

std::string batch_output(const std::string& folder, const std::string& input) {
    return (fs::path(folder) / (fs::path(input).stem().string() + ".json")).string();
}

Outcome simplify_slice(const std::string& input, const std::string& output,
                       const SimplifyOptions& opt) {
    Outcome o;
    o.input = input;
    o.output = output;
    const TimeLimit limit(opt.time_limit);
    try {
        ensure_not_an_input(o.output, {fs::path(input)});
        const Scene read = with_default_thickness(read_scene(input), opt.thickness);
        const ProgressFn progress = limit.around({});
        // Past the limit: TimeLimitReached, whose message is the slice's error below.
        const std::optional<Scene> prepared = limit.guard(input, [&] {
            return prepare_input(read, input, opt.input_crossings, opt.params, o.untangled,
                                 progress);
        });
        if (!prepared) {
            o.skipped = true;
            return o;
        }
        Scene result;
        Outcome r =
            limit.guard(input, [&] { return run_one(*prepared, opt, progress, result, nullptr); });
        write_scene(result, o.output);
        o.report = std::move(r.report);
        o.naive = std::move(r.naive);
    } catch (const std::bad_alloc&) {
        o.error = "out of memory: this slice needs more memory than the process may use";
    } catch (const std::exception& e) {
        o.error = e.what();
    }
    return o;
}

void BatchTotals::add(const Outcome& o) {
    ++slices;
    if (!o.error.empty()) {
        ++failed;
        return;
    }
    if (o.skipped) {
        ++skipped;
        return;
    }
    if (o.untangled) ++untangled;
    if (!o.report->collision_free) ++tangled;
}

std::string batch_header() {
    return format("%-40s %8s %8s %7s %7s %7s %8s %9s %8s\n", "slice", "before", "after", "input-x",
                  "naive-x", "strata-x", "refused", "hausdorff", "time-s");
}

std::string batch_row(const Outcome& o) {
    const std::string name = fs::path(o.input).filename().string();
    if (!o.error.empty()) return format("%-40s FAILED: %s\n", name.c_str(), o.error.c_str());
    if (o.skipped)
        return format("%-40s skipped: the input crosses (--input-crossings skip)\n", name.c_str());
    std::size_t before = 0, after = 0;
    for (const LayerSimplifyReport& l : o.report->layers) {
        before += l.before;
        after += l.after;
    }
    return format("%-40s %8zu %8zu %7s %7s %7zu %8zu %9.3g %8.3f\n", name.c_str(), before, after,
                  o.untangled ? std::to_string(o.untangled->crossings).c_str() : "0",
                  o.naive ? std::to_string(o.naive->crossings).c_str() : "-", o.report->crossings,
                  o.report->refused, max_hausdorff(*o.report), o.report->seconds_total);
}

std::string batch_footer(const BatchTotals& t, double peak_memory) {
    return format(
        "%zu slices: %zu simplified (%zu of them untangled first), %zu skipped, %zu failed "
        "(nothing written for them), %zu not collision-free; peak memory %.0f MiB\n",
        t.slices, t.slices - t.failed - t.skipped, t.untangled, t.skipped, t.failed, t.tangled,
        peak_memory);
}

nlohmann::json batch_entry(const Outcome& o) {
    if (!o.error.empty()) return {{"input", o.input}, {"error", o.error}};
    if (o.skipped) return {{"input", o.input}, {"skipped", true}};
    nlohmann::json j = report_json(*o.report, o.naive ? &*o.naive : nullptr);
    j["input"] = o.input;
    j["output"] = o.output;
    if (o.untangled) j["input_untangled"] = untangling_json(*o.untangled);
    return j;
}

}  // namespace strata::cli
