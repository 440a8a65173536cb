#pragma once
/// @file A layer being decimated by the simplification driver: its vertices by input id, alive
/// ones linked in polyline order. Private to src/simplify.

#include "strata/core/types.h"

#include <cstddef>
#include <limits>
#include <vector>

namespace strata::detail {

/// "No vertex" in WorkLayer::prev / next.
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

// A layer being decimated: a doubly linked list over the input vertex ids.
struct WorkLayer {
    bool closed = false;
    std::vector<Vec2> original, pos;
    std::vector<std::size_t> prev, next;
    std::vector<char> alive, locked;
    std::size_t alive_count = 0, target = 0;
    std::size_t first() const {  // an alive vertex to start walking from
        for (std::size_t i = 0; i < alive.size(); ++i)
            if (alive[i]) return i;
        return kNone;
    }
};

}  // namespace strata::detail
