// The vertex budget of simplify() on real slices: a run that leaves a layer above its target
// removes what the exact check of the whole scene allows, then trims ends of open layers
// (SimplifyParams::trim_ends); a run that meets every target is not changed by it.
#include "strata/geometry/checks.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

using namespace strata;

namespace {

// The real slices of issue 13 (tests/data/slices, copies of ../shared/data/slices).
std::vector<std::filesystem::path> real_slices() {
    std::vector<std::filesystem::path> paths;
    const std::filesystem::path dir = test::test_data("slices");
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        if (entry.path().extension() == ".json") paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    return paths;
}

std::size_t vertices(const Scene& s) {
    std::size_t n = 0;
    for (const Layer& l : s.layers()) n += l.points.size();
    return n;
}

}  // namespace

TEST_CASE("simplify meets the vertex budget of the real slices at 90-98%", "[simplify][budget]") {
    const std::vector<std::filesystem::path> paths = real_slices();
    REQUIRE(paths.size() == 8);
    for (const auto& path : paths) {
        const Scene input = read_scene(path);
        if (!check_scene(input).is_collision_free()) continue;  // untangled first by the CLI
        for (const double remove : {0.9, 0.95, 0.98}) {
            CAPTURE(path.filename().string(), remove);
            Scene scene = input;
            SimplifyParams params;
            params.remove = remove;
            const SimplifyReport report = simplify(scene, params);
            CHECK(report.collision_free);
            CHECK(report.targets_met);
            std::size_t target = 0;
            for (const LayerSimplifyReport& l : report.layers) target += l.target;
            CHECK(vertices(scene) <= target);
            // The gap rule holds (the separations it raised are part of the check).
            CHECK(report.min_separation_ratio >= 0.9);
        }
    }
}

TEST_CASE("trim_ends: an open piece bent around another keeps its ends only when asked",
          "[simplify][budget]") {
    const Scene input = read_scene(test::test_data("slices/mh_casualsuit05_y+4.00.json"));
    SimplifyParams params;
    params.remove = 0.9;
    params.trim_ends = false;
    Scene kept = input;
    const SimplifyReport with_ends = simplify(kept, params);
    CHECK(with_ends.collision_free);
    CHECK(with_ends.trimmed_ends == 0);
    // Every open layer keeps its two input ends.
    for (std::size_t l = 0; l < input.size(); ++l)
        if (!input.layer(l).closed) {
            CHECK(with_ends.origins[l].front() == 0);
            CHECK(with_ends.origins[l].back() == input.layer(l).points.size() - 1);
        }
    // This slice's lapel is a hairpin around the end of another piece: no 2-vertex piece
    // between its ends is clear, so with its ends kept a layer stays above its target.
    CHECK_FALSE(with_ends.targets_met);

    params.trim_ends = true;
    Scene trimmed = input;
    const SimplifyReport report = simplify(trimmed, params);
    CHECK(report.collision_free);
    CHECK(report.targets_met);
    CHECK(report.trimmed_ends >= 1);
    // Only layers that were above their target changed.
    for (std::size_t l = 0; l < input.size(); ++l)
        if (with_ends.layers[l].after <= with_ends.layers[l].target)
            CHECK(trimmed.layer(l).points == kept.layer(l).points);
}

TEST_CASE("trim_ends changes nothing in a run that meets every target", "[simplify][budget]") {
    const Scene input = test::stacked_sines(4, 400);
    for (const double remove : {0.9, 0.98}) {
        CAPTURE(remove);
        SimplifyParams params;
        params.remove = remove;
        Scene a = input, b = input;
        const SimplifyReport ra = simplify(a, params);
        params.trim_ends = false;
        simplify(b, params);
        REQUIRE(ra.targets_met);
        CHECK(ra.trimmed_ends == 0);
        for (std::size_t l = 0; l < input.size(); ++l)
            CHECK(a.layer(l).points == b.layer(l).points);
    }
}

TEST_CASE("the budget steps leave max_error's bound alone", "[simplify][budget]") {
    // With max_error a layer stays above its target where the bound says so: no whole-scene
    // removal nor trimmed end (neither bounds the error).
    const Scene input = read_scene(test::test_data("slices/mh_casualsuit05_y+4.00.json"));
    SimplifyParams params;
    params.remove = 1.0;
    params.max_error = 0.05;
    Scene a = input, b = input;
    const SimplifyReport ra = simplify(a, params);
    params.trim_ends = false;
    simplify(b, params);
    CHECK(ra.collision_free);
    CHECK_FALSE(ra.targets_met);
    CHECK(ra.trimmed_ends == 0);
    for (std::size_t l = 0; l < input.size(); ++l) {
        CHECK(a.layer(l).points == b.layer(l).points);
        if (!input.layer(l).closed) {
            CHECK(a.layer(l).points.front() == input.layer(l).points.front());
            CHECK(a.layer(l).points.back() == input.layer(l).points.back());
        }
    }
}
