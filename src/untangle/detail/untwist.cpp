#include "untangle/detail/untwist.h"

#include "strata/geometry/checks.h"
#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace strata::detail {

namespace {

// Segments of `scene` that the segments at vertex v of layer l meet with that vertex at `at`:
// {of other layers, of layer l}. The segments next to those two are left out (they share an
// end with them).
std::pair<std::size_t, std::size_t> segments_met(const Scene& scene, std::size_t l, std::size_t v,
                                                 const Vec2& at) {
    const Layer& layer = scene.layer(l);
    const std::size_t n = layer.points.size();
    const bool closed = layer.closed;
    std::vector<std::pair<Vec2, Vec2>> own;
    if (v > 0 || closed) own.emplace_back(layer.points[(v + n - 1) % n], at);
    if (v + 1 < n || closed) own.emplace_back(at, layer.points[(v + 1) % n]);
    // Segment j of layer l shares an end with a segment at v.
    auto next_to_v = [&](std::size_t j) {
        if (!closed) return j + 2 >= v && j <= v + 1;
        for (const std::size_t d : {n - 2, n - 1, std::size_t{0}, std::size_t{1}})
            if (j == (v + d) % n) return true;
        return false;
    };
    std::size_t others = 0, self = 0;
    for (std::size_t m = 0; m < scene.size(); ++m) {
        const std::vector<Vec2>& q = scene.layer(m).points;
        const std::size_t segments =
            q.size() < 2 ? 0 : (scene.layer(m).closed ? q.size() : q.size() - 1);
        for (std::size_t j = 0; j < segments; ++j) {
            if (m == l && next_to_v(j)) continue;
            for (const auto& [p0, p1] : own)
                if (segment_contact(p0, p1, q[j], q[(j + 1) % q.size()]) != SegmentContact::None)
                    ++(m == l ? self : others);
        }
    }
    return {others, self};
}

}  // namespace

bool untwist(Scene& scene) {
    const Box2 box = scene.bounds();
    const double floor = 1e-9 * glm::length(box.size());
    CheckParams params;
    params.max_listed = 1;
    CheckReport check = check_scene(scene, params);
    const std::size_t limit = 4 * check.total_self_crossings() + 4;
    for (std::size_t step = 0; step < limit; ++step) {
        if (check.total_self_crossings() == 0) return true;
        params.max_listed = check.total_self_crossings();
        check = check_scene(scene, params);
        double shortest = std::numeric_limits<double>::infinity();
        std::size_t best_layer = 0, best_vertex = 0;
        Vec2 best_at(0.0);
        for (const Crossing& c : check.self_crossings) {
            const Layer& layer = scene.layer(c.layer_a);
            const std::size_t n = layer.points.size();
            const double aim = std::max(layer.thickness, floor);
            for (const auto& [mine, theirs] :
                 {std::pair{c.segment_a, c.segment_b}, std::pair{c.segment_b, c.segment_a}}) {
                const Vec2 q0 = layer.points[theirs], q1 = layer.points[(theirs + 1) % n];
                const double length = glm::length(q1 - q0);
                if (!(length > 0.0)) continue;
                const Vec2 normal = Vec2(q0.y - q1.y, q1.x - q0.x) / length;
                for (const std::size_t v : {mine, (mine + 1) % n}) {
                    const Vec2 p = layer.points[v];
                    const double d = glm::dot(p - q0, normal);
                    const double move = std::abs(d) + aim;
                    if (!(move < shortest)) continue;
                    // Across the line to its far side; a vertex on the line (a touch, e.g. a
                    // slice through a saddle vertex of its mesh) off it, to either side.
                    const Vec2 across = p - (d + std::copysign(aim, d)) * normal;
                    const std::array<Vec2, 2> targets = {d != 0.0 ? across : p + aim * normal,
                                                         p - aim * normal};
                    const auto before = segments_met(scene, c.layer_a, v, p);
                    for (std::size_t k = 0; k < (d != 0.0 ? 1u : 2u); ++k) {
                        const auto after = segments_met(scene, c.layer_a, v, targets[k]);
                        if (after.second >= before.second || after.first > before.first) continue;
                        shortest = move;
                        best_layer = c.layer_a;
                        best_vertex = v;
                        best_at = targets[k];
                        break;
                    }
                }
            }
        }
        if (!std::isfinite(shortest)) return false;
        std::vector<Vec2> points = scene.layer(best_layer).points;
        points[best_vertex] = best_at;
        scene.set_points(best_layer, std::move(points));
        params.max_listed = 1;
        check = check_scene(scene, params);
    }
    return check.total_self_crossings() == 0;
}

}  // namespace strata::detail
