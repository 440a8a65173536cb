// The gap rule of simplify() (SimplifyParams::keep_input_gaps) on layers without thickness.
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/simplify/simplify.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using namespace strata;

namespace {

// Smallest distance from a vertex of one layer to the other layer, both ways.
double pair_gap(const Scene& s, std::size_t a, std::size_t b) {
    double best = std::numeric_limits<double>::infinity();
    for (auto [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
        const Layer& from = s.layer(x);
        const Layer& to = s.layer(y);
        for (const Vec2& p : from.points)
            for (std::size_t i = 0; i + 1 < to.points.size(); ++i) {
                const Vec2 u = to.points[i], v = to.points[i + 1], d = v - u;
                const double t = std::clamp(
                    ((p.x - u.x) * d.x + (p.y - u.y) * d.y) / (d.x * d.x + d.y * d.y), 0.0, 1.0);
                best = std::min(best, std::hypot(p.x - u.x - t * d.x, p.y - u.y - t * d.y));
            }
    }
    return best;
}

}  // namespace

TEST_CASE("simplify keeps 0.9 of the input gaps of layers without thickness", "[simplify][gaps]") {
    const Scene input = folded_stack(3, 400, 10.0, 0.04, 0.0);
    std::vector<double> before;
    for (std::size_t a = 0; a + 1 < input.size(); ++a) before.push_back(pair_gap(input, a, a + 1));

    Scene kept = input;
    SimplifyParams params;
    params.remove = 0.9;
    const SimplifyReport r = simplify(kept, params);
    CHECK(r.collision_free);
    CHECK(r.raised_separations >= 2);
    for (std::size_t a = 0; a + 1 < input.size(); ++a) {
        INFO("pair " << a << ", " << a + 1 << ": " << before[a] << " -> "
                     << pair_gap(kept, a, a + 1));
        CHECK(pair_gap(kept, a, a + 1) >= 0.9 * before[a]);
    }
    // The output scene carries the raised separations, as the final check saw them.
    CHECK(kept.required_separation(0, 1) >= 0.9 * before[0]);

    // Without the rule the layers come much closer (nothing is required between them).
    Scene loose = input;
    params.keep_input_gaps = 0.0;
    const SimplifyReport r0 = simplify(loose, params);
    CHECK(r0.raised_separations == 0);
    CHECK(r0.collision_free);
    double worst = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a + 1 < input.size(); ++a)
        worst = std::min(worst, pair_gap(loose, a, a + 1) / before[a]);
    CHECK(worst < 0.9);

    params.keep_input_gaps = 1.5;
    CHECK_THROWS_AS(validate(params), InvalidInput);
}
