// strata_bench_untangle: global untangling (strata::untangle) of tangled scenes.
//
// Every family of scene_families.h, and the stack and the loops scaled by 1e-3 and by 1e3 and
// offset by 1e6, is tangled three ways: naive random decimation at 90% and 95% (simplify()
// with untangle = false) and per-layer Douglas-Peucker (Boost.Geometry's simplify, what
// shapely or GEOS give when each layer is simplified alone, with the tolerance bisected per
// layer to remove about 90% of its vertices). Each case is untangled with the default
// UntangleParams (the backend from --backend) as `strata untangle` does without an original
// (untangle_inferring_sides(): the sides inferred per region where the input has rolled
// regions and that comes out clean, else the global order) and scored by the exact check:
//   clean = no crossing or self-crossing, nesting kept, and the worst gap / required ratio
//           >= 0.9 x min(1, the untangled input's ratio).
// Nesting is judged against the sides of the un-decimated input (record_input_sides(),
// matched onto the tangled scene): a rolled part must stay rolled; elsewhere those are the
// global order's. A real slice has no such input: the global order judges it, or the sides
// inferred per region of it when the untangling kept those.
// Columns: crossings and nesting violations before/after, the ratio after and its bar, time,
// moved vertices, the largest Hausdorff distance of a layer to its un-decimated input.
// Usage: strata_bench_untangle [--family NAME] [--tangle naive90|naive95|dp]
//                              [--backend indexed|grid] [--points N] [--timing] [--write DIR]
//                              [--sides | --global-order] [--unrolled] [--gap G]
// --write DIR: every case's generated input (NAME.input.json), tangled input
// (NAME.tangled.json) and result (NAME.json, and
// NAME.svg with the tangled input drawn faintly under it), DIR existing.
// --timing: the two timing cases instead (12 loops x 150 and 6 x 300 stack, naive 90%).
// --slices DIR (default tests/data/crossing_slices, when run from the repository's root): the
// scenes of DIR (.json, .svg) whose input already crosses, untangled as they are (tangle
// "real"): slices of real garments (../shared/data/garments, bench/garments.sh) where the
// meshes interpenetrate. "--slices none" leaves them out.
// --sides: the un-decimated input is the reference, as `strata untangle --reference` has it:
// its sides of the open layers are given to untangle_inferring_sides()
// (UntangleParams::input_sides, outside_sides; first without the sides read at a fold's other
// sheet). Real slices are untangled as without it (their input is the tangle).
// --global-order: untangle() by the global order alone (`strata untangle --global-order`).
// --gap G: FamilyParams::gap (segment lengths, default 2) of every family's scene (not the
// stack's fixed wider and narrower cases), e.g. to sweep `strata simplify` over gaps.
// --unrolled: the rolled families' counterparts that keep the global order
// (FamilyParams::unrolled; named NAME_unrolled), e.g. to time `strata simplify` on the same
// scene without its roll.

#include "strata/core/error.h"
#include "strata/core/progress.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/scene_io.h"
#include "strata/io/svg_io.h"
#include "strata/simplify/scene_families.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/linestring.hpp>
#include <boost/geometry/geometries/point_xy.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

using namespace strata;

namespace {

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// Douglas-Peucker of one layer with Boost.Geometry, at the tolerance (bisected) that keeps
// about `keep` of its vertices (at least 2 open, 3 closed).
std::vector<Vec2> douglas_peucker(const Layer& layer, double keep) {
    namespace bg = boost::geometry;
    using Point = bg::model::d2::point_xy<double>;
    bg::model::linestring<Point> line;
    for (const Vec2& p : layer.points) line.emplace_back(p.x, p.y);
    if (layer.closed) line.emplace_back(layer.points.front().x, layer.points.front().y);
    const std::size_t target = std::max<std::size_t>(
        layer.closed ? 4 : 2, static_cast<std::size_t>(keep * static_cast<double>(line.size())));
    Box2 box = layer.bounds();
    double lo = 0.0, hi = std::hypot(box.size().x, box.size().y);
    bg::model::linestring<Point> out;
    for (int i = 0; i < 50; ++i) {
        const double mid = 0.5 * (lo + hi);
        out.clear();
        bg::simplify(line, out, mid);
        if (out.size() > target)
            lo = mid;
        else
            hi = mid;
    }
    out.clear();
    bg::simplify(line, out, hi);
    std::vector<Vec2> points;
    for (const Point& p : out) points.emplace_back(p.x(), p.y());
    if (layer.closed && points.size() > 1 && points.front() == points.back()) points.pop_back();
    if (points.size() < (layer.closed ? 3u : 2u)) return layer.points;
    return points;
}

Scene tangle(const Scene& input, const std::string& how) {
    if (how == "dp") {
        std::vector<Layer> layers = input.layers();
        for (Layer& layer : layers) layer.points = douglas_peucker(layer, 0.1);
        return Scene(std::move(layers), input.units());
    }
    SimplifyParams naive;
    naive.decimator = "random";
    naive.remove = how == "naive95" ? 0.95 : 0.9;
    naive.untangle = false;
    Scene out = input;
    simplify(out, naive);
    return out;
}

struct Case {
    std::string name;
    Scene input;
};

bool unrolled = false;    // --unrolled
double family_gap = 2.0;  // --gap (FamilyParams::gap, the families of all_scene_families())

std::vector<Case> cases(std::size_t points, const std::string& only) {
    std::vector<Case> out;
    for (SceneFamily family : all_scene_families()) {
        FamilyParams p;
        p.points = points;
        p.gap = family_gap;
        p.layers = family == SceneFamily::Folded ? 4 : 6;
        p.unrolled = unrolled && is_rolled(family);
        const std::string name = family_name(family) + (p.unrolled ? "_unrolled" : "");
        if (only.empty() || only == family_name(family))
            out.push_back({name, make_scene(family, p)});
        if (family != SceneFamily::Stack && family != SceneFamily::Loops) continue;
        if (!only.empty() && only != name && only != "scaled") continue;
        FamilyParams small = p, large = p, far = p;
        small.scale = 1e-3;
        large.scale = 1e3;
        far.offset = Vec2(1e6, 1e6);
        out.push_back({name + " x1e-3", make_scene(family, small)});
        out.push_back({name + " x1e3", make_scene(family, large)});
        out.push_back({name + " +1e6", make_scene(family, far)});
    }
    // Wider and narrower gaps (0.5 and 4 segment lengths) and 12 layers for the stack.
    for (const auto& [layers, gap] : {std::pair<std::size_t, double>{5, 0.5}, {12, 4.0}}) {
        if (!only.empty() && only != "stack") continue;
        FamilyParams p;
        p.points = points;
        p.layers = layers;
        p.gap = gap;
        out.push_back(
            {"stack " + std::to_string(layers) + "x gap " + std::to_string(gap).substr(0, 3),
             make_scene(SceneFamily::Stack, p)});
    }
    return out;
}

struct Row {
    bool clean = false;
    bool capped = false;
};

std::string write_dir;      // --write
bool keep_sides = false;    // --sides
bool global_order = false;  // --global-order

Row run(const std::string& name, const std::string& how, const Scene& input,
        const UntangleParams& params, double cap_seconds) {
    const CheckReport original = check_scene(input);
    const Scene tangled = how == "real" ? input : tangle(input, how);
    // The input's sides carried onto the tangled scene: scored, and with --sides kept.
    UntangleParams p = params;
    CheckParams scoring;
    InputSides sides;
    if (how != "real") {
        scoring.outside_sides = outside_sides(input);
        sides = InputSides::matched(record_input_sides(input), input, tangled);
        scoring.input_sides = &sides;
        if (keep_sides) {
            p.outside_sides = scoring.outside_sides;
            p.input_sides = &sides;
        }
    }
    const CheckReport before = check_scene(tangled, scoring);
    Scene scene = tangled;
    const double start = now();
    Row row;
    UntangleReport report;
    InputSides inferred;  // the sides it kept, when inferred
    try {
        const ProgressFn capped = [&](std::string_view, double) {
            return now() - start < cap_seconds;
        };
        report = global_order ? untangle(scene, p, capped)
                              : untangle_inferring_sides(scene, p, capped, &inferred);
    } catch (const Cancelled&) {
        row.capped = true;
        scene = tangled;
    }
    const double seconds = now() - start;
    if (how == "real" && report.inferred_sides) {  // judged as untangle judged it
        scoring.outside_sides = untangling_outside_sides(tangled);
        scoring.input_sides = &inferred;
    }
    const CheckReport after = check_scene(scene, scoring);
    const double bar = 0.9 * std::min(1.0, original.min_separation_ratio);
    row.clean = !row.capped && after.is_collision_free() && after.min_separation_ratio >= bar;
    double hausdorff = 0.0;
    const double diagonal = std::hypot(input.bounds().size().x, input.bounds().size().y);
    for (std::size_t l = 0; l < scene.size(); ++l)
        hausdorff = std::max(
            hausdorff,
            strata::hausdorff(scene.layer(l), input.layer(l), 1e-4 * diagonal).symmetric());
    if (!write_dir.empty()) {
        std::string file = name + "-" + how;
        std::replace(file.begin(), file.end(), ' ', '_');
        const std::string base = write_dir + "/" + file;
        if (how != "real") write_scene(input, base + ".input.json");
        write_scene(tangled, base + ".tangled.json");
        write_scene(scene, base + ".json");
        SvgWriteParams svg;
        svg.underlay = &tangled;
        write_scene_svg(scene, base + ".svg", svg);
    }
    std::printf(
        "%-22s %-8s %5zux%-5zu %5zu/%-5zu %5zu/%-5zu %7.3f %6.3f %8.3f %8zu %10.3g %5s%s%s\n",
        name.c_str(), how.c_str(), tangled.size(), tangled.vertex_count() / tangled.size(),
        before.crossing_count, after.crossing_count, before.nesting_violation_count,
        after.nesting_violation_count, after.min_separation_ratio, bar, seconds,
        report.moved_vertices, hausdorff, row.clean ? "yes" : "NO", row.capped ? " (time cap)" : "",
        report.inferred_sides ? " (inferred sides)" : "");
    std::fflush(stdout);
    return row;
}

void timing(const UntangleParams& params) {
    // The two timing cases (targets: 2 s and 0.5 s on one core: taskset -c 0).
    FamilyParams loops;
    loops.layers = 12;
    loops.points = 150;
    FamilyParams stack;
    stack.layers = 6;
    stack.points = 300;
    for (const auto& [name, scene] :
         {std::pair<std::string, Scene>{"loops 12x150", make_scene(SceneFamily::Loops, loops)},
          {"stack 6x300", make_scene(SceneFamily::Stack, stack)}})
        run(name, "naive90", scene, params, 120.0);
}

}  // namespace

int main(int argc, char** argv) {
    std::string family, how, backend = "indexed", slices = "tests/data/crossing_slices";
    std::size_t points = 300;
    bool timed = false;
    for (int i = 1; i < argc; ++i) {
        const std::string key = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "strata_bench_untangle: %s needs a value\n", key.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        // A number > 0 (whole for --points), or exit 2 naming the option and the value.
        auto positive = [&](bool whole) {
            const std::string text = value();
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0.0) ||
                (whole && v != std::floor(v))) {
                std::fprintf(stderr,
                             "strata_bench_untangle: %s must be a%s number > 0 (got '%s')\n",
                             key.c_str(), whole ? " whole" : "", text.c_str());
                std::exit(2);
            }
            return v;
        };
        if (key == "--family")
            family = value();
        else if (key == "--tangle")
            how = value();
        else if (key == "--backend")
            backend = value();
        else if (key == "--points")
            points = static_cast<std::size_t>(positive(true));
        else if (key == "--timing")
            timed = true;
        else if (key == "--write")
            write_dir = value();
        else if (key == "--slices")
            slices = value();
        else if (key == "--sides")
            keep_sides = true;
        else if (key == "--global-order")
            global_order = true;
        else if (key == "--unrolled")
            unrolled = true;
        else if (key == "--gap")
            family_gap = positive(false);
        else {
            std::fprintf(stderr,
                         "usage: strata_bench_untangle [--family NAME] [--tangle "
                         "naive90|naive95|dp|real] [--backend indexed|grid] [--points N] "
                         "[--timing] [--write DIR] [--slices DIR|none] [--sides | --global-order] "
                         "[--unrolled] [--gap G]\n");
            return 2;
        }
    }
    if (backend != "indexed" && backend != "grid") {
        std::fprintf(stderr, "strata_bench_untangle: --backend must be indexed or grid (got %s)\n",
                     backend.c_str());
        return 2;
    }
    if (keep_sides && global_order) {
        std::fprintf(stderr,
                     "strata_bench_untangle: --sides and --global-order exclude each other\n");
        return 2;
    }
    if (!write_dir.empty()) std::filesystem::create_directories(write_dir);
    UntangleParams params;
    params.field.backend = backend == "grid" ? FieldBackend::Grid : FieldBackend::ExactIndexed;
    std::printf("%-22s %-8s %11s %11s %11s %7s %6s %8s %8s %10s %5s\n", "scene", "tangle",
                "layers x n", "crossings", "nesting", "gap/req", "bar", "seconds", "moved",
                "Hausdorff", "clean");
    if (timed) {
        timing(params);
        return 0;
    }
    int clean = 0, total = 0;
    double seconds = 0.0;
    const double start = now();
    for (const Case& c : cases(points, family))
        for (const char* t : {"naive90", "naive95", "dp"}) {
            if (!how.empty() && how != t) continue;
            ++total;
            clean += run(c.name, t, c.input, params, 60.0).clean;
        }
    if (slices != "none" && family.empty() && (how.empty() || how == "real")) {
        if (!std::filesystem::is_directory(slices)) {
            std::fprintf(stderr, "strata_bench_untangle: no folder '%s' (--slices): skipped\n",
                         slices.c_str());
        } else {
            std::vector<std::filesystem::path> files;
            for (const auto& entry : std::filesystem::directory_iterator(slices))
                if (entry.path().extension() == ".json" || entry.path().extension() == ".svg")
                    files.push_back(entry.path());
            std::sort(files.begin(), files.end());
            for (const std::filesystem::path& file : files) {
                const Scene input = read_scene(file);
                if (check_scene(input).is_collision_free()) continue;  // nothing to untangle
                ++total;
                clean += run(file.stem().string(), "real", input, params, 60.0).clean;
            }
        }
    }
    seconds = now() - start;
    std::printf("%d of %d clean (%.1f s in all)\n", clean, total, seconds);
    return 0;
}
