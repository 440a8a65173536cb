#include "strata/simplify/simplify.h"

#include <algorithm>
#include <cmath>

namespace strata {

Scene folded_stack(std::size_t layers, std::size_t points, double width, double spacing,
                   double thickness) {
    if (spacing <= 0.0) {
        constexpr double kSmallestRadius = 0.268;  // of the folded curve (found numerically)
        spacing = layers > 1
                      ? std::min(0.04, 0.8 * kSmallestRadius / static_cast<double>(layers - 1))
                      : 0.04;
    }
    std::vector<Layer> out;
    for (std::size_t k = 0; k < layers; ++k) {
        Layer layer;
        layer.name = "layer_" + std::to_string(k);
        layer.thickness = thickness;
        const double offset = spacing * static_cast<double>(k);
        for (std::size_t i = 0; i < points; ++i) {
            const double x = width * static_cast<double>(i) / static_cast<double>(points - 1);
            const double y =
                0.5 * std::sin(0.6 * x) + 0.18 * std::sin(2.3 * x + 0.5) + 0.07 * std::sin(6.1 * x);
            const double slope = 0.3 * std::cos(0.6 * x) + 0.414 * std::cos(2.3 * x + 0.5) +
                                 0.427 * std::cos(6.1 * x);
            const double len = std::sqrt(1.0 + slope * slope);
            layer.points.emplace_back(x - offset * slope / len, y + offset / len);
        }
        out.push_back(std::move(layer));
    }
    return Scene(std::move(out));
}

Scene demo_scene(std::size_t points) {
    const Scene stack = folded_stack(5, points);
    return Scene(stack.layers(), "dm");
}

}  // namespace strata
