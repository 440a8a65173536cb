// RegionCheck: the counts of check_scene() from a check near the moved region only, compared
// with check_scene() itself on random scenes and random moves.
#include "geometry/detail/region_check.h"
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

using namespace strata;

namespace {

constexpr double kPi = 3.14159265358979323846;

// `count` open wavy layers 0.2 apart (one stack, innermost first), `points` vertices each.
Scene wavy_stack(std::size_t count, std::size_t points, double thickness, std::mt19937& rng) {
    std::uniform_real_distribution<double> jitter(-0.01, 0.01);
    std::vector<Layer> layers;
    for (std::size_t l = 0; l < count; ++l) {
        Layer layer;
        layer.name = "s" + std::to_string(l);
        layer.thickness = thickness;
        for (std::size_t i = 0; i < points; ++i) {
            const double x = 10.0 * static_cast<double>(i) / static_cast<double>(points - 1);
            layer.points.emplace_back(
                x + jitter(rng),
                0.3 * std::sin(2.0 * x) + 0.2 * static_cast<double>(l) + jitter(rng));
        }
        layers.push_back(std::move(layer));
    }
    return Scene(std::move(layers));
}

// `count` wobbly closed loops, each inside the next, and an open layer over them.
Scene loops(std::size_t count, std::size_t points, double thickness, std::mt19937& rng) {
    std::uniform_real_distribution<double> jitter(-0.01, 0.01);
    std::vector<Layer> layers;
    for (std::size_t l = 0; l < count; ++l) {
        Layer layer;
        layer.name = "c" + std::to_string(l);
        layer.closed = true;
        layer.thickness = thickness;
        for (std::size_t i = 0; i < points; ++i) {
            const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(points);
            const double r = 2.0 + 0.25 * static_cast<double>(l) + 0.05 * std::sin(5.0 * t);
            layer.points.emplace_back(r * std::cos(t) + jitter(rng), r * std::sin(t) + jitter(rng));
        }
        layers.push_back(std::move(layer));
    }
    Layer top;
    top.name = "top";
    top.thickness = thickness;
    const double r = 2.0 + 0.25 * static_cast<double>(count);
    for (std::size_t i = 0; i <= points / 2; ++i) {
        const double t = kPi * static_cast<double>(i) / static_cast<double>(points / 2);
        top.points.emplace_back(r * std::cos(t) + jitter(rng), r * std::sin(t) + jitter(rng));
    }
    layers.push_back(std::move(top));
    return Scene(std::move(layers));
}

// `scene` with some vertices inside `box` moved by up to `reach`, kept inside it; some of
// them put exactly on a vertex of another layer (touches).
Scene moved(const Scene& scene, const Box2& box, double reach, std::mt19937& rng) {
    std::uniform_real_distribution<double> d(-reach, reach), u(0.0, 1.0);
    std::vector<Layer> layers = scene.layers();
    // The vertices of each layer inside the box (as they are: a snapped vertex lands on
    // another layer's vertex, never on one of its own layer).
    std::vector<std::vector<Vec2>> inside(layers.size());
    for (std::size_t l = 0; l < layers.size(); ++l)
        for (const Vec2& p : layers[l].points)
            if (box.contains(p)) inside[l].push_back(p);
    for (std::size_t l = 0; l < layers.size(); ++l)
        for (Vec2& p : layers[l].points) {
            if (!box.contains(p) || u(rng) < 0.5) continue;
            Vec2 q = p + Vec2(d(rng), d(rng));
            const std::vector<Vec2>& other = inside[(l + 1) % layers.size()];
            if (u(rng) < 0.05 && !other.empty())
                q = other[static_cast<std::size_t>(u(rng) * static_cast<double>(other.size())) %
                          other.size()];
            if (box.contains(q)) p = q;
        }
    return Scene(std::move(layers));
}

void require_same(const CheckCounts& region, const CheckCounts& whole) {
    CHECK(region.crossing_count == whole.crossing_count);
    CHECK(region.touch_count == whole.touch_count);
    CHECK(region.self_crossing_count == whole.self_crossing_count);
    CHECK(region.separation_violation_count == whole.separation_violation_count);
    CHECK(region.nesting_violation_count == whole.nesting_violation_count);
    CHECK(region.min_separation_ratio == whole.min_separation_ratio);
    CHECK(region.is_collision_free() == whole.is_collision_free());
    CHECK(region.separations_hold() == whole.separations_hold());
}

}  // namespace

TEST_CASE("RegionCheck gives check_scene()'s counts on random scenes and moves",
          "[checks][region]") {
    std::mt19937 rng(20231);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::size_t checks = 0, whole = 0, tangled = 0, clean = 0;
    for (std::size_t trial = 0; trial < 60; ++trial) {
        const double thickness = trial % 3 == 0 ? 0.0 : 0.05 + 0.1 * u(rng);
        const Scene reference = trial % 2 == 0 ? wavy_stack(3 + trial % 3, 120, thickness, rng)
                                               : loops(2 + trial % 2, 90, thickness, rng);
        CheckParams params;
        params.separation_tolerance = trial % 4 == 0 ? 0.0 : 0.1;
        params.outside_sides = outside_sides(reference);
        const InputSides sides = record_input_sides(reference);
        if (trial % 5 == 4) params.input_sides = &sides;
        // A box well inside the scene (moves there leave the bounds, and so the automatic
        // near distance, as they are).
        const Box2 all = reference.bounds();
        const Vec2 size = all.size();
        Box2 box;
        const Vec2 corner = all.min + Vec2(0.1 + 0.5 * u(rng), 0.1 + 0.5 * u(rng)) * size;
        box.extend(corner);
        box.extend(corner + Vec2(0.1 + 0.2 * u(rng), 0.1 + 0.2 * u(rng)) * size);
        // The region: the box of the moves and the neighbours of the moved vertices.
        const RegionCheck region(reference, params, box.inflated(0.25));
        require_same(counts_of(region.reference_report()),
                     counts_of(check_scene(reference, params)));
        for (int step = 0; step < 6; ++step) {
            const double reach = (step % 3 == 0 ? 0.02 : step % 3 == 1 ? 0.1 : 0.4);
            const Scene scene = moved(reference, box, reach, rng);
            const CheckCounts got = region.check(scene);
            const CheckCounts want = counts_of(check_scene(scene, params));
            require_same(got, want);
            ++checks;
            (want.is_collision_free() && want.separations_hold() ? clean : tangled) += 1;
        }
        whole += region.whole_checks();
    }
    // The region path ran (not the whole-scene fallback) on most, and both verdicts occurred.
    INFO("checks " << checks << ", whole " << whole << ", tangled " << tangled);
    CHECK(whole * 20 < checks);
    CHECK(tangled > 0);
    CHECK(clean > 0);
}

TEST_CASE("RegionCheck falls back to the whole scene where the region does not tell",
          "[checks][region]") {
    std::mt19937 rng(7);
    const Scene reference = wavy_stack(3, 60, 0.05, rng);
    CheckParams params;
    params.outside_sides = outside_sides(reference);
    Box2 box;
    box.extend(Vec2(4.0, -1.0));
    box.extend(Vec2(6.0, 2.0));
    const RegionCheck region(reference, params, box);
    // A vertex outside the box moves (across the next layer): the whole scene is checked.
    std::vector<Layer> layers = reference.layers();
    layers[0].points[2].y += 0.5;
    const Scene outside(layers);
    require_same(region.check(outside), counts_of(check_scene(outside, params)));
    CHECK(region.whole_checks() == 1);
    // Nothing moved: the reference's counts, no check.
    require_same(region.check(reference), counts_of(region.reference_report()));
    CHECK(region.whole_checks() == 1);
    // Another layer count is refused.
    layers.pop_back();
    CHECK_THROWS_AS(region.check(Scene(layers)), InvalidInput);
    // Without outside sides every check is whole.
    const RegionCheck plain(reference, CheckParams{}, box);
    require_same(plain.check(outside), counts_of(check_scene(outside, CheckParams{})));
    CHECK(plain.whole_checks() == 1);
}
