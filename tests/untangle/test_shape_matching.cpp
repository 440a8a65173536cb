#include "strata/core/error.h"
#include "strata/untangle/shape_matching.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <random>

using namespace strata;

namespace {

std::vector<Vec2> arc_piece(std::size_t n) {
    std::vector<Vec2> points;
    for (std::size_t i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / static_cast<double>(n - 1);
        points.emplace_back(3.0 * t, 0.5 * std::sin(2.0 * t) + 0.2 * t * t);
    }
    return points;
}

Vec2 rigid(const Vec2& p, double angle, const Vec2& shift) {
    return {std::cos(angle) * p.x - std::sin(angle) * p.y + shift.x,
            std::sin(angle) * p.x + std::cos(angle) * p.y + shift.y};
}

double max_distance(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
    double d = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, glm::length(a[i] - b[i]));
    return d;
}

}  // namespace

TEST_CASE("a rigidly moved piece is its own goal", "[untangle][shape_matching]") {
    const std::vector<Vec2> rest = arc_piece(20);
    for (double angle : {0.0, 0.3, -2.5, 3.1}) {
        std::vector<Vec2> current;
        for (const Vec2& p : rest) current.push_back(rigid(p, angle, {1.5, -7.0}));
        const std::vector<Vec2> moved = current;
        for (double beta : {0.0, 0.5, 1.0}) {
            ShapeMatchParams params;
            params.alpha = 1.0;
            params.beta = beta;
            std::vector<Vec2> out = moved;
            const ShapeMatchReport report = shape_match(rest, out, {}, {}, params);
            CHECK(max_distance(out, moved) < 1e-10);
            CHECK(std::remainder(report.rotation - angle, 2.0 * M_PI) == Approx(0.0).margin(1e-12));
            CHECK(report.quadratic_rank == 5);
        }
    }
}

TEST_CASE("a quadratically bent piece is reproduced by the quadratic fit",
          "[untangle][shape_matching]") {
    const std::vector<Vec2> rest = arc_piece(15);
    std::vector<Vec2> bent;
    for (const Vec2& p : rest)  // an arbitrary quadratic map of the plane
        bent.emplace_back(0.9 * p.x + 0.1 * p.y + 0.05 * p.x * p.x - 0.02 * p.x * p.y + 2.0,
                          -0.2 * p.x + 1.1 * p.y + 0.03 * p.y * p.y + 0.07 * p.x * p.x - 1.0);
    ShapeMatchParams params;
    params.alpha = 1.0;
    params.beta = 1.0;
    std::vector<Vec2> out = bent;
    shape_match(rest, out, {}, {}, params);
    CHECK(max_distance(out, bent) < 1e-9);
}

TEST_CASE("a straight piece does not blow up and is bent back", "[untangle][shape_matching]") {
    std::vector<Vec2> rest;
    for (int i = 0; i <= 10; ++i) rest.emplace_back(0.1 * i, 0.0);
    std::vector<Vec2> current = rest;
    current[5].y += 0.05;  // one vertex pushed off the line
    ShapeMatchParams params;
    const ShapeMatchReport report = shape_match(rest, current, {}, {}, params);
    CHECK(report.quadratic_rank == 2);  // qx and qx^2 only
    for (const Vec2& p : current) {
        CHECK(std::isfinite(p.x));
        CHECK(std::isfinite(p.y));
    }
    CHECK(std::abs(current[5].y) < 0.05);  // moved back toward the line
    // Two points: every mode interpolates, so the fit falls back to rigid (beta 0).
    std::vector<Vec2> two_rest{{0, 0}, {1, 0}}, two{{0, 0}, {0, 2}};
    const ShapeMatchReport r2 = shape_match(two_rest, two, {}, {}, params);
    CHECK(r2.quadratic_rank == 1);  // centred, qx^2 is constant
    CHECK(r2.beta_used == 0.0);
    CHECK(glm::length(two[1] - two[0]) == Approx(1.0 + 0.2 * (2.0 - 1.0)).epsilon(1e-9));
}

TEST_CASE("shape matching pulls a noisy piece toward its rest shape",
          "[untangle][shape_matching]") {
    const std::vector<Vec2> rest = arc_piece(40);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::vector<Vec2> truth, current;
    for (const Vec2& p : rest) {
        truth.push_back(rigid(p, 0.4, {1, 2}));
        current.push_back(truth.back() + Vec2(noise(rng), noise(rng)));
    }
    auto rms = [&](const std::vector<Vec2>& x) {
        double sum = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i)
            sum += glm::dot(x[i] - truth[i], x[i] - truth[i]);
        return std::sqrt(sum / static_cast<double>(x.size()));
    };
    const double before = rms(current);
    std::vector<char> fixed(current.size(), 0);
    fixed.front() = fixed.back() = 1;
    const Vec2 first = current.front();
    shape_match(rest, current, {}, fixed, {});
    CHECK(rms(current) < 0.6 * before);  // the fit smooths the noise out
    CHECK(current.front() == first);     // fixed points keep their position
}

TEST_CASE("shape matching rejects bad parameters and sizes", "[untangle][shape_matching]") {
    std::vector<Vec2> rest{{0, 0}, {1, 0}, {0, 1}}, current = rest;
    ShapeMatchParams params;
    params.alpha = 1.5;
    CHECK_THROWS_WITH(shape_match(rest, current, {}, {}, params),
                      Catch::Contains("params.alpha") && Catch::Contains("1.5"));
    CHECK_THROWS_AS(shape_match(rest, current, {1.0, 1.0}, {}, {}), InvalidInput);
    CHECK_THROWS_WITH(shape_match(rest, current, {1.0, 0.0, 1.0}, {}, {}),
                      Catch::Contains("masses[1]"));
}
