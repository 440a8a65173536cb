// Field backends side by side: build time, memory per segment, value+gradient queries per
// second (random near the curve and curve-ordered), localized update time (one vertex moved by
// a fixed distance: the same box at every size). Then the grid layouts: per-layer z = 0 slabs
// against one layer-stacked grid (z = layer index) on 5- and 8-layer stacked scenes.
// Plain timing main; prints two tables. Usage: strata_bench_field [max_segments]

#include "strata/field/field.h"

#include <openvdb/openvdb.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
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

using Tree = openvdb::FloatTree;
using Accessor = openvdb::tree::ValueAccessor<const Tree, false>;

/// The grid's voxels of one layer: exact signed values (ExactIndexed) at the voxel centres
/// within the band, as the Grid backend stores them (visited segment by segment, band boxes).
template <typename F>
void for_band_voxels(const Layer& layer, const LayerField& exact, const ResolvedFieldParams& p,
                     F&& f) {
    const double h = p.voxel_size;
    openvdb::BoolTree visited(false);
    openvdb::tree::ValueAccessor<openvdb::BoolTree> seen(visited);
    for (std::size_t s = 0; s < layer.segment_count(); ++s) {
        Box2 box;
        box.extend(layer.segment_start(s));
        box.extend(layer.segment_end(s));
        box = box.inflated(p.band_width);
        const int i0 = static_cast<int>(std::ceil(box.min.x / h));
        const int i1 = static_cast<int>(std::floor(box.max.x / h));
        const int j0 = static_cast<int>(std::ceil(box.min.y / h));
        const int j1 = static_cast<int>(std::floor(box.max.y / h));
        for (int i = i0; i <= i1; ++i)
            for (int j = j0; j <= j1; ++j) {
                const openvdb::Coord c(i, j, 0);
                if (seen.isValueOn(c)) continue;
                seen.setValueOn(c, true);
                const FieldSample v = exact.sample(Vec2(i * h, j * h));
                if (v.in_band) f(i, j, static_cast<float>(v.value));
            }
    }
}

/// Bilinear sample from the 4 corner values (as the Grid backend does).
FieldSample bilinear(const float v[4], bool on, double fx, double fy, double h) {
    FieldSample out;
    const double d00 = v[0], d10 = v[1], d01 = v[2], d11 = v[3];
    out.value = (1.0 - fy) * ((1.0 - fx) * d00 + fx * d10) + fy * ((1.0 - fx) * d01 + fx * d11);
    out.gradient = Vec2(((1.0 - fy) * (d10 - d00) + fy * (d11 - d01)) / h,
                        ((1.0 - fx) * (d01 - d00) + fx * (d11 - d10)) / h);
    out.in_band = on;
    return out;
}

/// Per-layer slabs (z = 0, one tree per layer) against one stacked tree (z = layer index) on a
/// scene of `layers` concentric wavy curves `gap` apart: grid memory (OpenVDB memUsage; the
/// segment stores and leaf buckets are the same for both layouts) and the time of sampling
/// every layer at a point (what SceneFields::sample_all does).
void bench_layout(std::size_t layers, std::size_t n, double gap) {
    std::vector<Layer> ls;
    for (std::size_t k = 0; k < layers; ++k) {
        ls.push_back(wavy_circle(n, gap * static_cast<double>(k)));
        ls.back().name = "layer" + std::to_string(k);
    }
    const Scene scene(ls);
    const ResolvedFieldParams p = resolve({}, scene);
    const float bg = static_cast<float>(p.band_width);
    std::vector<Tree::Ptr> slabs;
    const auto stacked = std::make_shared<Tree>(bg);
    std::size_t segments = 0;
    for (std::size_t k = 0; k < layers; ++k) {
        ResolvedFieldParams e = p;
        e.backend = FieldBackend::ExactIndexed;
        const auto exact = make_field(ls[k], 1, e);
        segments += ls[k].segment_count();
        auto slab = std::make_shared<Tree>(bg);
        const int z = static_cast<int>(k);
        for_band_voxels(ls[k], *exact, p, [&](int i, int j, float v) {
            slab->setValueOn(openvdb::Coord(i, j, 0), v);
            stacked->setValueOn(openvdb::Coord(i, j, z), v);
        });
        slabs.push_back(slab);
    }
    std::size_t slab_bytes = 0, slab_leaves = 0;
    for (const auto& t : slabs) {
        slab_bytes += static_cast<std::size_t>(t->memUsage());
        slab_leaves += static_cast<std::size_t>(t->leafCount());
    }
    const auto stacked_bytes = static_cast<std::size_t>(stacked->memUsage());
    // Production fields of the same scene (slab layout): total bytes incl. stores and buckets.
    const SceneFields fields(scene);
    std::size_t field_bytes = 0;
    for (std::size_t k = 0; k < fields.size(); ++k)
        field_bytes += fields.field(k).stats().memory_bytes;

    std::mt19937 rng(3);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::normal_distribution<double> off(0.0, 0.5 * p.band_width);
    std::vector<Vec2> qs;
    for (int q = 0; q < 200000; ++q) {
        const Layer& l = ls[static_cast<std::size_t>(q) % layers];
        qs.push_back(l.points[pick(rng)] + Vec2(off(rng), off(rng)));
    }
    const double h = p.voxel_size;
    std::vector<FieldSample> out(layers);
    double sink = 0.0;
    const auto time_it = [&](auto&& sample_all) {
        const auto start = Clock::now();
        for (const Vec2& x : qs) {
            sample_all(x);
            sink += out[0].value + out[layers - 1].gradient.x;
        }
        return static_cast<double>(qs.size()) / seconds_since(start);
    };
    std::vector<Accessor> slab_acc;
    for (const auto& t : slabs) slab_acc.emplace_back(*t);
    const double slab_rate = time_it([&](const Vec2& x) {
        const double gx = x.x / h, gy = x.y / h, fx0 = std::floor(gx), fy0 = std::floor(gy);
        const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
        for (std::size_t k = 0; k < layers; ++k) {
            float v[4];
            bool on = true;
            for (int c = 0; c < 4; ++c)
                on &= slab_acc[k].probeValue(openvdb::Coord(i0 + (c & 1), j0 + (c >> 1), 0), v[c]);
            out[k] = bilinear(v, on, gx - fx0, gy - fy0, h);
        }
    });
    Accessor stacked_acc(*stacked);
    const double stacked_rate = time_it([&](const Vec2& x) {
        const double gx = x.x / h, gy = x.y / h, fx0 = std::floor(gx), fy0 = std::floor(gy);
        const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
        // One leaf access per corner returns every layer's value there.
        const Tree::LeafNodeType* leaf[4];
        for (int c = 0; c < 4; ++c)
            leaf[c] = stacked_acc.probeConstLeaf(openvdb::Coord(i0 + (c & 1), j0 + (c >> 1), 0));
        for (std::size_t k = 0; k < layers; ++k) {
            float v[4];
            bool on = true;
            for (int c = 0; c < 4; ++c) {
                const openvdb::Coord xyz(i0 + (c & 1), j0 + (c >> 1), static_cast<int>(k));
                if (leaf[c] != nullptr) {
                    const openvdb::Index o = Tree::LeafNodeType::coordToOffset(xyz);
                    v[c] = leaf[c]->getValue(o);
                    on &= leaf[c]->isValueOn(o);
                } else {
                    on &= stacked_acc.probeValue(xyz, v[c]);
                }
            }
            out[k] = bilinear(v, on, gx - fx0, gy - fy0, h);
        }
    });
    const auto per_seg = [&](std::size_t bytes) {
        return static_cast<double>(bytes) / static_cast<double>(segments);
    };
    std::printf("%-7zu %-9zu %-8s %12.0f %10zu %14.0f%s\n", layers, segments, "slab",
                per_seg(slab_bytes), slab_leaves, slab_rate, sink == 12345.0 ? "!" : "");
    std::printf("%-7zu %-9zu %-8s %12.0f %10zu %14.0f\n", layers, segments, "stacked",
                per_seg(stacked_bytes), static_cast<std::size_t>(stacked->leafCount()),
                stacked_rate);
    std::printf(
        "  (gap %g, h = %g, band = %g; production slab fields incl. segment stores and "
        "buckets: %.0f bytes/segment)\n",
        gap, h, p.band_width, per_seg(field_bytes));
}

void bench_layouts() {
    openvdb::initialize();
    std::printf("\n%-7s %-9s %-8s %12s %10s %14s\n", "layers", "segments", "layout", "grid B/seg",
                "leaves", "sample_all/s");
    for (std::size_t layers : {5u, 8u}) bench_layout(layers, 10000, 0.5);
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
