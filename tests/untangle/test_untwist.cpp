// Untwisting (src/untangle/detail/untwist.h), the last resorts' way of taking self-crossings
// out: one vertex moved for a local twist, a scene without self-crossings left as it is, and on
// twisted loops around and inside other layers, the exact checks before and after: no more
// crossings between layers, and the self-crossings all gone exactly when it says so.

#include "strata/geometry/checks.h"
#include "untangle/detail/untwist.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

using namespace strata;

namespace {

Layer loop(const char* name, std::vector<Vec2> points, double thickness = 0.0) {
    Layer layer;
    layer.name = name;
    layer.points = std::move(points);
    layer.closed = true;
    layer.thickness = thickness;
    return layer;
}

std::vector<Vec2> circle(std::size_t n, double r) {
    std::vector<Vec2> points;
    for (std::size_t k = 0; k < n; ++k) {
        const double t = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(n);
        points.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return points;
}

std::size_t moved(const Scene& a, const Scene& b) {
    std::size_t count = 0;
    for (std::size_t l = 0; l < a.size(); ++l)
        for (std::size_t v = 0; v < a.layer(l).points.size(); ++v)
            count += a.layer(l).points[v] != b.layer(l).points[v];
    return count;
}

}  // namespace

TEST_CASE("untwist: a loop with two vertices swapped loses its twist by one vertex move",
          "[untwist]") {
    std::vector<Vec2> twisted = circle(12, 1.0);
    std::swap(twisted[3], twisted[4]);  // segments 2-4 and 3-5 cross
    std::vector<Vec2> far = circle(16, 1.0);
    for (Vec2& p : far) p += Vec2(10.0, 0.0);
    Scene scene({loop("twisted", twisted, 0.05), loop("far", far)});
    const Scene before = scene;
    REQUIRE(check_scene(before).total_self_crossings() == 1);

    REQUIRE(detail::untwist(scene));
    const CheckReport after = check_scene(scene);
    CHECK(after.total_self_crossings() == 0);
    CHECK(after.crossing_count == 0);
    CHECK(moved(before, scene) == 1);
    CHECK(scene.layer(1).points == before.layer(1).points);
}

TEST_CASE("untwist: a loop pinched at a repeated point comes apart by a tiny move", "[untwist]") {
    // Two lobes that meet at the origin, which the loop passes twice (a slice through a
    // saddle vertex of its mesh: the body at x = 2.5 dm): the strands touch there without
    // crossing, each vertex on the other's line, so no move across a line exists.
    const std::vector<Vec2> pinched = {{0, 0}, {1, 1},   {2, 0},  {1, -1},
                                       {0, 0}, {-1, -1}, {-2, 0}, {-1, 1}};
    std::vector<Vec2> around = circle(32, 4.0);
    Scene scene({loop("pinched", pinched), loop("around", around)});
    const Scene before = scene;
    REQUIRE(check_scene(before).total_self_crossings() == 1);

    REQUIRE(detail::untwist(scene));
    const CheckReport after = check_scene(scene);
    CHECK(after.total_self_crossings() == 0);
    CHECK(after.crossing_count == 0);
    CHECK(moved(before, scene) <= 2);  // the two copies of the pinch point at most
    for (std::size_t v = 0; v < pinched.size(); ++v)
        CHECK(glm::length(scene.layer(0).points[v] - pinched[v]) < 1e-6);
}

TEST_CASE("untwist: no move that crosses another layer", "[untwist]") {
    // The same twist with a small loop put where the move above took the vertex: that move
    // would now cross it, so another one is made, or none.
    std::vector<Vec2> twisted = circle(12, 1.0);
    std::swap(twisted[3], twisted[4]);
    Scene free({loop("twisted", twisted, 0.05)});
    REQUIRE(detail::untwist(free));
    std::size_t v = 0;
    while (free.layer(0).points[v] == twisted[v]) ++v;
    const Vec2 at = free.layer(0).points[v];
    const double r = 0.25 * glm::length(at - twisted[v]);
    std::vector<Vec2> blocker = circle(6, r);
    for (Vec2& p : blocker) p += at;
    Scene scene({loop("twisted", twisted, 0.05), loop("blocker", blocker)});
    REQUIRE(check_scene(scene).crossing_count == 0);

    const bool done = detail::untwist(scene);
    const CheckReport after = check_scene(scene);
    CHECK(after.crossing_count == 0);
    CHECK(done == (after.total_self_crossings() == 0));
    CHECK(scene.layer(0).points[v] != at);
}

TEST_CASE("untwist: a scene without self-crossings is left as it is", "[untwist]") {
    Scene scene({loop("inner", circle(12, 1.0)), loop("outer", circle(12, 2.0))});
    const Scene before = scene;
    CHECK(detail::untwist(scene));
    CHECK(moved(before, scene) == 0);
}

TEST_CASE("untwist: twisted loops between two others never cross them more", "[untwist]") {
    // A loop of 14 vertices on the unit circle, twisted: two pairs of neighbours swapped at
    // random (odd seeds), or one pair of any two vertices (even seeds); between a small loop
    // inside and a large one around. Some of the twisted loop's chords cross the small one.
    std::size_t twisted[2] = {0, 0}, untwisted[2] = {0, 0};
    for (unsigned seed = 1; seed <= 80; ++seed) {
        std::mt19937 rng(seed);
        std::vector<Vec2> points = circle(14, 1.0);
        std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
        const bool local = seed % 2 == 1;
        for (int swaps = 0; swaps < (local ? 2 : 1); ++swaps) {
            const std::size_t a = pick(rng);
            std::swap(points[a], points[local ? (a + 1) % points.size() : pick(rng)]);
        }
        Scene scene({loop("inner", circle(10, 0.3)), loop("twisted", points, 0.01),
                     loop("outer", circle(20, 3.0))});
        const CheckReport before = check_scene(scene);
        if (before.total_self_crossings() == 0) continue;
        ++twisted[local];
        const Scene input = scene;
        const bool done = detail::untwist(scene);
        const CheckReport after = check_scene(scene);
        INFO("seed " << seed);
        CHECK(after.crossing_count <= before.crossing_count);
        CHECK(done == (after.total_self_crossings() == 0));
        CHECK(scene.layer(0).points == input.layer(0).points);
        CHECK(scene.layer(2).points == input.layer(2).points);
        untwisted[local] += done;
    }
    INFO("local twists " << untwisted[1] << " of " << twisted[1] << " untwisted, others "
                         << untwisted[0] << " of " << twisted[0]);
    CHECK(twisted[1] >= 30);
    CHECK(twisted[0] >= 20);
    // A twist of neighbours is what the projection makes: every one is taken out. Of the wide
    // twists few are (a single vertex move rarely leaves its layer crossing itself less).
    CHECK(untwisted[1] == twisted[1]);
}
