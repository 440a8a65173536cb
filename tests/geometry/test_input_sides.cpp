// InputSides::by_region() (issue 19): sides recorded in a tangled scene, made consistent per
// region of each layer.
#include "strata/core/error.h"
#include "strata/geometry/input_sides.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

#include <cstddef>
#include <vector>

using namespace strata;

namespace {

// Every recorded side of `a` equals that of `b` (same scene shape).
std::size_t differences(const InputSides& a, const InputSides& b, const Scene& scene) {
    std::size_t count = 0;
    for (std::size_t l = 0; l < scene.size(); ++l)
        for (std::size_t k = 0; k < scene.layer(l).points.size(); ++k)
            for (std::size_t m = 0; m < scene.size(); ++m)
                if (a.side(l, k, m) != b.side(l, k, m) ||
                    a.beyond_end(l, k, m) != b.beyond_end(l, k, m))
                    ++count;
    return count;
}

}  // namespace

TEST_CASE("sides by region: a roll is kept, a vertex a tangle put across takes its region's",
          "[rolled][input_sides]") {
    const std::size_t points = 300;
    const Scene input = test::wavy_roll(points, 2.0);
    const double g = 2.0 * 10.0 / static_cast<double>(points - 1);
    const InputSides recorded = record_input_sides(input);
    // Untangled: nothing to change (the roll is a region of its own, around the outer's end).
    CHECK(differences(recorded.by_region(input), recorded, input) == 0);
    CHECK(differences(infer_input_sides(input), recorded, input) == 0);

    // Three base vertices of the inner layer lifted over the outer one (their segments cross
    // it): recorded on the other side, like the roll's top, but in the base's region.
    std::vector<Layer> layers = input.layers();
    const std::vector<std::size_t> lifted = {100, 101, 102};
    for (std::size_t k : lifted) layers[0].points[k].y = 2.0 * g;
    const Scene tangled(layers);
    const InputSides raw = record_input_sides(tangled);
    for (std::size_t k : lifted) {
        REQUIRE(raw.side(0, k, 1) != 0);
        REQUIRE(raw.side(0, k, 1) == -recorded.side(0, k, 1));
    }
    const InputSides fixed = raw.by_region(tangled);
    for (std::size_t k : lifted) CHECK(fixed.side(0, k, 1) == recorded.side(0, k, 1));
    // Everything else as in the untangled input: the roll's top keeps its side.
    std::size_t top = 0;
    for (std::size_t k = 0; k < input.layer(0).points.size(); ++k) {
        CHECK(fixed.side(0, k, 1) == recorded.side(0, k, 1));
        if (input.layer(0).points[k].y > 2.5 * g && recorded.side(0, k, 1) != 0) ++top;
    }
    CHECK(top > 0);

    CHECK_THROWS_AS(raw.by_region(Scene({layers[0]})), InvalidInput);
}

TEST_CASE("without_end_sides: the vertices around an end lose it, the others keep their side",
          "[rolled][input_sides]") {
    const Scene input = test::wavy_roll(300, 2.0);
    const InputSides recorded = record_input_sides(input);
    const InputSides dropped = recorded.without_end_sides(input);
    std::size_t around = 0, sided = 0;
    for (std::size_t l = 0; l < input.size(); ++l)
        for (std::size_t k = 0; k < input.layer(l).points.size(); ++k)
            for (std::size_t m = 0; m < input.size(); ++m) {
                CHECK_FALSE(dropped.beyond_end(l, k, m));
                CHECK(dropped.side(l, k, m) == recorded.side(l, k, m));
                if (recorded.beyond_end(l, k, m)) ++around;
                if (recorded.side(l, k, m) != 0) ++sided;
            }
    // The roll's bend goes around the outer layer's end; both sides are read elsewhere.
    CHECK(around > 0);
    CHECK(sided > 0);
    CHECK(InputSides().without_end_sides(input).empty());
    CHECK_THROWS_AS(recorded.without_end_sides(Scene({input.layer(0)})), InvalidInput);
}
