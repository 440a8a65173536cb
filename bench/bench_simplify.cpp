// Benchmarks of the collision-free simplification (issue 5), ratios measured in one run.
//
//   strata_bench_simplify paper            paper section 5.2: local vs global untangling
//   strata_bench_simplify scenes [--max N] generated 5/8-layer scenes, per backend
//
// Plain timers (std::chrono::steady_clock), one run per configuration: the machine is small
// and noisy, so read ratios rather than absolute times.
#include "strata/geometry/checks.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <sys/resource.h>
#include <glm/geometric.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace strata;

namespace {

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

long peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss / 1024;
}

// Paper section 5.2 on a Fig. 2-like configuration: the middle of five layers decimated
// naively (every 40th vertex kept over a stretch) cuts through its neighbours; untangle it
// globally and locally, 150 iterations (5 rounds of N_gd = 30) and to convergence.
void paper() {
    const Scene input = folded_stack(5, 2000, 10.0 * 2000.0 / 600.0);
    std::vector<Layer> layers = input.layers();
    Layer& middle = layers[2];
    std::vector<Vec2> kept;
    Box2 box;
    for (std::size_t i = 0; i < middle.points.size(); ++i) {
        const bool stretch = i > 400 && i < 1200;
        if (!stretch || i % 40 == 0) kept.push_back(middle.points[i]);
        if (stretch) box.extend(middle.points[i]);
    }
    middle.points = kept;
    const Scene tangled(layers);
    const CheckReport before = check_scene(tangled);
    std::printf(
        "paper 5.2: 5 layers x 2000 vertices, middle layer decimated over a stretch: %zu "
        "crossings\n",
        before.crossing_count);
    std::printf("%-28s %10s %10s %8s %10s\n", "run", "global s", "local s", "ratio", "crossings");
    for (const bool converge : {false, true}) {
        UntangleParams params;
        params.gradient_steps = 30;
        params.alpha = 0.8;
        params.beta = 0.9;
        params.field.backend = FieldBackend::ExactIndexed;
        if (!converge) {  // exactly 150 iterations: 5 rounds, one pass, no early stop
            params.max_rounds = 5;
            params.max_passes = 1;
            params.tolerance = 1e-300;
        }
        Scene global = tangled, local = tangled;
        double t = now();
        const UntangleReport rg = untangle(global, params);
        const double tg = now() - t;
        t = now();
        const UntangleReport rl = untangle_local(local, box.inflated(0.3), 7, params);
        const double tl = now() - t;
        std::printf("%-28s %10.3f %10.3f %8.1f %5zu/%-4zu\n",
                    converge ? "until converged" : "150 iterations", tg, tl, tg / tl,
                    rg.crossings_after, rl.crossings_after);
    }
}

void scenes(std::size_t max_points) {
    std::printf("%-7s %-8s %-5s %-8s %9s %9s %8s %10s %8s %8s %6s %7s\n", "layers", "pts", "rm",
                "backend", "naive s", "strata s", "ratio", "us/step", "refused", "untangl", "cross",
                "rss MB");
    for (std::size_t count : {std::size_t(5), std::size_t(8)})
        for (std::size_t points = 1000; points <= max_points; points *= 10) {
            const Scene input =
                folded_stack(count, points, 10.0 * static_cast<double>(points) / 600.0);
            for (double remove : {0.8, 0.9, 0.95}) {
                SimplifyParams naive;
                naive.decimator = "random";
                naive.remove = remove;
                naive.untangle = false;
                Scene n = input;
                double t = now();
                simplify(n, naive);
                const double tn = now() - t;
                for (FieldBackend backend : {FieldBackend::ExactIndexed, FieldBackend::Grid}) {
                    SimplifyParams params = naive;
                    params.untangle = true;
                    params.untangling.field.backend = backend;
                    Scene s = input;
                    t = now();
                    const SimplifyReport r = simplify(s, params);
                    const double ts = now() - t;
                    std::printf(
                        "%-7zu %-8zu %-5.2f %-8s %9.3f %9.3f %8.1f %10.2f %8zu %8zu %6zu %7ld\n",
                        count, points, remove, backend == FieldBackend::Grid ? "grid" : "indexed",
                        tn, ts, ts / tn, 1e6 * ts / static_cast<double>(r.removed), r.refused,
                        r.untangle_calls, r.crossings, peak_rss_mb());
                    std::fflush(stdout);
                }
            }
        }
}

}  // namespace

int main(int argc, char** argv) {
    const std::string what = argc > 1 ? argv[1] : "";
    if (what == "paper") {
        paper();
    } else if (what == "scenes") {
        const std::size_t max = argc > 3 && std::string(argv[2]) == "--max"
                                    ? std::strtoul(argv[3], nullptr, 10)
                                    : 10000;
        scenes(max);
    } else {
        std::fprintf(stderr,
                     "usage: strata_bench_simplify paper | scenes [--max POINTS_PER_LAYER]\n");
        return 2;
    }
    return 0;
}
