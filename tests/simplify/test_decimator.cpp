#include "strata/core/error.h"
#include "strata/simplify/decimator.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace strata;

TEST_CASE("decimator costs", "[simplify][decimator]") {
    const std::vector<Vec2> original{{0, 0}, {1, 0.5}, {2, 0}, {3, 0}, {4, 0}};
    const DecimationView view{original, original, false};
    SECTION("visvalingam is the triangle area") {
        CHECK(make_visvalingam_decimator()->cost(0, view, 0, 1, 2) == Approx(0.5));
        CHECK(make_visvalingam_decimator()->cost(0, view, 2, 3, 4) == 0.0);
    }
    SECTION("max-error is the distance of the span's input vertices to the chord") {
        CHECK(span_error(view, 0, 2) == Approx(0.5));
        CHECK(span_error(view, 0, 4) == Approx(0.5));
        CHECK(span_error(view, 2, 4) == 0.0);
        CHECK(make_max_error_decimator()->cost(0, view, 0, 1, 2) == Approx(0.5));
        const DecimationView loop{original, original, true};
        // Wraps: ids 4 and 0, at 1 and sqrt(1.25) from the chord (3, 0)-(1, 0.5).
        CHECK(span_error(loop, 3, 1) == Approx(std::sqrt(1.25)));
    }
    SECTION("random keys are seeded, deterministic and in [0, 1)") {
        const auto a = make_random_decimator(7), b = make_random_decimator(7),
                   c = make_random_decimator(8);
        int differ = 0;
        for (std::size_t v = 0; v < 100; ++v) {
            const double x = a->cost(1, view, 0, v, 0);
            CHECK(x == b->cost(1, view, 0, v, 0));
            CHECK(x >= 0.0);
            CHECK(x < 1.0);
            differ += x != c->cost(1, view, 0, v, 0);
        }
        CHECK(differ == 100);
    }
    CHECK_THROWS_WITH(make_decimator("qem2", 1), Catch::Contains("unknown name 'qem2'"));
}
