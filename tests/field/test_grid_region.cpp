// FieldParams::region: a grid built and updated only around the box a caller samples in.
#include "field/detail/grid_inspect.h"
#include "strata/core/error.h"
#include "strata/field/field.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace strata;

namespace {

// Three nested circles and an open arc between the outer two: closed and open layers.
Scene circles_and_arc() {
    std::vector<Layer> layers = test::nested_circles(3, 400, 1.0, 0.1).layers();
    Layer arc;
    arc.name = "arc";
    for (int i = 0; i <= 200; ++i) {
        const double a = 0.4 + 1.6 * static_cast<double>(i) / 200.0;
        arc.points.emplace_back(1.15 * std::cos(a), 1.15 * std::sin(a));
    }
    layers.insert(layers.begin() + 2, arc);
    return Scene(layers);
}

// The resolved sizes of `fields`, fixed, with `region`.
FieldParams fixed_params(const SceneFields& fields, const Box2& region) {
    FieldParams p;
    p.voxel_size = fields.params().voxel_size;
    p.band_width = fields.params().band_width;
    p.bucket_size = fields.params().bucket_size;
    p.region = region;
    return p;
}

Box2 box_of(Vec2 min, Vec2 max) {
    Box2 b;
    b.extend(min);
    b.extend(max);
    return b;
}

bool same_sample(const FieldSample& a, const FieldSample& b) {
    return a.value == b.value && a.gradient == b.gradient && a.in_band == b.in_band;
}

}  // namespace

TEST_CASE("grid region: samples within band of the region equal the whole grid's", "[field]") {
    const Scene scene = circles_and_arc();
    FieldParams grid_params;
    const SceneFields probe(scene, grid_params);
    const SceneFields whole(scene, fixed_params(probe, {}));
    // Across the curves; and inside every loop, away from the curves (no leaf there: the signs
    // come from the walk to the right, which leaves the region).
    const Box2 region =
        GENERATE(box_of(Vec2(0.5, 0.6), Vec2(1.0, 1.1)), box_of(Vec2(-0.2, -0.3), Vec2(0.3, 0.2)));
    const SceneFields part(scene, fixed_params(probe, region));
    // The part holds a fraction of the leaves.
    CHECK(part.total_stats().leaves * 4 < whole.total_stats().leaves);
    const Box2 near = region.inflated(probe.params().band_width);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(near.min.x, near.max.x), uy(near.min.y, near.max.y);
    std::size_t in_band = 0;
    for (int k = 0; k < 4000; ++k) {
        const Vec2 x(ux(rng), uy(rng));
        for (std::size_t l = 0; l < scene.size(); ++l) {
            const FieldSample a = whole.field(l).sample(x), b = part.field(l).sample(x);
            INFO("layer " << l << " at (" << x.x << ", " << x.y << ")");
            CHECK(a.in_band == b.in_band);
            if (scene.layer(l).closed || a.in_band) CHECK(same_sample(a, b));
            if (a.in_band) ++in_band;
            const FieldSample c = whole.field(l).sample_in_band(x);
            const FieldSample d = part.field(l).sample_in_band(x);
            CHECK(c.in_band == d.in_band);
            if (c.in_band) CHECK(same_sample(c, d));
        }
    }
    if (region.min.x > 0.0) CHECK(in_band > 1000);
}

TEST_CASE("grid region: farther out, closed layers read out of band with their exact sign",
          "[field]") {
    const Scene scene = circles_and_arc();
    const SceneFields probe(scene);
    const Box2 region = box_of(Vec2(0.5, 0.6), Vec2(1.0, 1.1));
    const SceneFields part(scene, fixed_params(probe, region));
    FieldParams exact_params = fixed_params(probe, {});
    exact_params.backend = FieldBackend::ExactIndexed;
    const SceneFields exact(scene, exact_params);
    const double band = probe.params().band_width;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.6, 1.6);
    std::size_t inside = 0, checked = 0;
    for (int k = 0; k < 3000; ++k) {
        const Vec2 x(u(rng), u(rng));
        if (region.inflated(band + 2.0 * probe.params().voxel_size).contains(x)) continue;
        for (std::size_t l = 0; l < scene.size(); ++l) {
            if (!scene.layer(l).closed) continue;
            const FieldSample e = exact.field(l).sample(x);
            if (std::abs(e.value) < band) continue;  // near a curve outside the region
            const FieldSample g = part.field(l).sample(x);
            INFO("layer " << l << " at (" << x.x << ", " << x.y << ")");
            CHECK_FALSE(g.in_band);
            CHECK(std::abs(g.value) == Approx(band));
            CHECK((g.value < 0.0) == (e.value < 0.0));
            if (e.value < 0.0) ++inside;
            ++checked;
        }
    }
    CHECK(checked > 1000);
    CHECK(inside > 100);
}

TEST_CASE("grid region: updates equal a rebuild with the same region", "[field]") {
    Scene scene = circles_and_arc();
    std::vector<Layer> layers = scene.layers();
    const SceneFields probe(scene);
    const Box2 region = box_of(Vec2(0.3, 0.4), Vec2(1.0, 1.2));
    const FieldParams params = fixed_params(probe, region);
    SceneFields fields(scene, params);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.03, 0.03);
    for (int step = 0; step < 60; ++step) {
        // Moves near and inside the region, and far from it (nothing to recompute there).
        const std::size_t l = static_cast<std::size_t>(step) % layers.size();
        std::vector<Vec2>& pts = layers[l].points;
        const std::size_t i = static_cast<std::size_t>(rng() % (pts.size() - 3));
        for (std::size_t k = i; k < i + 3; ++k) pts[k] += Vec2(u(rng), u(rng));
        fields.field(l).update(pts, {i, 3, 3});
        scene = Scene(layers);
        if (step % 15 != 14) continue;
        const SceneFields fresh(scene, params);
        for (std::size_t f = 0; f < scene.size(); ++f) {
            std::string why;
            const bool same = detail::grids_identical(fields.field(f), fresh.field(f), &why);
            INFO("step " << step << ", layer " << f << ": " << why);
            CHECK(same);
        }
    }
}

TEST_CASE("grid region: a region that is not finite is refused", "[field]") {
    FieldParams p;
    p.region = box_of(Vec2(0.0), Vec2(1.0, std::numeric_limits<double>::infinity()));
    CHECK_THROWS_AS(validate(p), InvalidInput);
    p.region = Box2{};
    CHECK_NOTHROW(validate(p));
}
