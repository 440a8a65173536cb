#include "simplify/detail/restore.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace strata::detail {

namespace {

// Adds to `points` where `check` (on `out`, with separation tolerance `tolerance`) finds
// something wrong, and sorts them by x (within() looks them up so).
void add_violation_points(const Scene& out, const CheckReport& check, double tolerance,
                          std::vector<Vec2>& points) {
    for (const Crossing& c : check.crossings) points.push_back(c.point);
    for (const Crossing& c : check.self_crossings) points.push_back(c.point);
    for (const NestingViolation& v : check.nesting_violations)
        points.push_back(out.layer(v.layer).points[v.vertex]);
    for (const SeparationViolation& v : check.separation_violations)
        points.push_back(out.layer(v.layer).points[v.vertex]);
    // A pair below its separation lists its closest points even when no vertex is listed.
    for (const PairSeparation& p : check.pairs)
        if (p.required > 0.0 && p.gap < p.required * (1.0 - tolerance)) {
            points.push_back(p.at_a);
            points.push_back(p.at_b);
        }
    std::sort(points.begin(), points.end(),
              [](const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
}

// Some point of `sorted` (by x) within r of p.
bool within(const std::vector<Vec2>& sorted, const Vec2& p, double r) {
    auto it = std::lower_bound(sorted.begin(), sorted.end(), p.x - r,
                               [](const Vec2& q, double x) { return q.x < x; });
    for (; it != sorted.end() && it->x <= p.x + r; ++it)
        if (glm::distance(*it, p) <= r) return true;
    return false;
}

}  // namespace

Restored restore_near_violations(const Scene& input, const LivePolylines& live, const Scene& out,
                                 const CheckReport& check, CheckParams params,
                                 const InputSides& sides) {
    Restored result;
    const Vec2 size = input.bounds().size();
    const double diagonal = std::hypot(size.x, size.y);
    std::vector<Vec2> points;
    add_violation_points(out, check, params.separation_tolerance, points);
    // From an eighth of the check's near distance, doubling; past the diagonal every vertex
    // is back (the input).
    double radius = automatic_near_distance(input) / 8.0;
    if (!(radius > 0.0)) radius = diagonal > 0.0 ? diagonal / 64.0 : 1.0;
    for (;; radius *= 2.0) {
        ++result.steps;
        const bool whole = points.empty() || radius > 2.0 * diagonal;
        std::vector<Layer> layers = input.layers();
        result.origins.assign(input.size(), {});
        result.restored = 0;
        for (std::size_t l = 0; l < input.size(); ++l) {
            const WorkLayer& w = live.layer(l);
            std::vector<Vec2> kept;
            for (std::size_t i = 0; i < w.pos.size(); ++i) {
                const bool back = whole || within(points, w.original[i], radius) ||
                                  (w.alive[i] && within(points, w.pos[i], radius));
                if (!back && !w.alive[i]) continue;
                if (back && (!w.alive[i] || w.pos[i] != w.original[i])) ++result.restored;
                kept.push_back(back ? w.original[i] : w.pos[i]);
                result.origins[l].push_back(i);
            }
            layers[l].points = std::move(kept);
        }
        Scene scene(std::move(layers), input.units());
        scene.metadata = input.metadata;
        for (const Scene::RaisedSeparation& r : input.raised_separations())
            scene.raise_required_separation(r.a, r.b, r.value);
        const InputSides renumbered = sides.renumbered(result.origins);
        params.input_sides = &renumbered;
        result.check = check_scene(scene, params);
        result.scene = std::move(scene);
        if (passes(result.check) || whole) return result;
        // What is still wrong joins the places to restore around.
        add_violation_points(result.scene, result.check, params.separation_tolerance, points);
    }
}

}  // namespace strata::detail
