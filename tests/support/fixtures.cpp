#include "support/fixtures.h"

#include "strata/geometry/hausdorff.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace strata::test {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

Scene nested_circles(std::size_t count, std::size_t points, double r0, double dr,
                     double thickness) {
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < count; ++k) {
        Layer layer;
        layer.name = "circle_" + std::to_string(k);
        layer.closed = true;
        layer.thickness = thickness;
        const double r = r0 + dr * static_cast<double>(k);
        for (std::size_t i = 0; i < points; ++i) {
            const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(points);
            layer.points.emplace_back(r * std::cos(t), r * std::sin(t));
        }
        layers.push_back(std::move(layer));
    }
    return Scene(std::move(layers));
}

Scene stacked_sines(std::size_t count, std::size_t points, double amplitude, double spacing,
                    double thickness) {
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < count; ++k) {
        Layer layer;
        layer.name = "sine_" + std::to_string(k);
        layer.thickness = thickness;
        for (std::size_t i = 0; i < points; ++i) {
            const double x = 4.0 * kPi * static_cast<double>(i) / static_cast<double>(points - 1);
            layer.points.emplace_back(x,
                                      spacing * static_cast<double>(k) + amplitude * std::sin(x));
        }
        layers.push_back(std::move(layer));
    }
    return Scene(std::move(layers));
}

Scene crossing_pair(std::size_t crossings) {
    Layer line, zigzag;
    line.name = "line";
    line.points = {{0.0, 0.0}, {static_cast<double>(crossings) + 1.0, 0.0}};
    zigzag.name = "zigzag";
    for (std::size_t i = 0; i <= crossings; ++i)
        zigzag.points.emplace_back(static_cast<double>(i) + 0.5, i % 2 == 0 ? 1.0 : -1.0);
    return Scene({line, zigzag});
}

Scene touching_pair() {
    Layer a, b;
    a.name = "left";
    a.closed = true;
    a.points = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    b.name = "right";
    b.closed = true;
    b.points = {{1, 1}, {2, 1}, {2, 2}, {1, 2}};
    a.outer = std::vector<std::string>{};
    b.outer = std::vector<std::string>{};
    return Scene({a, b});
}

Scene spiral(double turns, std::size_t points) {
    Layer layer;
    layer.name = "spiral";
    for (std::size_t i = 0; i < points; ++i) {
        const double t =
            2.0 * kPi * turns * static_cast<double>(i) / static_cast<double>(points - 1);
        const double r = 0.1 + 0.1 * t / (2.0 * kPi);
        layer.points.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return Scene({layer});
}

Scene wavy_roll(std::size_t points, double gap_in_segments) {
    const double s = 10.0 / static_cast<double>(points - 1), g = gap_in_segments * s;
    auto w = [g](double x) { return 0.3 * g * std::sin(2.0 * x); };
    Layer inner, outer;
    inner.name = "inner";
    outer.name = "outer";
    inner.thickness = outer.thickness = 0.5 * g;
    for (double x = 0.0; x <= 8.0 + 1e-9; x += s) outer.points.emplace_back(x, g + w(x));
    for (double x = 0.0; x < 9.0; x += s) inner.points.emplace_back(x, w(x));
    const double r = 1.5 * g;
    const int steps = std::max(4, static_cast<int>(std::ceil(kPi * r / s)));
    for (int j = 1; j < steps; ++j) {
        const double a = -0.5 * kPi + kPi * j / steps;
        inner.points.emplace_back(9.0 + r * std::cos(a), r + r * std::sin(a) + w(9.0));
    }
    for (double x = 9.0; x >= 5.0; x -= s) inner.points.emplace_back(x, 3.0 * g + w(x));
    return Scene({inner, outer});
}

std::filesystem::path test_data(const std::string& name) {
    return std::filesystem::path(STRATA_TEST_DATA_DIR) / name;
}

std::filesystem::path shared_data(const std::string& name) {
    const std::filesystem::path dir(STRATA_SHARED_DATA_DIR);
    if (!std::filesystem::exists(dir)) return {};
    return dir / name;
}

CheckReport check_against(const Scene& out, const Scene& original, const InputSides* sides) {
    CheckParams judged;
    judged.outside_sides = outside_sides(original);
    judged.input_sides = sides;
    judged.separation_tolerance = 0.1;
    return check_scene(out, judged);
}

double hausdorff_to(const Scene& a, const Scene& b, double tolerance) {
    double h = 0.0;
    for (std::size_t l = 0; l < a.size(); ++l)
        h = std::max(h, hausdorff(a.layer(l), b.layer(l), tolerance).symmetric());
    return h;
}

CheckReport check_by_original(const Scene& out, const Scene& original) {
    const InputSides recorded = record_input_sides(original);
    const InputSides matched = InputSides::matched(recorded, original, out);
    return check_against(out, original, &matched);
}

}  // namespace strata::test
