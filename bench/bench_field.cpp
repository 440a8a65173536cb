// Field backends side by side: build time, memory per segment, value+gradient queries per
// second (random near the curve and curve-ordered), localized update time (one vertex moved).
// Plain timing main; prints one table. Usage: strata_bench_field [max_segments]

#include "strata/field/field.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

using namespace strata;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// A wavy closed curve of n unit-length-ish segments.
Layer wavy_circle(std::size_t n) {
    Layer layer;
    layer.name = "wavy";
    layer.closed = true;
    const double r = static_cast<double>(n) / (2.0 * 3.14159265358979323846);
    for (std::size_t i = 0; i < n; ++i) {
        const double t =
            2.0 * 3.14159265358979323846 * static_cast<double>(i) / static_cast<double>(n);
        const double rr = r + 3.0 * std::sin(static_cast<double>(n / 50 + 1) * t);
        layer.points.emplace_back(rr * std::cos(t), rr * std::sin(t));
    }
    return layer;
}

}  // namespace

int main(int argc, char** argv) {
    const std::size_t max_n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 100000;
    std::printf("%-8s %-8s %10s %12s %14s %14s %12s\n", "segments", "backend", "build ms",
                "bytes/seg", "rand q/s", "ordered q/s", "update us");
    for (std::size_t n = 1000; n <= max_n; n *= 10) {
        Layer layer = wavy_circle(n);
        const Scene scene({layer});
        const ResolvedFieldParams base = resolve({}, scene);
        std::mt19937 rng(1);
        std::uniform_int_distribution<std::size_t> pick(0, n - 1);
        std::normal_distribution<double> off(0.0, 0.5 * base.band_width);
        std::vector<Vec2> random_q, ordered_q;
        for (int q = 0; q < 200000; ++q)
            random_q.push_back(layer.points[pick(rng)] + Vec2(off(rng), off(rng)));
        for (std::size_t q = 0; q < 200000; ++q) {
            const std::size_t i = (q / 4) % n;
            ordered_q.push_back(0.5 * (layer.points[i] + layer.points[(i + 1) % n]) +
                                Vec2(off(rng), off(rng)));
        }
        for (FieldBackend b :
             {FieldBackend::Grid, FieldBackend::ExactIndexed, FieldBackend::ExactBrute}) {
            ResolvedFieldParams p = base;
            p.backend = b;
            auto t0 = Clock::now();
            auto field = make_field(layer, 1, p);
            const double build = seconds_since(t0);
            const FieldStats st = field->stats();
            const std::size_t queries =
                b == FieldBackend::ExactBrute ? std::max<std::size_t>(200, 2000000 / n) : 200000;
            double sink = 0.0;
            const auto rate = [&](const std::vector<Vec2>& qs) {
                const auto start = Clock::now();
                for (std::size_t q = 0; q < queries; ++q) {
                    const FieldSample s = field->sample(qs[q]);
                    sink += s.value + s.gradient.x;
                }
                return static_cast<double>(queries) / seconds_since(start);
            };
            const double rq = rate(random_q), oq = rate(ordered_q);
            // Localized update: move one vertex by a tenth of a segment, 50 times, at places
            // spread along the curve.
            std::vector<Vec2> pts = layer.points;
            const int updates = 50;
            t0 = Clock::now();
            for (int u = 0; u < updates; ++u) {
                const std::size_t i = 10 + static_cast<std::size_t>(u) * (n - 20) / updates;
                pts[i] += Vec2(0.1, -0.05);
                field->update(pts, {i, 1, 1});
            }
            const double upd = seconds_since(t0) / updates;
            const char* name = b == FieldBackend::Grid
                                   ? "grid"
                                   : (b == FieldBackend::ExactIndexed ? "indexed" : "brute");
            std::printf("%-8zu %-8s %10.2f %12.0f %14.0f %14.0f %12.1f%s\n", n, name, build * 1e3,
                        static_cast<double>(st.memory_bytes) / static_cast<double>(n), rq, oq,
                        upd * 1e6, sink == 12345.0 ? "!" : "");
        }
        std::printf("  (h = %g, band = %g = %.1f voxels)\n", base.voxel_size, base.band_width,
                    base.band_width / base.voxel_size);
    }
    return 0;
}
