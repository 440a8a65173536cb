// strata check: exact collision checks of a scene, as a table or JSON.
#include "check_marks.h"
#include "cli_util.h"
#include "commands.h"
#include "reference.h"

#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/io/scene_io.h"
#include "strata/io/svg_io.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace strata::cli {

namespace {

struct CheckOptions {
    std::string input;
    std::string reference;
    std::string svg;
    bool json = false;
    bool strict = false;
    CheckParams params;
    double hausdorff_tolerance = 1e-9;
};

// Per-layer Hausdorff distance to the layer of the same name in `reference` (nullopt if absent).
std::vector<std::optional<HausdorffDistance>> hausdorff_to(const Scene& scene,
                                                           const Scene& reference,
                                                           double tolerance) {
    std::vector<std::optional<HausdorffDistance>> out(scene.size());
    for (std::size_t i = 0; i < scene.size(); ++i)
        if (auto j = reference.find(scene.layer(i).name))
            out[i] = hausdorff(scene.layer(i), reference.layer(*j), tolerance);
    return out;
}

nlohmann::json to_json(const Scene& scene, const CheckReport& r,
                       const std::vector<std::optional<HausdorffDistance>>& h, bool ok) {
    using nlohmann::json;
    auto point = [](const Vec2& p) { return json::array({p.x, p.y}); };
    auto finite_or_null = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    json layers = json::array();
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const Layer& l = scene.layer(i);
        json entry = {{"name", l.name},
                      {"closed", l.closed},
                      {"vertices", l.points.size()},
                      {"thickness", l.thickness},
                      {"self_crossings", r.self_crossing_count[i]}};
        if (!h.empty() && h[i])
            entry["hausdorff"] = {{"to_reference", h[i]->a_to_b},
                                  {"from_reference", h[i]->b_to_a},
                                  {"symmetric", h[i]->symmetric()}};
        layers.push_back(entry);
    }
    json crossings = json::array();
    for (const Crossing& c : r.crossings)
        crossings.push_back({{"layer_a", scene.layer(c.layer_a).name},
                             {"segment_a", c.segment_a},
                             {"layer_b", scene.layer(c.layer_b).name},
                             {"segment_b", c.segment_b},
                             {"point", point(c.point)},
                             {"touch", c.is_touch}});
    json self = json::array();
    for (const Crossing& c : r.self_crossings)
        self.push_back({{"layer", scene.layer(c.layer_a).name},
                        {"segment_a", c.segment_a},
                        {"segment_b", c.segment_b},
                        {"point", point(c.point)},
                        {"touch", c.is_touch}});
    json pairs = json::array();
    for (const PairSeparation& p : r.pairs)
        pairs.push_back({{"layer_a", scene.layer(p.layer_a).name},
                         {"layer_b", scene.layer(p.layer_b).name},
                         {"relation", relation_name(p.relation)},
                         {"gap", p.gap},
                         {"required", p.required},
                         {"ratio", finite_or_null(p.ratio())},
                         {"at_a", point(p.at_a)},
                         {"at_b", point(p.at_b)}});
    json sep = json::array();
    for (const SeparationViolation& v : r.separation_violations)
        sep.push_back({{"layer", scene.layer(v.layer).name},
                       {"vertex", v.vertex},
                       {"other", scene.layer(v.other).name},
                       {"distance", v.distance},
                       {"required", v.required}});
    json nest = json::array();
    for (const NestingViolation& v : r.nesting_violations)
        nest.push_back({{"layer", scene.layer(v.layer).name},
                        {"vertex", v.vertex},
                        {"other", scene.layer(v.other).name},
                        {"expected", relation_name(v.expected)}});
    return {{"collision_free", r.is_collision_free()},
            {"separations_hold", r.separations_hold()},
            {"ok", ok},
            {"layers", layers},
            {"crossing_count", r.crossing_count},
            {"touch_count", r.touch_count},
            {"crossings", crossings},
            {"self_crossing_count", r.total_self_crossings()},
            {"self_crossings", self},
            {"near_distance", r.near_distance},
            {"pairs", pairs},
            {"min_separation_ratio", finite_or_null(r.min_separation_ratio)},
            {"separation_violation_count", r.separation_violation_count},
            {"separation_violations", sep},
            {"nesting_violation_count", r.nesting_violation_count},
            {"nesting_violations", nest}};
}

void print_table(const std::string& input, const Scene& scene, const CheckReport& r,
                 const std::vector<std::optional<HausdorffDistance>>& h, bool ok) {
    // Names and units come from the file: shown with their control bytes escaped.
    std::printf("%s: %zu layers, %zu vertices%s%s\n", input.c_str(), scene.size(),
                scene.vertex_count(), scene.units().empty() ? "" : ", units ",
                shown_name(scene.units()).c_str());
    std::printf("  %-20s %-6s %8s %10s %6s%s\n", "layer", "closed", "vertices", "thickness",
                "self-x", h.empty() ? "" : "  hausdorff(ref)");
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const Layer& l = scene.layer(i);
        std::string hd =
            h.empty() ? ""
                      : (h[i] ? "  " + short_number(h[i]->symmetric()) : "  (not in reference)");
        std::printf("  %-20s %-6s %8zu %10s %6zu%s\n", shown_name(l.name).c_str(),
                    l.closed ? "yes" : "no", l.points.size(), short_number(l.thickness).c_str(),
                    r.self_crossing_count[i], hd.c_str());
    }
    std::printf("crossings between layers: %zu (%zu proper, %zu touching)\n", r.crossing_count,
                r.crossing_count - r.touch_count, r.touch_count);
    for (std::size_t k = 0; k < r.crossings.size() && k < 10; ++k) {
        const Crossing& c = r.crossings[k];
        std::printf("  %s at (%s, %s): '%s' segment %zu x '%s' segment %zu\n",
                    c.is_touch ? "touch" : "cross", short_number(c.point.x).c_str(),
                    short_number(c.point.y).c_str(),
                    shown_name(scene.layer(c.layer_a).name).c_str(), c.segment_a,
                    shown_name(scene.layer(c.layer_b).name).c_str(), c.segment_b);
    }
    if (r.crossing_count > 10) std::printf("  ... (--json lists up to %zu)\n", r.crossings.size());
    std::printf("self-crossings: %zu\n", r.total_self_crossings());
    std::printf("near pairs (closer than %s): %zu\n", short_number(r.near_distance).c_str(),
                r.pairs.size());
    if (!r.pairs.empty())
        std::printf("  %-20s %-20s %-12s %12s %12s %8s\n", "layer a", "layer b", "relation", "gap",
                    "required", "ratio");
    for (const PairSeparation& p : r.pairs)
        std::printf("  %-20s %-20s %-12s %12s %12s %8s\n",
                    shown_name(scene.layer(p.layer_a).name).c_str(),
                    shown_name(scene.layer(p.layer_b).name).c_str(), relation_name(p.relation),
                    short_number(p.gap).c_str(), short_number(p.required).c_str(),
                    short_number(p.ratio()).c_str());
    std::printf("min separation ratio: %s; vertices closer than required: %zu\n",
                short_number(r.min_separation_ratio).c_str(), r.separation_violation_count);
    std::printf(
        "nesting: %s\n",
        r.nesting_violation_count == 0
            ? "holds"
            : (std::to_string(r.nesting_violation_count) + " vertices on the wrong side").c_str());
    std::printf("verdict: %s\n", ok ? "OK"
                                    : (r.is_collision_free() ? "separation too small (--strict)"
                                                             : "NOT collision-free"));
}

}  // namespace

Run add_check_command(CLI::App& app) {
    auto opt = std::make_shared<CheckOptions>();
    CLI::App* cmd = app.add_subcommand("check",
                                       "Exact checks: crossings, self-crossings, separations, "
                                       "nesting (exit 0 ok, 1 not, 2 bad input)");
    cmd->add_option("input", opt->input, "Scene file (.json or .svg)")->required();
    cmd->add_option("--reference", opt->reference,
                    "Original scene: adds per-layer Hausdorff distances, and gives each open "
                    "layer the outside side it has there (as simplify's own check does)");
    cmd->add_flag("--json", opt->json, "Print the report as JSON");
    cmd->add_option("--svg", opt->svg,
                    "Picture of the scene (with its vertices, up to 10000) and the problems "
                    "found marked in red (crossings, vertices on the wrong side or too close, "
                    "the closest points of pairs below their gap; hover for details)");
    cmd->add_flag("--strict", opt->strict, "Separation shortfalls make the exit code 1");
    cmd->add_option("--near", opt->params.near_distance,
                    "Pairs closer than this get a separation entry (scene units; 0 = auto)")
        ->capture_default_str();
    cmd->add_option("--tolerance", opt->params.separation_tolerance,
                    "Relative tolerance on separations: gap >= required * (1 - tol)")
        ->capture_default_str();
    cmd->add_option("--hausdorff-tolerance", opt->hausdorff_tolerance,
                    "Accuracy of the Hausdorff distances, relative to the scene diagonal")
        ->capture_default_str();
    return [opt]() {
        validate(opt->params);
        if (!opt->svg.empty()) check_outputs({opt->svg}, {opt->input, opt->reference});
        const Scene scene = read_scene(opt->input);
        for (const std::string& note : scene.diagnostics().notes)
            std::cerr << "strata: note: " << opt->input << ": " << note << '\n';
        CheckParams params = opt->params;
        // The reference's own sides of its open layers (a rolled part): a nesting violation is
        // a vertex that left the side its reference has. Its outside sides: an open layer
        // simplified to a few vertices gets its side from its original.
        std::optional<Reference> reference;
        if (!opt->reference.empty()) {
            reference = read_reference(opt->reference, scene, params.near_distance, false);
            params.outside_sides = reference->outside_sides;
            params.input_sides = &reference->sides;
        }
        const std::size_t rolled = reference ? reference->rolled : 0;
        const CheckReport report = check_scene(scene, params);
        std::vector<std::optional<HausdorffDistance>> h;
        if (reference) {
            Box2 box = scene.bounds();
            box.extend(reference->scene.bounds());
            const double diagonal = std::hypot(box.size().x, box.size().y);
            h = hausdorff_to(scene, reference->scene,
                             opt->hausdorff_tolerance * std::max(diagonal, 1e-300));
        }
        const bool ok = report.is_collision_free() && (!opt->strict || report.separations_hold());
        if (!opt->svg.empty()) {
            SvgWriteParams svg = check_marks(scene, report, params.separation_tolerance);
            // Vertex dots where they stay readable (and the file small).
            svg.draw_vertices = scene.vertex_count() <= 10000;
            write_scene_svg(scene, opt->svg, svg);
        }
        if (opt->json) {
            nlohmann::json out = to_json(scene, report, h, ok);
            // Rolled or folded-over vertices of the reference (their own side kept), if any.
            if (rolled > 0) out["reference_rolled_vertices"] = rolled;
            std::cout << json_report_text(out) << '\n';
        } else {
            print_table(opt->input, scene, report, h, ok);
            if (rolled > 0)
                std::printf(
                    "reference: %zu vertices lie on the other side of an open layer than "
                    "the global order (rolled or folded over); nesting is checked "
                    "against the reference's sides\n",
                    rolled);
        }
        return ok ? 0 : 1;
    };
}

}  // namespace strata::cli
