#include "strata/simplify/simplify.h"

#include <cmath>

namespace strata {

Scene demo_scene(std::size_t points) {
    // Five cloth layers offset along the normal of one folded base curve (after the paper's
    // Fig. 1): where the folds bend, the layers are close, and a decimation that cuts a fold's
    // corner cuts into the neighbouring layer.
    constexpr double kPi = 3.14159265358979323846;
    const double spacing = 0.04;
    auto base = [&](double x) {
        return 0.5 * std::sin(0.6 * x) + 0.18 * std::sin(2.3 * x + 0.5) + 0.07 * std::sin(6.1 * x);
    };
    auto slope = [&](double x) {
        return 0.3 * std::cos(0.6 * x) + 0.414 * std::cos(2.3 * x + 0.5) +
               0.427 * std::cos(6.1 * x);
    };
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < 5; ++k) {
        Layer layer;
        layer.name = "layer_" + std::to_string(k);
        layer.thickness = 0.01;
        for (std::size_t i = 0; i < points; ++i) {
            const double x = 10.0 * static_cast<double>(i) / static_cast<double>(points - 1);
            const double d = slope(x), len = std::sqrt(1.0 + d * d);
            const double offset = spacing * static_cast<double>(k);
            layer.points.emplace_back(x - offset * d / len, base(x) + offset / len);
        }
        layers.push_back(std::move(layer));
    }
    (void)kPi;
    return Scene(std::move(layers), "dm");
}

}  // namespace strata
