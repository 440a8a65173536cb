#include "strata/untangle/localize.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>

using namespace strata;

namespace {
std::vector<std::size_t> range(std::size_t a, std::size_t b) {  // [a, b]
    std::vector<std::size_t> out;
    for (std::size_t i = a; i <= b; ++i) out.push_back(i);
    return out;
}
}  // namespace

TEST_CASE("an open layer's run is extended by n_out, clamped at the ends", "[untangle][localize]") {
    Layer line;
    line.name = "line";
    for (int i = 0; i < 30; ++i) line.points.emplace_back(i, 0.0);
    const Scene scene({line});
    const auto pieces = localize(scene, Box2{{9.5, -1}, {12.5, 1}}, 7);  // vertices 10..12
    REQUIRE(pieces.size() == 1);
    CHECK(pieces[0].vertices == range(3, 19));
    for (std::size_t k = 0; k < pieces[0].vertices.size(); ++k)
        CHECK((pieces[0].is_free[k] != 0) ==
              (pieces[0].vertices[k] >= 10 && pieces[0].vertices[k] <= 12));
    const auto start = localize(scene, Box2{{-1, -1}, {1.5, 1}}, 7);  // vertices 0, 1
    REQUIRE(start.size() == 1);
    CHECK(start[0].vertices == range(0, 8));
}

TEST_CASE("a layer entering the box twice gives two pieces, near runs merge",
          "[untangle][localize]") {
    const Scene scene = test::stacked_sines(1, 101, 1.0, 1.0);  // y = sin x over [0, 4 pi]
    // The band y > 0.9 holds two separate runs (around x = pi/2 and 5 pi/2).
    const auto pieces = localize(scene, Box2{{-1, 0.9}, {20, 2}}, 3);
    REQUIRE(pieces.size() == 2);
    for (const Piece& p : pieces) {
        // Never anything beyond the run plus 3 on each side.
        std::size_t first_free = p.vertices.size(), last_free = 0;
        for (std::size_t k = 0; k < p.vertices.size(); ++k)
            if (p.is_free[k]) {
                first_free = std::min(first_free, k);
                last_free = k;
            }
        CHECK(first_free == 3);
        CHECK(p.vertices.size() - 1 - last_free == 3);
    }
    // With a collar wider than the gap between the runs they merge.
    CHECK(localize(scene, Box2{{-1, 0.9}, {20, 2}}, 30).size() == 1);
}

TEST_CASE("closed layers wrap around and may become whole loops", "[untangle][localize]") {
    const Scene scene = test::nested_circles(2, 40, 1.0, 1.0);
    // A box around angle 0 of the inner circle only: vertices 39, 0, 1 are inside.
    const auto pieces = localize(scene, Box2{{0.9, -0.2}, {1.1, 0.2}}, 2);
    REQUIRE(pieces.size() == 1);
    CHECK(pieces[0].layer == 0);
    CHECK(pieces[0].vertices == std::vector<std::size_t>{37, 38, 39, 0, 1, 2, 3});
    CHECK(pieces[0].is_free == std::vector<char>{0, 0, 1, 1, 1, 0, 0});
    CHECK_FALSE(pieces[0].is_whole_loop);
    const auto whole = localize(scene, Box2{{0.9, -0.2}, {1.1, 0.2}}, 20);
    REQUIRE(whole.size() == 1);
    CHECK(whole[0].is_whole_loop);
    CHECK(whole[0].vertices.size() == 40);
}
