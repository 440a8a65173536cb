#include "strata/geometry/layer.h"

#include <glm/geometric.hpp>

namespace strata {

std::size_t Layer::segment_count() const {
    const std::size_t n = points.size();
    if (n < 2) return 0;
    return closed ? n : n - 1;
}

double Layer::length() const {
    double sum = 0.0;
    for (std::size_t i = 0; i < segment_count(); ++i)
        sum += glm::distance(segment_start(i), segment_end(i));
    return sum;
}

Box2 Layer::bounds() const {
    Box2 box;
    for (const Vec2& p : points) box.extend(p);
    return box;
}

}  // namespace strata
