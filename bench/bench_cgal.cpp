// strata against CGAL's Polyline_simplification_2, the peer a user would pick instead, on the
// same scenes and the same vertex budget, both outputs scored by strata's exact checks.
//
//   strata_bench_cgal [--max POINTS] [--layers L,...] [--points N,...] [--remove R,...]
//                     [--slices DIR]
//
// Scenes: folded_stack() with --layers (5, 8) layers and --points (2000, 10000) points per
// layer (up to --max, default 10000, unless --points is given), then every *.json slice in
// --slices (default ../shared/data/slices, from the project root; skipped when the folder
// does not exist, e.g. "none"). Removal --remove (0.90, 0.95, 0.98).
//
// strata: simplify(scene, params) with params.remove = rm, other parameters at their defaults;
// its time includes its own final check (the "chk s" column).
// CGAL: every layer is a polyline constraint (closed layers closed) of ONE
// Constrained_triangulation_plus_2 over a Constrained_Delaunay_triangulation_2 (EPICK,
// Exact_predicates_tag), simplified with Squared_distance_cost and Stop_below_count_threshold
// at the total of strata's per-layer targets; the time covers insertion and simplification.
//
// One "input" row per scene scores the input itself (rm 0). Columns: seconds; crossings
// between layers (CheckReport::crossing_count); self-crossings; nesting violations; worst
// gap / required separation (inf when nothing is required) and the smallest gap of a near
// pair, scene units; min..max vertices per layer after, and the per-layer target range; total
// vertices after / total budget; the largest per-layer symmetric Hausdorff distance to the
// input, scene units; for CGAL, the layers that collapsed (fewer than 10% of their target
// vertices, or a Hausdorff distance over 5 x strata's on that layer). "pts" is points per
// layer for the generated scenes, the total for slices. One run per configuration with plain
// std::chrono timers: the machine is small and noisy, read ratios rather than absolute times.
#include "strata/geometry/checks.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_plus_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polyline_simplification_2/simplify.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

using namespace strata;

namespace {

namespace ps = CGAL::Polyline_simplification_2;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Tds =
    CGAL::Triangulation_data_structure_2<ps::Vertex_base_2<Kernel>,
                                         CGAL::Constrained_triangulation_face_base_2<Kernel>>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Ct = CGAL::Constrained_triangulation_plus_2<Cdt>;

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// strata's per-layer target (simplify.cpp): n - floor(remove n), at least 2 (open) or 3.
std::size_t layer_target(const Layer& layer, double remove) {
    const std::size_t n = layer.points.size();
    const std::size_t target =
        n - static_cast<std::size_t>(std::floor(remove * static_cast<double>(n)));
    return std::max(std::min(target, n), layer.closed ? std::size_t(3) : std::size_t(2));
}

struct RunResult {
    double seconds = -1.0, check_seconds = -1.0;  // < 0: not timed / not reported
    Scene scene;
    std::string error;  // non-empty: the run failed, nothing else is valid
};

RunResult run_strata(const Scene& input, double remove) {
    RunResult result;
    result.scene = input;
    SimplifyParams params;
    params.remove = remove;
    try {
        const double start = now();
        const SimplifyReport report = simplify(result.scene, params);
        result.seconds = now() - start;
        result.check_seconds = report.seconds_check;
    } catch (const std::exception& e) {
        result.error = e.what();
    }
    return result;
}

RunResult run_cgal(const Scene& input, double remove) {
    RunResult result;
    std::size_t budget = 0;
    for (const Layer& layer : input.layers()) budget += layer_target(layer, remove);
    std::vector<std::vector<Vec2>> simplified(input.size());
    try {
        const double start = now();
        Ct ct;
        std::vector<Ct::Constraint_id> ids;
        for (const Layer& layer : input.layers()) {
            std::vector<Kernel::Point_2> points;
            points.reserve(layer.points.size());
            for (const Vec2& p : layer.points) points.emplace_back(p.x, p.y);
            ids.push_back(ct.insert_constraint(points.begin(), points.end(), layer.closed));
        }
        ps::simplify(ct, ps::Squared_distance_cost(), ps::Stop_below_count_threshold(budget));
        result.seconds = now() - start;
        for (std::size_t l = 0; l < input.size(); ++l) {
            std::vector<Vec2>& out = simplified[l];
            for (auto it = ct.vertices_in_constraint_begin(ids[l]);
                 it != ct.vertices_in_constraint_end(ids[l]); ++it)
                out.emplace_back((*it)->point().x(), (*it)->point().y());
            // A closed constraint repeats its first vertex at the end.
            if (input.layer(l).closed && out.size() > 1 && out.front() == out.back())
                out.pop_back();
        }
        std::vector<Layer> layers = input.layers();
        for (std::size_t l = 0; l < layers.size(); ++l) layers[l].points = simplified[l];
        result.scene = Scene(layers, input.units());
    } catch (const std::exception& e) {
        result.error = e.what();
    }
    return result;
}

struct Score {
    std::size_t crossings = 0, self_crossings = 0, nesting = 0;
    std::size_t min_verts = 0, max_verts = 0, total_verts = 0;
    double gap_ratio = 0.0, min_gap = std::numeric_limits<double>::infinity();
    std::vector<double> hausdorff;  // per layer, scene units
};

Score score(const Scene& input, const Scene& output) {
    Score s;
    const CheckReport check = check_scene(output);
    s.crossings = check.crossing_count;
    s.self_crossings = check.total_self_crossings();
    s.nesting = check.nesting_violation_count;
    s.gap_ratio = check.min_separation_ratio;
    for (const PairSeparation& pair : check.pairs) s.min_gap = std::min(s.min_gap, pair.gap);
    const Vec2 size = input.bounds().size();
    const double tolerance = 1e-6 * std::max(std::hypot(size.x, size.y), 1e-300);
    s.min_verts = std::numeric_limits<std::size_t>::max();
    for (std::size_t l = 0; l < output.size(); ++l) {
        const std::size_t n = output.layer(l).points.size();
        s.min_verts = std::min(s.min_verts, n);
        s.max_verts = std::max(s.max_verts, n);
        s.total_verts += n;
        s.hausdorff.push_back(hausdorff(output.layer(l), input.layer(l), tolerance).symmetric());
    }
    return s;
}

void print_header() {
    std::printf("%-24s %6s %7s %5s %-6s %8s %7s %5s %4s %7s %8s %9s %12s %10s %13s %10s %9s\n",
                "scene", "layers", "pts", "rm", "tool", "seconds", "chk s", "cross", "self",
                "nesting", "gap/req", "min gap", "verts/layer", "target", "total/budget",
                "max Hausd", "collapsed");
}

void print_row(const std::string& name, const Scene& input, std::size_t points, double remove,
               const char* tool, const RunResult& run, const Score* s, std::size_t target_min,
               std::size_t target_max, std::size_t budget, const char* collapsed) {
    std::printf("%-24s %6zu %7zu %5.2f %-6s ", name.c_str(), input.size(), points, remove, tool);
    if (!run.error.empty()) {
        std::printf("failed: %s\n", run.error.c_str());
        return;
    }
    const std::string verts = std::to_string(s->min_verts) + ".." + std::to_string(s->max_verts);
    const std::string target = std::to_string(target_min) + ".." + std::to_string(target_max);
    const double max_h = *std::max_element(s->hausdorff.begin(), s->hausdorff.end());
    char seconds[16] = "-", check[16] = "-";
    if (run.seconds >= 0.0) std::snprintf(seconds, sizeof seconds, "%.3f", run.seconds);
    if (run.check_seconds >= 0.0) std::snprintf(check, sizeof check, "%.3f", run.check_seconds);
    const std::string total = std::to_string(s->total_verts) + "/" + std::to_string(budget);
    std::printf("%8s %7s %5zu %4zu %7zu %8.3g %9.3g %12s %10s %13s %10.3g %9s\n", seconds, check,
                s->crossings, s->self_crossings, s->nesting, s->gap_ratio, s->min_gap,
                verts.c_str(), target.c_str(), total.c_str(), max_h, collapsed);
}

std::vector<double> removals{0.90, 0.95, 0.98};  // --remove

void compare(const std::string& name, const Scene& input, std::size_t points) {
    // The input's own score first: a flaw already there is not the tools' doing.
    RunResult original;
    original.scene = input;
    const Score input_score = score(input, input);
    print_row(name, input, points, 0.0, "input", original, &input_score, input_score.min_verts,
              input_score.max_verts, input_score.total_verts, "-");
    for (const double remove : removals) {
        std::size_t target_min = std::numeric_limits<std::size_t>::max(), target_max = 0,
                    budget = 0;
        std::vector<std::size_t> targets;
        for (const Layer& layer : input.layers()) {
            targets.push_back(layer_target(layer, remove));
            target_min = std::min(target_min, targets.back());
            target_max = std::max(target_max, targets.back());
            budget += targets.back();
        }
        const RunResult strata_run = run_strata(input, remove);
        Score strata_score;
        if (strata_run.error.empty()) strata_score = score(input, strata_run.scene);
        print_row(name, input, points, remove, "strata", strata_run, &strata_score, target_min,
                  target_max, budget, "-");
        std::fflush(stdout);

        const RunResult cgal_run = run_cgal(input, remove);
        Score cgal_score;
        std::string collapsed = "-";
        if (cgal_run.error.empty()) {
            cgal_score = score(input, cgal_run.scene);
            std::size_t count = 0;
            for (std::size_t l = 0; l < input.size(); ++l) {
                const bool starved = 10 * cgal_run.scene.layer(l).points.size() < targets[l];
                const bool far = strata_run.error.empty() &&
                                 cgal_score.hausdorff[l] > 5.0 * strata_score.hausdorff[l];
                if (starved || far) ++count;
            }
            collapsed = std::to_string(count);
        }
        print_row(name, input, points, remove, "cgal", cgal_run, &cgal_score, target_min,
                  target_max, budget, collapsed.c_str());
        std::fflush(stdout);
    }
}

}  // namespace

// "a,b,c" as numbers; empty on a bad item.
std::vector<double> number_list(const std::string& text) {
    std::vector<double> out;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma - start);
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !(v > 0.0)) return {};
        out.push_back(v);
        if (comma == std::string::npos) return out;
        start = comma + 1;
    }
}

int main(int argc, char** argv) {
    std::size_t max_points = 10000;
    std::vector<double> layer_counts{5, 8}, point_counts{2000, 10000};
    std::filesystem::path slices = "../shared/data/slices";
    for (int i = 1; i < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = i + 1 < argc ? argv[i + 1] : "";
        bool ok = i + 1 < argc;
        if (ok && key == "--max") {
            max_points = std::strtoul(argv[i + 1], nullptr, 10);
        } else if (ok && key == "--slices") {
            slices = value;
        } else if (ok && key == "--layers") {
            layer_counts = number_list(value);
            ok = !layer_counts.empty();
        } else if (ok && key == "--points") {
            point_counts = number_list(value);
            ok = !point_counts.empty();
            max_points = std::numeric_limits<std::size_t>::max();
        } else if (ok && key == "--remove") {
            removals = number_list(value);
            ok = !removals.empty();
            for (double r : removals) ok = ok && r < 1.0;
        } else {
            ok = false;
        }
        if (!ok) {
            std::fprintf(
                stderr,
                "usage: strata_bench_cgal [--max POINTS (10000)] [--layers L[,L...] (5,8)] "
                "[--points N[,N...] (2000,10000; no --max cap)] [--remove R[,R...] "
                "(0.9,0.95,0.98)] [--slices DIR|none (../shared/data/slices)]\n");
            return 2;
        }
    }
    print_header();
    for (const double layers : layer_counts)
        for (const double points : point_counts) {
            if (points > static_cast<double>(max_points)) continue;
            const Scene input =
                folded_stack(static_cast<std::size_t>(layers), static_cast<std::size_t>(points),
                             10.0 * points / 600.0);
            compare("folded_stack", input, static_cast<std::size_t>(points));
        }
    std::error_code error;
    if (!std::filesystem::is_directory(slices, error)) return 0;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(slices, error))
        if (entry.path().extension() == ".json") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const std::filesystem::path& file : files) {
        try {
            const Scene input = read_scene(file);
            compare(file.stem().string(), input, input.vertex_count());
        } catch (const std::exception& e) {
            std::printf("%-24s failed to read: %s\n", file.stem().string().c_str(), e.what());
        }
    }
    return 0;
}
