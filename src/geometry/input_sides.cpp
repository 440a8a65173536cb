#include "strata/geometry/input_sides.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace strata {

// record_input_sides() is defined in checks.cpp, with the side rule of check_scene().

void validate(const InputSideParams& params) {
    if (!std::isfinite(params.reach) || params.reach < 0.0)
        throw InvalidInput("input sides: params.reach must be a finite value >= 0 (got " +
                           format_number(params.reach) + ")");
}

InputSides InputSides::renumbered(const std::vector<std::vector<std::size_t>>& origin) const {
    if (empty()) return {};
    if (origin.size() != n_)
        throw InvalidInput("input sides: renumbered() got " + std::to_string(origin.size()) +
                           " layers for " + std::to_string(n_));
    InputSides out = *this;
    out.origin_.assign(n_, {});
    for (std::size_t a = 0; a < n_; ++a) {
        const std::size_t count = vertex_count(a);
        std::vector<std::size_t>& to = out.origin_[a];
        to.reserve(origin[a].size());
        for (std::size_t k : origin[a]) {
            if (k >= count)
                throw InvalidInput("input sides: renumbered(): vertex " + std::to_string(k) +
                                   " of layer " + std::to_string(a) + " out of range (" +
                                   std::to_string(count) + " vertices)");
            to.push_back(origin_.empty() ? k : origin_[a][k]);
        }
    }
    return out;
}

std::size_t InputSides::rolled_count(const Scene& scene,
                                     const std::vector<int>& outside_sides) const {
    std::size_t count = 0;
    for (std::size_t a = 0; a < n_ && a < scene.size(); ++a)
        for (std::size_t b = 0; b < n_ && b < outside_sides.size(); ++b) {
            if (a == b) continue;
            const int wanted = global_side(scene.relation(a, b), outside_sides[b]);
            const std::size_t vertices = std::min(vertex_count(a), scene.layer(a).points.size());
            for (std::size_t k = 0; k < vertices; ++k) {
                const int s = side(a, k, b);
                if (s != 0 && s != wanted) ++count;
            }
        }
    return count;
}

int corner_side(const Vec2& u, const Vec2& w, const Vec2& x, const Vec2& v) {
    const int turn = orient2d(u, w, x);
    const int o1 = orient2d(u, w, v);
    const int o2 = orient2d(w, x, v);
    if (turn > 0) return (o1 > 0 && o2 > 0) ? -1 : 1;  // the left side is the inner wedge
    if (turn < 0) return (o1 < 0 && o2 < 0) ? 1 : -1;  // the right side is the inner wedge
    return o1 != 0 ? -o1 : -o2;
}

int segment_side(const Vec2& a, const Vec2& b, const Vec2& v) {
    return -orient2d(a, b, v);
}

int global_side(Relation relation_of_a_to_b, int outside) {
    switch (relation_of_a_to_b) {
        case Relation::Under:
            return -outside;
        case Relation::Over:
            return outside;
        default:
            return 0;
    }
}

}  // namespace strata
