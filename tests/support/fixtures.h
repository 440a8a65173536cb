#pragma once
/// @file Generated scenes with known geometry, for the tests of every module.

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"
#include "strata/simplify/scene_families.h"
#include "strata/simplify/simplify.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

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

/// Two open layers, the inner one rolled over the end of the outer one, with waves (the
/// generated `rolled` family's layers are straight lines, whose collinear removals the
/// simplification refuses with or without a roll): inner base y = w(x) on [0, 9], a half
/// circle of radius 1.5 gaps around x = 9, the top back to x = 5 at 3 gaps; the outer layer at
/// 1 gap over [0, 8]; w(x) = 0.3 gap sin 2x; gap = gap_in_segments x 10 / (points - 1).
/// Thickness half the gap (required separation: half the gap).
Scene wavy_roll(std::size_t points, double gap_in_segments);

/// Naive random decimation of `input` (`strata simplify --decimator random --seed N
/// --no-untangle`), as strata_bench_untangle tangles its scenes; `origins`: if given, the input
/// index of every output vertex (inline: only the tests that use it link the simplify module).
inline Scene naive_decimation(const Scene& input, double remove, unsigned seed = 1,
                              std::vector<std::vector<std::size_t>>* origins = nullptr) {
    SimplifyParams naive;
    naive.decimator = "random";
    naive.seed = seed;
    naive.remove = remove;
    naive.untangle = false;
    Scene out = input;
    SimplifyReport report = simplify(out, naive);
    if (origins) *origins = std::move(report.origins);
    return out;
}

/// make_scene(SceneFamily::RolledBoth) with `points` and `gap_in_segments` (inline: only the
/// tests that use it link the simplify module).
inline Scene both_rolled(std::size_t points, double gap_in_segments) {
    FamilyParams p;
    p.points = points;
    p.gap = gap_in_segments;
    return make_scene(SceneFamily::RolledBoth, p);
}

/// make_scene(SceneFamily::ShirtRoll) with `points` and `gap_in_segments`.
inline Scene shirt_rolled_over_jacket(std::size_t points, double gap_in_segments) {
    FamilyParams p;
    p.points = points;
    p.gap = gap_in_segments;
    return make_scene(SceneFamily::ShirtRoll, p);
}

/// make_scene(SceneFamily::CollarWrap) with `points` and `gap_in_segments`: a collar folded
/// around a closed cord over a closed body (layers body, cord, collar).
inline Scene collar_wrapped_cord(std::size_t points, double gap_in_segments) {
    FamilyParams p;
    p.points = points;
    p.gap = gap_in_segments;
    return make_scene(SceneFamily::CollarWrap, p);
}

/// check_scene() of an untangled scene `out` as the untangling tests judge it against the
/// `original` it was decimated from: by the original's outside sides (and the `sides` recorded
/// in it, if given), a separation passing at 0.9 x required.
CheckReport check_against(const Scene& out, const Scene& original,
                          const InputSides* sides = nullptr);

/// check_against() as `strata check OUT --reference ORIG` judges: every vertex of `out` takes
/// the sides recorded in `original` at its vertex nearest to where it ended
/// (InputSides::matched()).
CheckReport check_by_original(const Scene& out, const Scene& original);

/// The largest per-layer symmetric Hausdorff distance between scenes `a` and `b` (layers
/// matched by index), to within `tolerance` (scene units, > 0).
double hausdorff_to(const Scene& a, const Scene& b, double tolerance);

/// tests/data/<name>
std::filesystem::path test_data(const std::string& name);
/// ../shared/data/<name> beside the project, or empty when that folder is absent.
std::filesystem::path shared_data(const std::string& name);

}  // namespace strata::test
