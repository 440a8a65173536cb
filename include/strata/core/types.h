#pragma once
/// @file Basic value types shared by every strata module.

#include <glm/vec2.hpp>

#include <algorithm>
#include <cstddef>
#include <limits>

namespace strata {

/// A point or vector of the plane, in scene units.
using Vec2 = glm::dvec2;

/// Axis-aligned box of the plane, in scene units. Empty when min > max (the default).
struct Box2 {
    Vec2 min{std::numeric_limits<double>::infinity()};
    Vec2 max{-std::numeric_limits<double>::infinity()};

    bool is_empty() const { return min.x > max.x || min.y > max.y; }
    void extend(const Vec2& p) {
        min = Vec2(std::min(min.x, p.x), std::min(min.y, p.y));
        max = Vec2(std::max(max.x, p.x), std::max(max.y, p.y));
    }
    void extend(const Box2& b) {
        if (!b.is_empty()) {
            extend(b.min);
            extend(b.max);
        }
    }
    /// Grows the box by `d` (scene units) on every side.
    Box2 inflated(double d) const {
        return is_empty() ? *this : Box2{min - Vec2(d), max + Vec2(d)};
    }
    bool overlaps(const Box2& b) const {
        return !is_empty() && !b.is_empty() && min.x <= b.max.x && b.min.x <= max.x &&
               min.y <= b.max.y && b.min.y <= max.y;
    }
    bool contains(const Vec2& p) const {
        return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y;
    }
    Vec2 size() const { return is_empty() ? Vec2(0.0) : max - min; }
};

}  // namespace strata
