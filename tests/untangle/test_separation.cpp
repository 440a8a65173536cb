#include "strata/geometry/checks.h"
#include "strata/untangle/localize.h"
#include "support/fixtures.h"
#include "support/require.h"
#include "untangle/detail/separation.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <random>

using namespace strata;

namespace {

Layer polyline(std::string name, std::vector<Vec2> points, double thickness, bool closed = false) {
    Layer layer;
    layer.name = std::move(name);
    layer.points = std::move(points);
    layer.thickness = thickness;
    layer.closed = closed;
    return layer;
}

// A horizontal layer at height y over x in [0, 1] whose end vertices (fixed in finish())
// bend away by `flare` (down when negative), so that the ends keep their gap.
Layer horizontal(std::string name, double y, double thickness, double flare = 0.0,
                 double shift = 0.0) {
    std::vector<Vec2> points;
    for (int i = 0; i <= 10; ++i)
        points.emplace_back(0.1 * i + shift, y + (i == 0 || i == 10 ? flare : 0.0));
    return polyline(std::move(name), std::move(points), thickness);
}

// Runs the finishing stage on every vertex of `scene` but the ends of open layers, with the
// outside sides of the open layers voted on `sides_from` (default: the scene itself).
detail::SeparationResult finish(Scene& scene, const Scene* sides_from = nullptr) {
    std::vector<Piece> pieces = whole_scene_pieces(scene);
    for (Piece& piece : pieces)
        if (!scene.layer(piece.layer).closed) {
            piece.is_free.front() = 0;
            piece.is_free.back() = 0;
        }
    detail::RelationSource relations;
    relations.scene = &scene;
    const Scene input = sides_from ? *sides_from : scene;
    const std::vector<int> sides = outside_sides(input);
    detail::SeparationParams params;
    params.outside_signs = &sides;
    return detail::finish_separations(scene, pieces, relations, params);
}

double gap(const Scene& scene, std::size_t a, std::size_t b) {
    const CheckReport check = check_scene(scene);
    for (const PairSeparation& pair : check.pairs)
        if (pair.layer_a == a && pair.layer_b == b) return pair.gap;
    return std::numeric_limits<double>::infinity();
}

}  // namespace

TEST_CASE("the finishing stage pushes two close layers to their separation", "[separation]") {
    // Required separation (0.1 + 0.1) / 2 = 0.1; they are 0.04 apart.
    Scene scene({horizontal("lower", 0.0, 0.1, -0.2), horizontal("upper", 0.04, 0.1, 0.2)});
    REQUIRE(gap(scene, 0, 1) == Approx(0.04));
    const detail::SeparationResult r = finish(scene);
    CHECK(r.moves > 0);
    CHECK(r.worst <= 0.02);
    CHECK(gap(scene, 0, 1) >= 0.098);
    test::require_collision_free(scene, 0.02);
    // Equal weights: both layers moved by about the same amount, in opposite directions.
    CHECK(scene.layer(0).points[5].y == Approx(-0.03).margin(0.003));
    CHECK(scene.layer(1).points[5].y == Approx(0.07).margin(0.003));
}

TEST_CASE("the finishing stage moves a heavier layer less", "[separation]") {
    Layer lower = horizontal("lower", 0.0, 0.1, -0.2);
    lower.weight = 9.0;
    Scene scene({lower, horizontal("upper", 0.04, 0.1, 0.2)});
    finish(scene);
    CHECK(gap(scene, 0, 1) >= 0.098);
    const double down = -scene.layer(0).points[5].y, up = scene.layer(1).points[5].y - 0.04;
    CHECK(up > 5.0 * down);
}

TEST_CASE("the finishing stage keeps fixed vertices where they are", "[separation]") {
    Scene scene({horizontal("lower", 0.0, 0.1, -0.2), horizontal("upper", 0.04, 0.1, 0.2)});
    std::vector<Piece> pieces = whole_scene_pieces(scene);
    std::fill(pieces[0].is_free.begin(), pieces[0].is_free.end(), 0);  // lower fixed
    pieces[1].is_free.front() = pieces[1].is_free.back() = 0;
    detail::RelationSource relations;
    relations.scene = &scene;
    const std::vector<int> sides{outside_side(scene, 0), outside_side(scene, 1)};
    detail::SeparationParams params;
    params.outside_signs = &sides;
    const Scene before = scene;
    detail::finish_separations(scene, pieces, relations, params);
    CHECK(scene.layer(0).points == before.layer(0).points);
    for (std::size_t v = 1; v + 1 < scene.layer(1).points.size(); ++v)
        CHECK(scene.layer(1).points[v].y >= 0.098);
}

TEST_CASE("the finishing stage brings a vertex poking through back to its side", "[separation]") {
    // The middle vertex of the lower layer pokes 0.01 above the upper one, 0.04 above it (less
    // than their separation, 0.02: deeper pokes are the projection's), between two of its
    // vertices (a vertex of the upper layer inside the poke would need the projection too).
    // The open layers' sides come from the scene before the poke (the vote would count the
    // poking vertex).
    Layer lower = horizontal("lower", 0.0, 0.02);
    const Layer upper = horizontal("upper", 0.04, 0.02, 0.0, 0.05);
    const Scene untangled({lower, upper});
    lower.points[5].y = 0.05;
    Scene scene({lower, upper});
    REQUIRE(check_scene(scene).crossing_count == 2);
    const detail::SeparationResult r = finish(scene, &untangled);
    CHECK(r.moves > 0);
    test::require_collision_free(scene, 0.1);
    CHECK(scene.layer(0).points[5].y < scene.layer(1).points[5].y);
}

TEST_CASE("the finishing stage takes a poke out of a side-by-side open layer", "[separation]") {
    // Two open pieces side by side (no side asked of either): vertex 5 of the lower one pokes
    // 0.01 through the upper one, between two of its vertices. The side it belongs on is the
    // one the rest of its layer is on.
    Layer lower = horizontal("lower", 0.0, 0.02);
    Layer upper = horizontal("upper", 0.04, 0.02, 0.0, 0.05);
    lower.outer = std::vector<std::string>{};
    upper.outer = std::vector<std::string>{};
    lower.points[5].y = 0.05;
    Scene scene({lower, upper});
    REQUIRE(scene.relation(0, 1) == Relation::SideBySide);
    REQUIRE(check_scene(scene).crossing_count == 2);
    const detail::SeparationResult r = finish(scene);
    CHECK(r.moves > 0);
    test::require_collision_free(scene, 0.1);
    CHECK(scene.layer(0).points[5].y < scene.layer(1).points[5].y);
}

TEST_CASE("the finishing stage pulls back an open end that crosses a side-by-side piece",
          "[separation]") {
    // The last two vertices of an open piece dangle 0.01 over another open piece side by side
    // (its last segment but one crosses it once): they belong on the side of the rest. The
    // end vertex is free here (finish() fixes the ends: the pieces are set by hand).
    Layer lower = horizontal("lower", 0.0, 0.02);
    Layer upper = polyline("upper", {{0.0, 0.04}, {0.6, 0.04}, {1.2, 0.04}}, 0.02);
    lower.outer = std::vector<std::string>{};
    upper.outer = std::vector<std::string>{};
    lower.points[9].y = 0.05;
    lower.points[10].y = 0.05;
    Scene scene({lower, upper});
    REQUIRE(scene.relation(0, 1) == Relation::SideBySide);
    REQUIRE(check_scene(scene).crossing_count == 1);
    std::vector<Piece> pieces = whole_scene_pieces(scene);
    pieces[1].is_free.assign(pieces[1].is_free.size(), 0);  // the upper piece stays
    detail::RelationSource relations;
    relations.scene = &scene;
    const std::vector<int> sides = outside_sides(scene);
    detail::SeparationParams params;
    params.outside_signs = &sides;
    const detail::SeparationResult r = detail::finish_separations(scene, pieces, relations, params);
    CHECK(r.moves > 0);
    test::require_collision_free(scene, 0.1);
    CHECK(scene.layer(0).points[10].y < 0.04);
}

TEST_CASE("the finishing stage never makes a crossing (random stacks)", "[separation]") {
    // Wavy stacks of 4 layers whose gaps are drawn below and above the required separation,
    // with their fixed ends fanned out: what the stage cannot fix it must leave uncrossed,
    // and it must not make things worse.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int improved = 0;
    for (int trial = 0; trial < 150; ++trial) {
        std::vector<Layer> layers;
        double y0 = 0.0;
        const double phase = 6.0 * u(rng), amplitude = 0.2 * u(rng);
        for (int l = 0; l < 4; ++l) {
            std::vector<Vec2> points;
            const int n = 20 + static_cast<int>(30 * u(rng));
            for (int i = 0; i < n; ++i) {
                const double x = 2.0 * i / (n - 1.0);
                points.emplace_back(
                    x, y0 + amplitude * std::sin(3.0 * x + phase) + 0.01 * (u(rng) - 0.5));
            }
            // The fixed ends fan out, so that the gaps can be met.
            points.front().y += 0.5 * (l - 1.5);
            points.back().y += 0.5 * (l - 1.5);
            layers.push_back(polyline("l" + std::to_string(l), points, 0.02 + 0.06 * u(rng)));
            y0 += 0.015 + 0.08 * u(rng);
        }
        Scene scene(layers);
        const CheckReport before = check_scene(scene);
        if (!before.is_collision_free()) continue;  // the jitter made a crossing: not this test
        INFO("trial " << trial);
        finish(scene);
        const CheckReport after = check_scene(scene);
        REQUIRE(after.crossing_count == 0);
        REQUIRE(after.total_self_crossings() == 0);
        REQUIRE(after.nesting_violation_count == 0);
        CHECK(after.min_separation_ratio >= std::min(before.min_separation_ratio, 1.0) - 1e-9);
        if (after.min_separation_ratio >= 0.9 && before.min_separation_ratio < 0.9) ++improved;
    }
    CHECK(improved > 20);
}

TEST_CASE("the finishing stage never adds a crossing to a tangled stack", "[separation]") {
    // Jagged stacks of 4 layers closer than their thickness, most already crossing: every
    // move is checked before it is made (the vertex's two segments may meet each other
    // segment no more often than before, and sweep over no vertex), so a stack may not end
    // with more crossings between its layers, or within one, than it had.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int tangled = 0, moved = 0;
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<Layer> layers;
        double y0 = 0.0;
        for (int l = 0; l < 4; ++l) {
            std::vector<Vec2> points;
            const int n = 8 + static_cast<int>(16 * u(rng));
            for (int i = 0; i < n; ++i)
                points.emplace_back(2.0 * i / (n - 1.0), y0 + 0.08 * (u(rng) - 0.5));
            points.front().y += 0.5 * (l - 1.5);
            points.back().y += 0.5 * (l - 1.5);
            layers.push_back(polyline("l" + std::to_string(l), points, 0.05 + 0.05 * u(rng)));
            y0 += 0.02 + 0.04 * u(rng);
        }
        Scene scene(layers);
        const CheckReport before = check_scene(scene);
        tangled += before.crossing_count > 0;
        INFO("trial " << trial);
        moved += finish(scene).moves > 0;
        const CheckReport after = check_scene(scene);
        REQUIRE(after.crossing_count <= before.crossing_count);
        REQUIRE(after.total_self_crossings() <= before.total_self_crossings());
    }
    CHECK(tangled > 50);
    CHECK(moved > 100);
}

TEST_CASE("the finishing stage does not sweep a layer over a small layer", "[separation]") {
    // The middle layer's vertex 1 is pushed up, away from the bottom layer 0.01 below it (its
    // thickness asks for 0.15). The top layer, one short fixed segment with no thickness (so
    // nothing pushes the two apart), lies just above the middle layer, where that push would
    // sweep the segment (0, 0)-(1, 0) over it without crossing anything: the moves must stop
    // below it.
    std::vector<Layer> layers;
    layers.push_back(polyline("bottom", {{0.0, -0.01}, {1.0, -0.01}, {2.0, -0.01}}, 0.3));
    layers.push_back(polyline("middle", {{0.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}}, 0.0));
    layers.push_back(polyline("top", {{0.85, 0.02}, {0.9, 0.03}}, 0.0));
    Scene scene(layers);
    REQUIRE(check_scene(scene).crossing_count == 0);
    REQUIRE(check_scene(scene).nesting_violation_count == 0);
    finish(scene);
    const CheckReport after = check_scene(scene);
    CHECK(after.crossing_count == 0);
    CHECK(after.nesting_violation_count == 0);
    // It moved, below the top layer's line through (0, 0).
    CHECK(scene.layer(1).points[1].y > 0.0);
    CHECK(scene.layer(1).points[1].y < 0.02 / 0.85);
}

TEST_CASE("the finishing stage keeps nested loops nested", "[separation]") {
    // Three concentric circles 0.02 apart that must keep 0.05.
    Scene scene = test::nested_circles(3, 48, 1.0, 0.02, 0.05);
    finish(scene);
    test::require_collision_free(scene, 0.05);
}

TEST_CASE("the finishing stage takes an open layer's end back behind a vertex around it",
          "[separation]") {
    // The lower layer rolls around the upper one's end: its last vertex lay around that end
    // in the input (any side of it), but the upper layer's end segment has come to reach 0.01
    // past it, so its closest point there is inside the segment, on the upper side: the checks
    // judge it by the global order (under), on the wrong side. The end moves back behind it.
    const double t = 0.02;  // required separation 0.02
    Scene scene(
        {polyline("lower", {{0.0, 0.0}, {0.5, 0.0}, {1.0, 0.0}, {1.0, 0.2}, {0.69, 0.2}}, t),
         polyline("upper", {{0.0, 0.1}, {0.35, 0.1}, {0.7, 0.1}}, t)});
    const std::vector<Piece> pieces = whole_scene_pieces(scene);
    detail::RelationSource relations;
    relations.scene = &scene;
    relations.local_sides.resize(2);
    relations.local_sides[0].resize(5);
    relations.local_sides[0][4].push_back({1, detail::RelationSource::Side::AnySide});
    // The open layers' sides voted on the layers without the roll.
    const std::vector<int> sides = outside_sides(
        Scene({polyline("lower", {{0.0, 0.0}, {0.5, 0.0}, {1.0, 0.0}}, t), scene.layer(1)}));
    detail::SeparationParams params;
    params.outside_signs = &sides;
    const Vec2 p = scene.layer(0).points[4];
    auto past_end = [&] {  // how far the upper layer's end segment reaches past p
        const std::vector<Vec2>& q = scene.layer(1).points;
        const Vec2 e = q[2] - q[1];
        return glm::dot(q[2] - scene.layer(0).points[4], e) / glm::length(e);
    };
    REQUIRE(past_end() == Approx(0.01));
    // On the other side of the upper layer's end segment than the rest of the lower layer.
    const Vec2 q1 = scene.layer(1).points[1], q2 = scene.layer(1).points[2];
    REQUIRE(orient2d(q1, q2, p) == -orient2d(q1, q2, scene.layer(0).points[1]));
    const detail::SeparationResult r = detail::finish_separations(scene, pieces, relations, params);
    CHECK(r.moves > 0);
    CHECK(past_end() <= -0.9 * t);  // the end is behind the vertex by about the aim
    test::require_collision_free(scene, 0.1);
}

TEST_CASE("the finishing stage's cache across calls changes no result", "[separation]") {
    // Random stacks of uneven segments, pieces around a box (most segments fixed), the free
    // vertices moved between calls (their segments' lengths, and with them the median the
    // stage reads, change): calls that keep a FinishCache give what calls without one give.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int moved = 0;
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<Layer> layers;
        for (int l = 0; l < 4; ++l) {
            std::vector<Vec2> points;
            double x = 0.0;
            while (x < 4.0) {
                points.emplace_back(x, 0.02 * l + 0.004 * (u(rng) - 0.5));
                x += 0.04 + 0.2 * u(rng) * u(rng);
            }
            // Segments longer than the gaps aimed for: the median sets the stage's grid.
            layers.push_back(polyline("l" + std::to_string(l), points, 0.03));
        }
        const Scene input(layers);
        Box2 box;
        box.extend(Vec2(1.0 + u(rng), -0.1));
        box.extend(Vec2(1.5 + u(rng), 0.3));
        const std::vector<Piece> pieces = localize(input, box, 3);
        detail::RelationSource relations;
        relations.scene = &input;
        const std::vector<int> sides = outside_sides(input);
        detail::SeparationParams params;
        params.outside_signs = &sides;
        Scene with = input, without = input;
        detail::FinishCache cache;
        for (int call = 0; call < 4; ++call) {
            INFO("trial " << trial << ", call " << call);
            const detail::SeparationResult a =
                detail::finish_separations(with, pieces, relations, params, &cache);
            const detail::SeparationResult b =
                detail::finish_separations(without, pieces, relations, params);
            REQUIRE(a.moves == b.moves);
            REQUIRE(a.sweeps == b.sweeps);
            REQUIRE(a.worst == b.worst);
            for (std::size_t l = 0; l < input.size(); ++l)
                REQUIRE(with.layer(l).points == without.layer(l).points);
            moved += a.moves > 0 ? 1 : 0;
            // The free vertices move along the layer (as the projection would move them).
            for (const Piece& piece : pieces) {
                std::vector<Vec2> points = with.layer(piece.layer).points;
                for (std::size_t k = 0; k < piece.vertices.size(); ++k)
                    if (piece.is_free[k]) points[piece.vertices[k]].x += 0.04 * (u(rng) - 0.5);
                with.set_points(piece.layer, points);
                without.set_points(piece.layer, points);
            }
        }
    }
    CHECK(moved > 10);
}
