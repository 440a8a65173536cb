#pragma once
/// @file Generated scenes with known geometry, for the tests of every module.

#include "strata/geometry/scene.h"

#include <cstddef>
#include <filesystem>
#include <string>

namespace strata::test {

/// `count` concentric closed circles of radii r0, r0 + dr, ..., each with `points` vertices
/// (a vertex at angle 0), innermost first, one implicit stack.
Scene nested_circles(std::size_t count, std::size_t points, double r0 = 1.0, double dr = 0.25,
                     double thickness = 0.0);

/// `count` open curves y = k * spacing + amplitude * sin(x) over x in [0, 4 pi] with `points`
/// vertices each, innermost (lowest) first, one implicit stack.
Scene stacked_sines(std::size_t count, std::size_t points, double amplitude = 0.3,
                    double spacing = 1.0, double thickness = 0.0);

/// Two open layers that cross properly exactly `crossings` times: the x axis from 0 to
/// crossings + 1 and a zigzag alternating y = +-1 at x = 0.5, 1.5, ... (no vertex on the axis).
Scene crossing_pair(std::size_t crossings);

/// Two closed unit squares side by side sharing the corner (1, 1): one touch, no crossing.
Scene touching_pair();

/// One open Archimedean spiral r = 0.1 + 0.1 * angle / (2 pi) over `turns` turns.
Scene spiral(double turns, std::size_t points);

/// tests/data/<name>
std::filesystem::path test_data(const std::string& name);
/// ../shared/data/<name> beside the project, or empty when that folder is absent.
std::filesystem::path shared_data(const std::string& name);

}  // namespace strata::test
