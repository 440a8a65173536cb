// Benchmarks of the collision-free simplification (issue 5), ratios measured in one run.
//
//   strata_bench_simplify paper [--repeat N] [--only global|local] [--stretch long|short]
//                               [--margin M]... [--backend indexed|grid]
//                                           paper section 5.2: local vs global untangling
//                                           (best of N, default 3; the local box grown by
//                                           each M, default 0.3 and 0.1; fields of the
//                                           backend, default indexed, in both runs)
//   strata_bench_simplify backends [--repeat N]
//                                           where grid fields pay in a global untangling:
//                                           paper 5.2's stacks resampled and thinner,
//                                           indexed against grid (best of N, default 3)
//   strata_bench_simplify scenes [options]  generated 5/8-layer scenes, per backend and
//                                           schedule (options: see the usage line)
//
// Plain timers (std::chrono::steady_clock), one run per configuration: the machine is small
// and noisy, so read ratios rather than absolute times.
#include "strata/geometry/checks.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

using namespace strata;

namespace {

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// `count` closed wavy loops offset outward by `spacing` (innermost first, one implicit stack:
// each loop inside the next), `points` vertices each, thickness 0.01: the closed counterpart
// of folded_stack, with the same segment length (about 10/600) and waves 1.5 long whatever
// the size, so that a removal's neighbourhood is the same at every size.
Scene wavy_loops(std::size_t count, std::size_t points, double spacing) {
    constexpr double kPi = 3.14159265358979323846;
    const double radius = static_cast<double>(points) * (10.0 / 600.0) / (2.0 * kPi);
    const double waves = std::max(5.0, std::round(2.0 * kPi * radius / 1.5));
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < count; ++k) {
        Layer layer;
        layer.name = "loop" + std::to_string(k);
        layer.closed = true;
        layer.thickness = 0.01;
        for (std::size_t i = 0; i < points; ++i) {
            const double a = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(points);
            const double r = radius + 0.15 * std::sin(waves * a);
            const double dr = 0.15 * waves * std::cos(waves * a);
            const Vec2 tangent(dr * std::cos(a) - r * std::sin(a),
                               dr * std::sin(a) + r * std::cos(a));
            const Vec2 outward = glm::normalize(Vec2(tangent.y, -tangent.x));
            layer.points.push_back(Vec2(r * std::cos(a), r * std::sin(a)) +
                                   spacing * static_cast<double>(k) * outward);
        }
        layers.push_back(std::move(layer));
    }
    return Scene(std::move(layers));
}

long peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss / 1024;
}

// Paper section 5.2 on a Fig. 2-like configuration: the middle of five layers decimated
// naively (every 40th vertex kept over a stretch) cuts through its neighbours; untangle it
// globally and locally, 150 iterations (5 rounds of N_gd = 30) and to convergence. The
// stretch is vertices (first, last) of the middle layer: 400-1200 (40% of it), and a short
// one, 400-480 (4%), where the local box holds a few percent of the scene as in a
// simplification step. The local box is the stretch's box grown by each of `margins` (scene
// units) in turn. Each run is repeated `repeat` times, global and the local ones in turn, and
// the best time of each is kept. `only`: "global" or "local" runs only that mode
// (profiling), "" both. paper_scene() makes the tangled scene and the stretch's box.
Scene paper_scene(std::size_t first, std::size_t last, Box2& box) {
    const Scene input = folded_stack(5, 2000, 10.0 * 2000.0 / 600.0);
    std::vector<Layer> layers = input.layers();
    Layer& middle = layers[2];
    std::vector<Vec2> kept;
    for (std::size_t i = 0; i < middle.points.size(); ++i) {
        const bool stretch = i > first && i < last;
        if (!stretch || i % 40 == 0) kept.push_back(middle.points[i]);
        if (stretch) box.extend(middle.points[i]);
    }
    middle.points = kept;
    return Scene(layers);
}

void paper(std::size_t first, std::size_t last, int repeat, const std::string& only,
           std::vector<double> margins, FieldBackend backend) {
    Box2 box;
    const Scene tangled = paper_scene(first, last, box);
    // By default the box of the earlier runs (the stretch's box grown by 0.3) and the one the
    // simplification grows around a removal (docs/simplify.md, step 2): by twice the nested
    // thickness, the thickness of the middle layer and of every layer nested with it (0.1
    // here). (The driver grows it by half the new chord where that is more, for a chord it
    // made itself: the naive decimation's chords here are 0.67 long.)
    if (margins.empty()) {
        double nest = tangled.layer(2).thickness;
        for (std::size_t b = 0; b < tangled.size(); ++b)
            if (b != 2 && tangled.relation(2, b) != Relation::SideBySide)
                nest += tangled.layer(b).thickness;
        margins = {0.3, 2.0 * nest};
    }
    const CheckReport before = check_scene(tangled);
    std::printf(
        "paper 5.2: 5 layers x 2000 vertices, middle layer decimated over vertices %zu-%zu: %zu "
        "crossings; best of %d\n",
        first, last, before.crossing_count, repeat);
    // margin: how far the local box reaches beyond the stretch's box; free: vertices each run
    // may move; clean: the local result is collision-free with its gaps (smallest gap /
    // required after it).
    std::printf("%-16s %6s %9s %9s %6s %9s %6s %6s %10s %7s %7s\n", "run", "margin", "global s",
                "local s", "ratio", "crossings", "clean", "gap", "free", "rounds", "passes");
    const bool run_global = only != "local", run_local = only != "global";
    for (const bool converge : {false, true}) {
        UntangleParams params;
        params.gradient_steps = 30;
        params.alpha = 0.8;
        params.beta = 0.9;
        params.field.backend = backend;
        if (!converge) {  // at most 150 iterations: 5 rounds, one pass, no early stop
            params.max_rounds = 5;
            params.max_passes = 1;
            params.tolerance = 1e-300;
        }
        double tg = 1e300;
        std::vector<double> tl(margins.size(), 1e300);
        UntangleReport rg;
        std::vector<UntangleReport> rl(margins.size());
        for (int k = 0; k < repeat; ++k) {
            if (run_global) {
                Scene global = tangled;
                const double t = now();
                rg = untangle(global, params);
                tg = std::min(tg, now() - t);
            }
            for (std::size_t m = 0; m < margins.size() && run_local; ++m) {
                Scene local = tangled;
                const double t = now();
                rl[m] = untangle_local(local, box.inflated(margins[m]), 7, params);
                tl[m] = std::min(tl[m], now() - t);
            }
        }
        if (!run_global) tg = 0.0;
        for (std::size_t m = 0; m < margins.size(); ++m) {
            if (!run_local) tl[m] = 0.0;
            std::printf(
                "%-16s %6.3f %9.3f %9.3f %6.1f %4zu/%-4zu %6s %6.3f %5zu/%-4zu %3d/%-3d %3d/%-3d\n",
                converge ? "until converged" : "150 iterations", margins[m], tg, tl[m],
                tl[m] > 0.0 ? tg / tl[m] : 0.0, rg.crossings_after, rl[m].crossings_after,
                !run_local             ? "-"
                : rl[m].collision_free ? "yes"
                                       : "NO",
                rl[m].min_separation_ratio_after, rg.free_vertices, rl[m].free_vertices, rg.rounds,
                rl[m].rounds, rg.passes, rl[m].passes);
            std::printf(
                "  phases of the last run (fields / untangle / check / finish s): global %.4f / "
                "%.4f / %.4f / %.4f, local %.4f / %.4f / %.4f / %.4f\n",
                rg.seconds_fields, rg.seconds_untangle, rg.seconds_check, rg.seconds_finish,
                rl[m].seconds_fields, rl[m].seconds_untangle, rl[m].seconds_check,
                rl[m].seconds_finish);
        }
    }
}

// `scene` with every layer's thickness times `thickness` and its vertices resampled: every
// `every`-th kept (the first and, for an open layer, the last too), or with `every` 0 a
// midpoint inserted in every segment.
Scene resampled(const Scene& scene, double thickness, std::size_t every) {
    std::vector<Layer> layers = scene.layers();
    for (Layer& layer : layers) {
        layer.thickness *= thickness;
        std::vector<Vec2> points;
        const std::vector<Vec2>& p = layer.points;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (every == 0) {
                points.push_back(p[i]);
                if (i + 1 < p.size() || layer.closed)
                    points.push_back(0.5 * (p[i] + p[(i + 1) % p.size()]));
            } else if (i % every == 0 || (!layer.closed && i + 1 == p.size())) {
                points.push_back(p[i]);
            }
        }
        layer.points = points;
    }
    return Scene(layers);
}

// Where the grid backend pays in a global untangling: paper 5.2's tangled stacks (both
// stretches), resampled (a midpoint in every segment, every 2nd or 4th vertex kept, the
// thickness scaled with the segment length) and with thinner layers (thickness x 0.75, 0.5,
// 0.25: the automatic voxel is then capped by half the smallest separation, and the band
// holds more voxels a segment). untangle_inferring_sides() with default parameters, as
// `strata untangle` runs; indexed and grid in turn, best of `repeat` each.
void backends(int repeat) {
    std::printf(
        "global untangling, indexed against grid fields, default UntangleParams; best of %d\n",
        repeat);
    std::printf("%-7s %-9s %-9s %8s %9s %10s %8s %7s %6s %6s\n", "stretch", "vertices", "thickness",
                "segments", "voxels/seg", "indexed s", "grid s", "grid/ix", "clean", "passes");
    struct Variant {
        const char* name;
        double thickness;
        std::size_t every;
    };
    const Variant variants[] = {{"x2", 0.5, 0},  {"x1", 1.0, 1}, {"x1/2", 2.0, 2}, {"x1/4", 4.0, 4},
                                {"x1", 0.75, 1}, {"x1", 0.5, 1}, {"x1", 0.25, 1}};
    for (const bool long_stretch : {true, false}) {
        Box2 box;
        const Scene base = long_stretch ? paper_scene(400, 1200, box) : paper_scene(400, 480, box);
        for (const Variant& v : variants) {
            const Scene tangled = resampled(base, v.thickness, v.every);
            FieldParams grid_params;
            grid_params.backend = FieldBackend::Grid;
            const FieldStats stats = SceneFields(tangled, grid_params).total_stats();
            double best[2] = {1e300, 1e300};
            bool clean = true;
            int passes[2] = {0, 0};
            for (int k = 0; k < repeat; ++k)
                for (int b = 0; b < 2; ++b) {
                    UntangleParams params;
                    params.field.backend = b == 0 ? FieldBackend::ExactIndexed : FieldBackend::Grid;
                    Scene s = tangled;
                    const double t = now();
                    const UntangleReport r = untangle_inferring_sides(s, params);
                    best[b] = std::min(best[b], now() - t);
                    clean = clean && r.collision_free;
                    passes[b] = r.passes;
                }
            std::printf(
                "%-7s %-9s %9.4f %8zu %10.0f %10.3f %8.3f %7.2f %6s %3d/%-3d\n",
                long_stretch ? "long" : "short", v.name, tangled.layer(0).thickness, stats.segments,
                static_cast<double>(stats.active_voxels) / static_cast<double>(stats.segments),
                best[0], best[1], best[1] / best[0], clean ? "yes" : "NO", passes[0], passes[1]);
            std::fflush(stdout);
        }
    }
}

struct SceneFilter {
    std::size_t min_points = 1000, max_points = 10000, layers = 0;  // 0: 5 and 8
    double remove = 0.0;                                            // 0: 0.8, 0.9, 0.95
    std::string backend;                                            // "": indexed and grid
    std::string schedule;                                           // "": deferred and immediate
    std::vector<std::size_t> batches{0};  // each strata run at each; 0: SimplifyParams' default
    std::vector<std::size_t> threads{0};  // each strata run at each; 0: TBB's default
    std::vector<std::size_t> give_up{0};  // give_up_when_stalled off (0) / on (1), each
    std::vector<std::size_t> finish{1};   // finish_separations off (0) / on (1), each
    std::string decimator = "random";     // the paper's experiments
    bool closed = false;                  // wavy_loops instead of folded_stack
};

double max_hausdorff(const SimplifyReport& report) {
    double h = 0.0;
    for (const LayerSimplifyReport& layer : report.layers) h = std::max(h, layer.hausdorff);
    return h;
}

void scenes(const SceneFilter& filter) {
    // strata s and naive s: whole simplify() calls, final exact check and Hausdorff included;
    // loop us/step: the removal loop alone (SimplifyReport::seconds_total) per kept removal.
    // batch: SimplifyParams::batch; thr: worker threads (0: every core); jobs/b: untanglings
    // per batch run (side by side); fields / untangle / check s: SimplifyReport's phase times,
    // summed over the untanglings (which run side by side: with threads, more than the wall).
    // give: UntangleParams::give_up_when_stalled; gave up: refused removals it ended early.
    // fin: UntangleParams::finish_separations; finish s: its time; ok: the final exact check
    // found no crossing and the nesting kept (SimplifyReport::collision_free).
    std::printf(
        "%-6s %-7s %-5s %-8s %-9s %5s %3s %4s %3s %8s %9s %7s %8s %8s %8s %8s %7s %7s %6s %5s %3s "
        "%7s %9s %9s %6s %8s %9s %8s %8s\n",
        "layers", "pts", "rm", "backend", "schedule", "batch", "thr", "give", "fin", "naive s",
        "strata s", "ratio", "us/step", "loop us", "deferred", "refused", "gave up", "untangl",
        "jobs/b", "cross", "ok", "gap/req", "H naive", "H strata", "rss MB", "fields s",
        "untangle s", "finish s", "check s");
    for (std::size_t count : {std::size_t(5), std::size_t(8)})
        for (std::size_t points = filter.min_points; points <= filter.max_points; points *= 10) {
            if (filter.layers != 0 && count != filter.layers) continue;
            const Scene input =
                filter.closed
                    ? wavy_loops(count, points, count > 6 ? 0.0306 : 0.04)
                    : folded_stack(count, points, 10.0 * static_cast<double>(points) / 600.0);
            if (!check_scene(input).is_collision_free()) {
                std::fprintf(stderr,
                             "strata_bench_simplify: the generated %zu x %zu input "
                             "crosses itself\n",
                             count, points);
                std::exit(1);
            }
            const std::vector<double> removals = filter.remove > 0.0
                                                     ? std::vector<double>{filter.remove}
                                                     : std::vector<double>{0.8, 0.9, 0.95};
            for (double remove : removals) {
                SimplifyParams naive;
                naive.decimator = filter.decimator;
                naive.remove = remove;
                naive.untangle = false;
                Scene n = input;
                double t = now();
                const SimplifyReport rn = simplify(n, naive);
                const double tn = now() - t;
                for (FieldBackend backend : {FieldBackend::ExactIndexed, FieldBackend::Grid})
                    for (UntangleSchedule schedule :
                         {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                        const std::string name = backend == FieldBackend::Grid ? "grid" : "indexed";
                        const std::string when =
                            schedule == UntangleSchedule::Deferred ? "deferred" : "immediate";
                        if (!filter.backend.empty() && name != filter.backend) continue;
                        if (!filter.schedule.empty() && when != filter.schedule) continue;
                        SimplifyParams params = naive;
                        params.untangle = true;
                        params.schedule = schedule;
                        params.untangling.field.backend = backend;
                        const std::size_t nt = filter.threads.size(), nb = filter.batches.size();
                        const std::size_t ng = filter.give_up.size();
                        for (std::size_t run = 0; run < filter.finish.size() * ng * nb * nt;
                             ++run) {
                            const std::size_t fin = filter.finish[run / (ng * nb * nt)];
                            const std::size_t give = filter.give_up[(run / (nb * nt)) % ng];
                            const std::size_t batch = filter.batches[(run / nt) % nb];
                            const std::size_t threads = filter.threads[run % nt];
                            params.untangling.give_up_when_stalled = give != 0;
                            params.untangling.finish_separations = fin != 0;
                            params.batch = batch > 0 ? batch : SimplifyParams{}.batch;
                            std::optional<tbb::global_control> limit;
                            if (threads > 0)
                                limit.emplace(tbb::global_control::max_allowed_parallelism,
                                              threads);
                            Scene s = input;
                            t = now();
                            const SimplifyReport r = simplify(s, params);
                            const double ts = now() - t;
                            std::printf(
                                "%-6zu %-7zu %-5.2f %-8s %-9s %5zu %3zu %4zu %3zu %8.3f %9.3f "
                                "%7.1f %8.2f %8.2f %8zu %8zu %7zu %7zu %6.2f %5zu %3s %7.3f "
                                "%9.4f %9.4f %6ld %8.3f %9.3f %8.3f %8.3f\n",
                                count, points, remove, name.c_str(), when.c_str(), params.batch,
                                threads, give, fin, tn, ts, ts / tn,
                                1e6 * ts / static_cast<double>(r.removed),
                                1e6 * r.seconds_total / static_cast<double>(r.removed), r.deferred,
                                r.refused, r.gave_up, r.untangle_calls,
                                r.batches ? static_cast<double>(r.untangle_calls) /
                                                static_cast<double>(r.batches)
                                          : 0.0,
                                r.crossings, r.collision_free ? "yes" : "NO",
                                r.min_separation_ratio, max_hausdorff(rn), max_hausdorff(r),
                                peak_rss_mb(), r.seconds_fields, r.seconds_untangle,
                                r.seconds_finish, r.seconds_check);
                            std::fflush(stdout);
                        }
                    }
            }
        }
}

// "1,2" -> {1, 2}.
std::vector<std::size_t> numbers(const std::string& list) {
    std::vector<std::size_t> out;
    for (std::size_t at = 0; at < list.size();) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        out.push_back(std::strtoul(list.substr(at, comma - at).c_str(), nullptr, 10));
        at = comma + 1;
    }
    return out;
}

// A finite number >= 0, the whole of `text`.
bool is_margin(const std::string& text) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    return !text.empty() && *end == '\0' && std::isfinite(v) && v >= 0.0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string what = argc > 1 ? argv[1] : "";
    if (what == "paper") {
        int repeat = 3;
        std::string only, stretch;
        std::vector<double> margins;
        FieldBackend backend = FieldBackend::ExactIndexed;
        for (int i = 2; i + 1 < argc; i += 2) {
            const std::string key = argv[i], value = argv[i + 1];
            if (key == "--repeat" && std::atoi(value.c_str()) >= 1) {
                repeat = std::atoi(value.c_str());
            } else if (key == "--only" && (value == "global" || value == "local")) {
                only = value;
            } else if (key == "--stretch" && (value == "long" || value == "short")) {
                stretch = value;
            } else if (key == "--margin" && is_margin(value)) {
                margins.push_back(std::strtod(value.c_str(), nullptr));
            } else if (key == "--backend" && (value == "indexed" || value == "grid")) {
                backend = value == "grid" ? FieldBackend::Grid : FieldBackend::ExactIndexed;
            } else {
                std::fprintf(stderr, "strata_bench_simplify: bad paper option %s %s\n", key.c_str(),
                             value.c_str());
                return 2;
            }
        }
        if (stretch != "short") paper(400, 1200, repeat, only, margins, backend);
        if (stretch != "long") paper(400, 480, repeat, only, margins, backend);
    } else if (what == "backends") {
        const bool given = argc == 4 && std::string(argv[2]) == "--repeat";
        const int repeat = given ? std::atoi(argv[3]) : 3;
        if (repeat < 1 || (argc != 2 && !given)) {
            std::fprintf(stderr, "usage: strata_bench_simplify backends [--repeat N]\n");
            return 2;
        }
        backends(repeat);
    } else if (what == "scenes") {
        SceneFilter filter;
        for (int i = 2; i + 1 < argc; i += 2) {
            const std::string key = argv[i], value = argv[i + 1];
            if (key == "--min") {
                filter.min_points = std::strtoul(value.c_str(), nullptr, 10);
            } else if (key == "--max") {
                filter.max_points = std::strtoul(value.c_str(), nullptr, 10);
            } else if (key == "--layers") {
                filter.layers = std::strtoul(value.c_str(), nullptr, 10);
            } else if (key == "--remove") {
                filter.remove = std::strtod(value.c_str(), nullptr);
            } else if (key == "--threads") {
                filter.threads = numbers(value);
            } else if (key == "--batch") {
                filter.batches = numbers(value);
            } else if (key == "--shape") {
                if (value != "open" && value != "closed") {
                    std::fprintf(stderr,
                                 "strata_bench_simplify: --shape must be open or closed (got %s)\n",
                                 value.c_str());
                    return 2;
                }
                filter.closed = value == "closed";
            } else if (key == "--decimator") {
                filter.decimator = value;
            } else if (key == "--give-up" || key == "--finish") {
                if (value != "0" && value != "1" && value != "0,1" && value != "1,0") {
                    std::fprintf(stderr, "strata_bench_simplify: %s must be 0, 1 or 0,1 (got %s)\n",
                                 key.c_str(), value.c_str());
                    return 2;
                }
                (key == "--give-up" ? filter.give_up : filter.finish) = numbers(value);
            } else if (key == "--schedule") {
                filter.schedule = value;
            } else if (key == "--backend") {
                filter.backend = value;
            } else {
                std::fprintf(stderr, "strata_bench_simplify: unknown option %s\n", key.c_str());
                return 2;
            }
        }
        try {
            scenes(filter);
        } catch (const std::exception& e) {  // a bad --decimator, say
            std::fprintf(stderr, "strata_bench_simplify: error: %s\n", e.what());
            return 2;
        }
    } else {
        std::fprintf(stderr,
                     "usage: strata_bench_simplify paper [--repeat N] [--only global|local] "
                     "[--stretch long|short] [--margin M]... [--backend indexed|grid] | backends "
                     "[--repeat N] | scenes "
                     "[--min N] [--max N] "
                     "[--layers 5|8] [--remove FRACTION] [--backend indexed|grid] "
                     "[--schedule deferred|immediate] [--threads N[,N...]] [--batch N[,N...]] "
                     "[--give-up 0,1] [--finish 0,1] [--decimator random|visvalingam|max-error] "
                     "[--shape open|closed]\n");
        return 2;
    }
    return 0;
}
