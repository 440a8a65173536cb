// Field backends side by side: build time, memory per segment, value+gradient queries per
// second (random near the curve and curve-ordered), localized update time (one vertex moved by
// a fixed distance: the same box at every size). Then the grid layouts: the production
// layer-stacked grid of SceneFields (z = layer index) against one z = 0 slab field per layer,
// on 1-, 5- and 8-layer stacked scenes.
// Plain timing main; prints two tables. Usage: strata_bench_field [max_segments]

#include "strata/field/field.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

using namespace strata;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// A wavy closed curve of n unit-length-ish segments, its radius offset by `offset`.
Layer wavy_circle(std::size_t n, double offset = 0.0) {
    Layer layer;
    layer.name = "wavy";
    layer.closed = true;
    const double r = static_cast<double>(n) / (2.0 * 3.14159265358979323846) + offset;
    for (std::size_t i = 0; i < n; ++i) {
        const double t =
            2.0 * 3.14159265358979323846 * static_cast<double>(i) / static_cast<double>(n);
        const double rr = r + 3.0 * std::sin(static_cast<double>(n / 50 + 1) * t);
        layer.points.emplace_back(rr * std::cos(t), rr * std::sin(t));
    }
    return layer;
}

/// The layouts of the Grid backend on a scene of `layers` concentric wavy curves `gap` apart:
/// the production SceneFields (one layer-stacked grid, layer i at z = i) against one field per
/// layer built alone (make_field: a stack of one, i.e. a z = 0 slab per layer, with its own
/// segment store and index). Memory: FieldStats (grid memUsage + segment stores + bucket
/// indexes); "grid" subtracts the stores and indexes (an ExactIndexed SceneFields of the same
/// scene holds the same ones). sample_all: every layer at a point near a random layer.
/// Update: one vertex of layer u % layers moved by (0.1, -0.05), 200 spread moves, mean.
void bench_layout(std::size_t layers, std::size_t n, double gap) {
    std::vector<Layer> ls;
    for (std::size_t k = 0; k < layers; ++k) {
        ls.push_back(wavy_circle(n, gap * static_cast<double>(k)));
        ls.back().name = "layer" + std::to_string(k);
    }
    const Scene scene(ls);
    const ResolvedFieldParams p = resolve({}, scene);
    std::size_t segments = 0;
    for (const Layer& l : ls) segments += l.segment_count();

    // Build times: the faster of two builds of each (the first build of a run pays for page
    // faults and the thread pool's start).
    double stacked_build = 1e300, slab_build = 1e300;
    std::optional<SceneFields> stacked;
    std::vector<std::unique_ptr<LayerField>> slabs;
    for (int rep = 0; rep < 2; ++rep) {
        stacked.reset();
        auto t0 = Clock::now();
        stacked.emplace(scene);
        stacked_build = std::min(stacked_build, seconds_since(t0));
        slabs.clear();
        t0 = Clock::now();
        for (const Layer& l : ls) slabs.push_back(make_field(l, 1, p));
        slab_build = std::min(slab_build, seconds_since(t0));
    }
    FieldParams ep;
    ep.backend = FieldBackend::ExactIndexed;
    const std::size_t index_bytes = SceneFields(scene, ep).total_stats().memory_bytes;
    const FieldStats total = stacked->total_stats();
    std::size_t slab_bytes = 0, slab_leaves = 0;
    for (const auto& f : slabs) {
        const FieldStats st = f->stats();
        slab_bytes += st.memory_bytes;
        slab_leaves += st.leaves;
    }

    std::mt19937 rng(3);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::normal_distribution<double> off(0.0, 0.5 * p.band_width);
    std::vector<Vec2> qs;
    for (int q = 0; q < 200000; ++q) {
        const Layer& l = ls[static_cast<std::size_t>(q) % layers];
        qs.push_back(l.points[pick(rng)] + Vec2(off(rng), off(rng)));
    }
    std::vector<FieldSample> out(layers), other(layers);
    double sink = 0.0;
    std::size_t differ = 0;  // closed layers: both layouts give the same samples
    const auto time_it = [&](auto&& sample_all) {
        const auto start = Clock::now();
        for (const Vec2& x : qs) {
            sample_all(x, out);
            sink += out[0].value + out[layers - 1].gradient.x;
        }
        return static_cast<double>(qs.size()) / seconds_since(start);
    };
    const double stacked_rate =
        time_it([&](const Vec2& x, std::vector<FieldSample>& o) { stacked->sample_all(x, o); });
    const double slab_rate = time_it([&](const Vec2& x, std::vector<FieldSample>& o) {
        for (std::size_t k = 0; k < layers; ++k) o[k] = slabs[k]->sample(x);
    });
    for (std::size_t q = 0; q < qs.size(); q += 7) {
        stacked->sample_all(qs[q], other);
        for (std::size_t k = 0; k < layers; ++k) {
            const FieldSample s = slabs[k]->sample(qs[q]);
            if (s.value != other[k].value || s.gradient != other[k].gradient ||
                s.in_band != other[k].in_band)
                ++differ;
        }
    }
    const auto time_updates = [&](auto&& field_of) {
        std::vector<std::vector<Vec2>> pts;
        for (const Layer& l : ls) pts.push_back(l.points);
        const int updates = 200;
        const auto start = Clock::now();
        for (int u = 0; u < updates; ++u) {
            const auto l = static_cast<std::size_t>(u) % layers;
            const std::size_t i = 10 + static_cast<std::size_t>(u) * (n - 20) / updates;
            pts[l][i] += Vec2(0.1, -0.05);
            field_of(l).update(pts[l], {i, 1, 1});
        }
        return seconds_since(start) / updates;
    };
    const double stacked_update =
        time_updates([&](std::size_t l) -> LayerField& { return stacked->field(l); });
    const double slab_update =
        time_updates([&](std::size_t l) -> LayerField& { return *slabs[l]; });

    const auto per_seg = [&](std::size_t bytes) {
        return static_cast<double>(bytes) / static_cast<double>(segments);
    };
    const auto row = [&](const char* layout, std::size_t bytes, std::size_t leaves, double build,
                         double rate, double update) {
        std::printf("%-7zu %-9zu %-8s %10.0f %10.0f %9zu %10.1f %13.0f %10.1f\n", layers, segments,
                    layout, per_seg(bytes), per_seg(bytes - index_bytes), leaves, build * 1e3, rate,
                    update * 1e6);
    };
    row("slabs", slab_bytes, slab_leaves, slab_build, slab_rate, slab_update);
    row("stacked", total.memory_bytes, total.leaves, stacked_build, stacked_rate, stacked_update);
    std::printf("  (gap %g, h = %g, band = %g; stores + indexes %.0f bytes/segment%s)\n", gap,
                p.voxel_size, p.band_width, per_seg(index_bytes),
                differ == 0 ? "" : "; LAYOUTS DIFFER");
    if (sink == 12345.0) std::printf("!\n");
}

void bench_layouts() {
    std::printf("\n%-7s %-9s %-8s %10s %10s %9s %10s %13s %10s\n", "layers", "segments", "layout",
                "bytes/seg", "grid B/seg", "leaves", "build ms", "sample_all/s", "update us");
    for (std::size_t layers : {1u, 5u, 8u}) bench_layout(layers, 10000, 0.5);
    bench_layout(8, 10000, 0.25);  // layers closer together share more leaves
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
            // Localized update: move one vertex by a tenth of a segment, 200 times, at places
            // spread along the curve.
            std::vector<Vec2> pts = layer.points;
            const int updates = 200;
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
    bench_layouts();
    return 0;
}
