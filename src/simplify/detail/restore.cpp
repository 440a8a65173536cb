#include "simplify/detail/restore.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>
#include <utility>

namespace strata::detail {

namespace {

// Vertices the checks of thin() may read in all (about 2 us each: a few seconds).
constexpr std::size_t kThinningBudget = 2'000'000;

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

// A scene of `layers` with the units, metadata and raised separations of `input`.
Scene like_input(const Scene& input, std::vector<Layer> layers) {
    Scene scene(std::move(layers), input.units());
    scene.metadata = input.metadata;
    for (const Scene::RaisedSeparation& r : input.raised_separations())
        scene.raise_required_separation(r.a, r.b, r.value);
    return scene;
}

// A vertex put back that thin() may take out again.
struct Restorable {
    bool kept_before;          // not one the radius put back: tried after those
    double cost;               // twice the area of its triangle (Visvalingam)
    std::size_t layer, index;  // index: in the restored scene's layer
};

// The scene of `input`'s kind with, per layer, the vertices of `base` whose `kept` flag is set;
// checked (`params`, the sides renumbered): true and `result` replaced if it passes.
bool take_if_passes(const Scene& input, const Scene& base,
                    const std::vector<std::vector<std::size_t>>& base_origins,
                    const std::vector<std::vector<char>>& kept, CheckParams params,
                    const InputSides& sides, Restored& result) {
    const std::size_t layers = base.size();
    std::vector<Layer> thinned = base.layers();
    std::vector<std::vector<std::size_t>> origins(layers);
    for (std::size_t l = 0; l < layers; ++l) {
        thinned[l].points.clear();
        for (std::size_t k = 0; k < kept[l].size(); ++k)
            if (kept[l][k]) {
                thinned[l].points.push_back(base.layer(l).points[k]);
                origins[l].push_back(base_origins[l][k]);
            }
    }
    Scene scene = like_input(input, std::move(thinned));
    // The Scene drops a point equal to its neighbour: then the origins no longer match.
    for (std::size_t l = 0; l < layers; ++l)
        if (scene.layer(l).points.size() != origins[l].size()) return false;
    const InputSides renumbered = sides.renumbered(origins);
    params.input_sides = &renumbered;
    CheckReport check = check_scene(scene, params);
    if (!passes(check)) return false;
    result.scene = std::move(scene);
    result.origins = std::move(origins);
    result.check = std::move(check);
    return true;
}

// Takes vertices out of the layers of `result` above their target (`targets`) as long as the
// exact check still passes: first those that came back from removal (`came_back`, per layer and
// vertex of result.scene), then the others (which the local checks may have kept for want of a
// view of the whole), each cheapest first; a group at once, halved where it fails (few checks
// when most may go). At most `max_checks` checks.
void thin(const Scene& input, Restored& result, const std::vector<std::vector<char>>& came_back,
          const std::vector<std::size_t>& targets, CheckParams params, const InputSides& sides,
          std::size_t max_checks) {
    const Scene base = result.scene;
    const std::vector<std::vector<std::size_t>> base_origins = result.origins;
    const std::size_t layers = base.size();
    std::vector<Restorable> candidates;
    std::vector<std::size_t> spare(layers, 0);  // removals each layer can still take
    for (std::size_t l = 0; l < layers; ++l) {
        const Layer& layer = base.layer(l);
        const std::size_t n = layer.points.size();
        const std::size_t floor = std::max(targets[l], layer.closed ? std::size_t{3} : 2);
        spare[l] = n > floor ? n - floor : 0;
        for (std::size_t k = 0; k < n && spare[l] > 0; ++k) {
            if (!layer.closed && (k == 0 || k + 1 == n)) continue;
            const Vec2& a = layer.points[k == 0 ? n - 1 : k - 1];
            const Vec2& b = layer.points[k];
            const Vec2& c = layer.points[k + 1 == n ? 0 : k + 1];
            const double area2 = std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
            candidates.push_back({!came_back[l][k], area2, l, k});
        }
    }
    std::sort(candidates.begin(), candidates.end(), [](const Restorable& a, const Restorable& b) {
        return std::tie(a.kept_before, a.cost, a.layer, a.index) <
               std::tie(b.kept_before, b.cost, b.layer, b.index);
    });
    std::vector<std::vector<char>> kept(layers);  // per vertex of `base`: still there
    for (std::size_t l = 0; l < layers; ++l) kept[l].assign(base.layer(l).points.size(), 1);
    std::size_t checks = 0;
    // Takes out the candidates [begin, end) their layers can spare; true if that passes.
    auto attempt = [&](std::size_t begin, std::size_t end) {
        std::vector<std::size_t> taken;
        std::vector<std::size_t> spent(layers, 0);
        for (std::size_t i = begin; i < end; ++i) {
            const Restorable& c = candidates[i];
            if (spent[c.layer] == spare[c.layer]) continue;
            ++spent[c.layer];
            kept[c.layer][c.index] = 0;
            taken.push_back(i);
        }
        if (taken.empty()) return true;
        ++checks;
        if (!take_if_passes(input, base, base_origins, kept, params, sides, result)) {
            for (std::size_t i : taken) kept[candidates[i].layer][candidates[i].index] = 1;
            return false;
        }
        for (std::size_t i : taken) {
            --spare[candidates[i].layer];
            if (!candidates[i].kept_before) --result.restored;
        }
        return true;
    };
    std::vector<std::pair<std::size_t, std::size_t>> groups{{0, candidates.size()}};
    while (!groups.empty() && checks < max_checks) {
        const auto [begin, end] = groups.back();
        groups.pop_back();
        if (begin >= end || attempt(begin, end) || end - begin == 1) continue;
        const std::size_t middle = begin + (end - begin) / 2;
        groups.push_back({middle, end});  // after the first half
        groups.push_back({begin, middle});
    }
}

bool above_targets(const Scene& scene, const std::vector<std::size_t>& targets) {
    for (std::size_t l = 0; l < scene.size(); ++l)
        if (scene.layer(l).points.size() > targets[l]) return true;
    return false;
}

}  // namespace

std::size_t meet_targets(const Scene& input, Restored& result,
                         const std::vector<std::size_t>& targets, CheckParams params,
                         const InputSides& sides, bool trim_ends) {
    const std::size_t max_checks =
        std::max<std::size_t>(1, kThinningBudget / std::max<std::size_t>(1, input.vertex_count()));
    auto thin_all = [&] {
        std::vector<std::vector<char>> came_back(result.scene.size());
        for (std::size_t l = 0; l < result.scene.size(); ++l)
            came_back[l].assign(result.scene.layer(l).points.size(), 0);
        thin(input, result, came_back, targets, params, sides, max_checks);
    };
    thin_all();
    std::size_t trimmed = 0;
    const Vec2 size = input.bounds().size();
    const double tolerance = 1e-6 * std::max(std::hypot(size.x, size.y), 1e-300);
    if (!trim_ends) return trimmed;
    for (std::size_t checks = 0; checks < max_checks && above_targets(result.scene, targets);) {
        bool took = false;
        for (std::size_t l = 0; l < result.scene.size() && checks < max_checks; ++l) {
            const Layer& layer = result.scene.layer(l);
            const std::size_t n = layer.points.size();
            if (layer.closed || n <= std::max<std::size_t>(targets[l], 2)) continue;
            // The end whose removal leaves the layer nearer its input first (Hausdorff), the
            // end of the shorter segment where that ties.
            auto cost = [&](std::size_t end) {
                Layer rest = layer;
                rest.points.erase(rest.points.begin() + static_cast<std::ptrdiff_t>(end));
                return std::make_pair(
                    hausdorff(rest, input.layer(l), tolerance).symmetric(),
                    glm::distance(layer.points[end], layer.points[end == 0 ? 1 : n - 2]));
            };
            const bool first_first = cost(0) <= cost(n - 1);
            const Scene base = result.scene;
            const std::vector<std::vector<std::size_t>> base_origins = result.origins;
            for (const std::size_t end : first_first ? std::array<std::size_t, 2>{0, n - 1}
                                                     : std::array<std::size_t, 2>{n - 1, 0}) {
                std::vector<std::vector<char>> kept(base.size());
                for (std::size_t k = 0; k < base.size(); ++k)
                    kept[k].assign(base.layer(k).points.size(), 1);
                kept[l][end] = 0;
                ++checks;
                if (take_if_passes(input, base, base_origins, kept, params, sides, result)) {
                    ++trimmed;
                    took = true;
                    break;
                }
            }
        }
        if (!took) break;
        thin_all();
    }
    return trimmed;
}

Restored restore_near_violations(const Scene& input, const LivePolylines& live, const Scene& out,
                                 const CheckReport& check, CheckParams params,
                                 const InputSides& sides) {
    Restored result;
    const Vec2 size = input.bounds().size();
    const double diagonal = std::hypot(size.x, size.y);
    std::vector<Vec2> points;
    add_violation_points(out, check, params.separation_tolerance, points);
    std::vector<std::vector<char>> came_back;  // per layer and vertex of the candidate
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
        came_back.assign(input.size(), {});
        for (std::size_t l = 0; l < input.size(); ++l) {
            const WorkLayer& w = live.layer(l);
            std::vector<Vec2> kept;
            for (std::size_t i = 0; i < w.pos.size(); ++i) {
                const bool back = whole || within(points, w.original[i], radius) ||
                                  (w.alive[i] && within(points, w.pos[i], radius));
                if (!back && !w.alive[i]) continue;
                if (back && (!w.alive[i] || w.pos[i] != w.original[i])) ++result.restored;
                kept.push_back(back ? w.original[i] : w.pos[i]);
                came_back[l].push_back(!w.alive[i]);
                result.origins[l].push_back(i);
            }
            layers[l].points = std::move(kept);
        }
        Scene scene = like_input(input, std::move(layers));
        const InputSides renumbered = sides.renumbered(result.origins);
        params.input_sides = &renumbered;
        result.check = check_scene(scene, params);
        result.scene = std::move(scene);
        if (passes(result.check)) {
            // Then the layers above their target lose vertices again where the check allows,
            // within a budget of checks (each reads the whole scene).
            std::vector<std::size_t> targets(input.size());
            for (std::size_t l = 0; l < input.size(); ++l) targets[l] = live.layer(l).target;
            const std::size_t checks = std::max<std::size_t>(
                1, kThinningBudget / std::max<std::size_t>(1, input.vertex_count()));
            thin(input, result, came_back, targets, params, sides, checks);
            return result;
        }
        if (whole) return result;
        // What is still wrong joins the places to restore around.
        add_violation_points(result.scene, result.check, params.separation_tolerance, points);
    }
}

}  // namespace strata::detail
