#include "untangle/detail/retract_ends.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

namespace strata::detail {

namespace {

using Score = std::tuple<std::size_t, std::size_t, std::size_t, std::size_t>;

Score score_of(const CheckReport& check) {
    return {check.crossing_count, check.total_self_crossings(), check.nesting_violation_count,
            check.separation_violation_count};
}

// Layer l's end `end` (0 or its last vertex) with end segment `segment` is in a listed
// crossing or violation of `check`; `crossed` receives the points where its segment is met.
bool is_involved(const CheckReport& check, std::size_t l, std::size_t end, std::size_t segment,
                 std::vector<Vec2>& crossed) {
    crossed.clear();
    auto take = [&](const Crossing& c) {
        if ((c.layer_a == l && c.segment_a == segment) ||
            (c.layer_b == l && c.segment_b == segment))
            crossed.push_back(c.point);
    };
    for (const Crossing& c : check.crossings) take(c);
    for (const Crossing& c : check.self_crossings) take(c);
    if (!crossed.empty()) return true;
    for (const NestingViolation& v : check.nesting_violations)
        if (v.layer == l && v.vertex == end) return true;
    for (const SeparationViolation& v : check.separation_violations)
        if (v.layer == l && v.vertex == end) return true;
    return false;
}

}  // namespace

std::size_t retract_ends(Scene& scene, const CheckParams& judge) {
    CheckParams params = judge;
    params.max_listed = std::numeric_limits<std::size_t>::max();
    CheckReport check = check_scene(scene, params);
    std::size_t retracted = 0;
    std::vector<Vec2> crossed;
    for (std::size_t l = 0; l < scene.size(); ++l) {
        if (scene.layer(l).closed || scene.layer(l).points.size() < 2) continue;
        const std::size_t n = scene.layer(l).points.size();
        for (const auto& [end, inner, segment] :
             {std::array<std::size_t, 3>{0, 1, 0},
              std::array<std::size_t, 3>{n - 1, n - 2, n - 2}}) {
            if (!is_involved(check, l, end, segment, crossed)) continue;
            const Vec2 e = scene.layer(l).points[end], b = scene.layer(l).points[inner];
            const double length = glm::distance(e, b);
            if (!(length > 0.0)) continue;
            // Fractions of the end segment kept, from its inner vertex.
            std::vector<double> kept;
            if (!crossed.empty()) {
                double nearest = 1.0;
                for (const Vec2& c : crossed)
                    nearest = std::min(nearest, glm::distance(c, b) / length);
                kept.push_back(0.5 * nearest);
            } else {
                kept = {0.75, 0.5, 0.25};
            }
            const Score before = score_of(check);
            for (const double f : kept) {
                if (!(f > 0.0)) continue;
                std::vector<Vec2> points = scene.layer(l).points;
                points[end] = b + f * (e - b);
                if (points[end] == b || points[end] == e) continue;
                Scene trial = scene;
                trial.set_points(l, std::move(points));
                CheckReport after = check_scene(trial, params);
                if (!(score_of(after) < before)) continue;
                scene = std::move(trial);
                check = std::move(after);
                ++retracted;
                break;
            }
        }
    }
    return retracted;
}

}  // namespace strata::detail
