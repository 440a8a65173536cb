#include "strata/core/error.h"
#include "strata/untangle/composition.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <vector>

// Counts the allocations made through operator new, to check that a warmed-up Composer's
// chain paths do not allocate. Not inlined, so that GCC does not pair malloc and delete.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

[[gnu::noinline]] void* operator new(std::size_t size) {
    ++g_allocations;
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    ++g_allocations;
    return std::malloc(size == 0 ? 1 : size);
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
    std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, const std::nothrow_t&) noexcept {
    std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}

using namespace strata;
using Catch::Matchers::Contains;

namespace {

using Vector = std::vector<double>;
using Constraints = std::vector<CompositionConstraint>;

CompositionConstraint under(std::size_t a, std::size_t b, double s) {
    return {a, b, false, s};
}
CompositionConstraint beside(std::size_t a, std::size_t b, double s) {
    return {a, b, true, s};
}

Constraints chain_constraints(const Vector& separations) {
    Constraints out;
    for (std::size_t i = 0; i < separations.size(); ++i)
        out.push_back(under(i, i + 1, separations[i]));
    return out;
}

double value_of(const CompositionConstraint& c, const Vector& y) {
    return c.side_by_side ? y[c.a] + y[c.b] : y[c.a] - y[c.b];
}

double cost(const Vector& y, const Vector& f, const Vector& w) {
    double sum = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) sum += w[k] * (y[k] - f[k]) * (y[k] - f[k]);
    return sum;
}

/// Weighted antitonic regression by enumeration: every partition of 0..K-1 into contiguous
/// blocks, block values the weighted means, keep the non-increasing one of least cost.
Vector brute_force_antitonic(const Vector& g, const Vector& w) {
    const std::size_t k = g.size();
    Vector best;
    double best_cost = std::numeric_limits<double>::infinity();
    for (unsigned cuts = 0; cuts < (1u << (k - 1)); ++cuts) {
        Vector y(k);
        std::size_t begin = 0;
        bool is_monotone = true;
        double previous = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < k; ++i) {
            const bool is_end = i + 1 == k || (cuts >> i & 1u) != 0;
            if (!is_end) continue;
            double sw = 0.0, swg = 0.0;
            for (std::size_t j = begin; j <= i; ++j) {
                sw += w[j];
                swg += w[j] * g[j];
            }
            const double mean = swg / sw;
            if (mean > previous) is_monotone = false;
            previous = mean;
            for (std::size_t j = begin; j <= i; ++j) y[j] = mean;
            begin = i + 1;
        }
        if (!is_monotone) continue;
        const double c = cost(y, g, w);
        if (c < best_cost) {
            best_cost = c;
            best = y;
        }
    }
    return best;
}

/// Solves the dense n x n system a x = b by Gaussian elimination with partial pivoting;
/// false when a pivot is below `eps` (singular).
bool solve_dense(std::vector<Vector> a, Vector b, Vector& x, double eps) {
    const std::size_t n = b.size();
    for (std::size_t c = 0; c < n; ++c) {
        std::size_t pivot = c;
        for (std::size_t r = c + 1; r < n; ++r) {
            if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
        }
        if (std::abs(a[pivot][c]) < eps) return false;
        std::swap(a[c], a[pivot]);
        std::swap(b[c], b[pivot]);
        for (std::size_t r = c + 1; r < n; ++r) {
            const double factor = a[r][c] / a[c][c];
            for (std::size_t j = c; j < n; ++j) a[r][j] -= factor * a[c][j];
            b[r] -= factor * b[c];
        }
    }
    x.assign(n, 0.0);
    for (std::size_t r = n; r-- > 0;) {
        double sum = b[r];
        for (std::size_t j = r + 1; j < n; ++j) sum -= a[r][j] * x[j];
        x[r] = sum / a[r][r];
    }
    return true;
}

/// The weighted projection by enumeration of active sets: for every subset S with a
/// non-singular Gram matrix, solve the KKT system on S; keep the feasible one with multipliers
/// >= 0 of least cost.
Vector brute_force_projection(const Vector& f, const Vector& w, const Constraints& constraints) {
    const std::size_t m = constraints.size();
    const std::size_t k = f.size();
    Vector best;
    double best_cost = std::numeric_limits<double>::infinity();
    for (unsigned subset = 0; subset < (1u << m); ++subset) {
        std::vector<std::size_t> s;
        for (std::size_t i = 0; i < m; ++i) {
            if ((subset >> i & 1u) != 0) s.push_back(i);
        }
        // Row i of A: +1 at a, -1 (under) or +1 (beside) at b.
        auto row = [&](std::size_t i) {
            Vector r(k, 0.0);
            r[constraints[i].a] += 1.0;
            r[constraints[i].b] += constraints[i].side_by_side ? 1.0 : -1.0;
            return r;
        };
        std::vector<Vector> gram(s.size(), Vector(s.size(), 0.0));
        Vector rhs(s.size());
        for (std::size_t p = 0; p < s.size(); ++p) {
            const Vector rp = row(s[p]);
            for (std::size_t q = 0; q < s.size(); ++q) {
                const Vector rq = row(s[q]);
                for (std::size_t j = 0; j < k; ++j) gram[p][q] += rp[j] * rq[j] / w[j];
            }
            rhs[p] = constraints[s[p]].separation - value_of(constraints[s[p]], f);
        }
        Vector lambda;
        if (!solve_dense(gram, rhs, lambda, 1e-9)) continue;
        if (std::any_of(lambda.begin(), lambda.end(), [](double l) { return l < -1e-9; })) continue;
        Vector y = f;
        for (std::size_t p = 0; p < s.size(); ++p) {
            const Vector rp = row(s[p]);
            for (std::size_t j = 0; j < k; ++j) y[j] += lambda[p] * rp[j] / w[j];
        }
        bool is_feasible = true;
        for (const CompositionConstraint& c : constraints) {
            if (value_of(c, y) < c.separation - 1e-9) is_feasible = false;
        }
        if (!is_feasible) continue;
        const double c = cost(y, f, w);
        if (c < best_cost) {
            best_cost = c;
            best = y;
        }
    }
    return best;
}

struct Random {
    std::mt19937 engine{20230917u};
    double uniform(double lo, double hi) {
        return std::uniform_real_distribution<double>(lo, hi)(engine);
    }
    std::size_t index(std::size_t n) {
        return std::uniform_int_distribution<std::size_t>(0, n - 1)(engine);
    }
    Vector values(std::size_t n, double lo, double hi) {
        Vector v(n);
        for (double& x : v) x = uniform(lo, hi);
        return v;
    }
    /// Weights spread over three decades.
    Vector weights(std::size_t n) {
        Vector v(n);
        for (double& x : v) x = std::pow(10.0, uniform(-1.0, 2.0));
        return v;
    }
};

/// Random acyclic constraint set on k layers: "under" only from a lower to a higher index,
/// some pairs side by side.
Constraints random_constraints(Random& rng, std::size_t k, std::size_t m) {
    Constraints out;
    while (out.size() < m) {
        std::size_t a = rng.index(k), b = rng.index(k);
        if (a == b) continue;
        if (a > b) std::swap(a, b);
        const double s = rng.uniform(0.0, 0.3);
        out.push_back(rng.uniform(0.0, 1.0) < 0.3 ? beside(a, b, s) : under(a, b, s));
    }
    return out;
}

/// Central finite differences of fhat with respect to f_j, compared with column j of P, where
/// the active set is the same at f, f + h e_j and f - h e_j (elsewhere fhat has a kink).
/// Returns the number of columns compared.
int check_finite_differences(const Vector& f, const Vector& w, const Constraints& constraints,
                             const CompositionParams& params) {
    const double h = 1e-6;
    const CompositionResult at = compose(f, w, constraints, params);
    int compared = 0;
    for (std::size_t j = 0; j < f.size(); ++j) {
        Vector fp = f, fm = f;
        fp[j] += h;
        fm[j] -= h;
        const CompositionResult plus = compose(fp, w, constraints, params);
        const CompositionResult minus = compose(fm, w, constraints, params);
        if (plus.active != at.active || minus.active != at.active) continue;
        ++compared;
        for (std::size_t k = 0; k < f.size(); ++k) {
            const double derivative = (plus.fhat[k] - minus.fhat[k]) / (2.0 * h);
            CHECK(derivative == Approx(at.coefficient(k, j)).margin(1e-6));
        }
    }
    return compared;
}

}  // namespace

TEST_CASE("chain composition matches brute-force antitonic regression", "[untangle][composition]") {
    Random rng;
    Composer composer;
    for (int trial = 0; trial < 3000; ++trial) {
        const std::size_t k = 1 + rng.index(8);
        const Vector f = rng.values(k, -1.0, 1.0);
        const Vector w = rng.weights(k);
        const Vector s = rng.values(k - 1, 0.0, 0.3);
        Vector offset(k, 0.0), g(k);
        for (std::size_t i = k - 1; i-- > 0;) offset[i] = offset[i + 1] + s[i];
        for (std::size_t i = 0; i < k; ++i) g[i] = f[i] - offset[i];
        const Vector expected = brute_force_antitonic(g, w);

        const CompositionResult& chain = composer.compose_chain(f, w, s);
        REQUIRE(chain.is_exact());
        CHECK(chain.method == CompositionMethod::Chain);
        for (std::size_t i = 0; i < k; ++i) {
            CHECK(chain.fhat[i] == Approx(expected[i] + offset[i]).margin(1e-12));
        }
        // The same through compose(): the constraints are detected as a chain.
        const CompositionResult general = compose(f, w, chain_constraints(s));
        CHECK(general.method == CompositionMethod::Chain);
        CHECK(general.fhat == composer.result().fhat);
    }
}

TEST_CASE("two layers: the closed form", "[untangle][composition]") {
    const double s = 0.1;
    const std::vector<std::pair<Vector, Vector>> cases{
        {{0.3, 0.5}, {1.0, 1.0}}, {{0.3, 0.5}, {1.0, 3.0}},  {{-0.2, 0.4}, {5.0, 0.5}},
        {{0.5, 0.3}, {1.0, 1.0}}, {{0.15, 0.1}, {2.0, 1.0}}, {{0.0, 0.0}, {1.0, 1.0}}};
    for (const auto& [f, w] : cases) {
        const double m = (w[0] * (f[0] - s) + w[1] * f[1]) / (w[0] + w[1]);
        const CompositionResult r = compose_chain(f, w, {s});
        CHECK(r.fhat[0] == Approx(std::max(f[0], m + s)).margin(1e-15));
        CHECK(r.fhat[1] == Approx(std::min(f[1], m)).margin(1e-15));
        CHECK(r.fhat[0] - r.fhat[1] >= s - 1e-15);
    }
}

TEST_CASE("nothing changes where the order holds", "[untangle][composition]") {
    Random rng;
    CompositionParams general_params;
    general_params.use_chain_fast_path = false;
    Composer chain, general(general_params);
    for (int trial = 0; trial < 500; ++trial) {
        const std::size_t k = 1 + rng.index(8);
        const Vector s = rng.values(k - 1, 0.0, 0.3);
        Vector f(k);
        f[k - 1] = rng.uniform(-1.0, 1.0);
        for (std::size_t i = k - 1; i-- > 0;) f[i] = f[i + 1] + s[i] + rng.uniform(0.0, 0.2);
        const Vector w = rng.weights(k);
        for (const CompositionResult* r :
             {&chain.compose_chain(f, w, s), &general.compose(f, w, chain_constraints(s))}) {
            CHECK(r->fhat == f);
            CHECK(r->active.empty());
            CHECK(r->residual == 0.0);
            for (std::size_t a = 0; a < k; ++a) {
                for (std::size_t b = 0; b < k; ++b)
                    CHECK(r->coefficient(a, b) == (a == b ? 1.0 : 0.0));
            }
            for (double l : r->multipliers) CHECK(l == 0.0);
        }
    }
}

TEST_CASE("chain separations always hold and pooled layers move to weighted means",
          "[untangle][composition]") {
    Random rng;
    Composer composer;
    for (int trial = 0; trial < 2000; ++trial) {
        const std::size_t k = 2 + rng.index(7);
        const Vector f = rng.values(k, -1.0, 1.0);
        const Vector w = rng.weights(k);
        const Vector s = rng.values(k - 1, 0.0, 0.3);
        const CompositionResult& r = composer.compose_chain(f, w, s);
        for (std::size_t i = 0; i + 1 < k; ++i) CHECK(r.fhat[i] - r.fhat[i + 1] >= s[i] - 1e-12);
        CHECK(r.residual <= 1e-12);
        // Blocks: maximal runs joined by active links. P_kj = w_j / W_B inside a block, 0 out.
        std::vector<std::size_t> block(k, 0);
        for (std::size_t i = 1; i < k; ++i) {
            const bool is_joined =
                std::find(r.active.begin(), r.active.end(), i - 1) != r.active.end();
            block[i] = is_joined ? block[i - 1] : block[i - 1] + 1;
        }
        for (std::size_t a = 0; a < k; ++a) {
            double total = 0.0, row_sum = 0.0;
            for (std::size_t j = 0; j < k; ++j) total += block[j] == block[a] ? w[j] : 0.0;
            for (std::size_t j = 0; j < k; ++j) {
                const double expected = block[j] == block[a] ? w[j] / total : 0.0;
                CHECK(r.coefficient(a, j) == Approx(expected).margin(1e-14));
                row_sum += r.coefficient(a, j);
            }
            CHECK(row_sum == Approx(1.0));
        }
        // Inside a block the multipliers are positive, between blocks zero.
        for (std::size_t i = 0; i + 1 < k; ++i) {
            if (block[i] == block[i + 1]) {
                CHECK(r.multipliers[i] > 0.0);
            } else {
                CHECK(r.multipliers[i] == 0.0);
            }
        }
    }
}

TEST_CASE("a heavier layer moves less", "[untangle][composition]") {
    // Layer 0 should be 0.1 outside... under layer 1 but is 0.2 past it.
    const Vector f{0.0, 0.2};
    const CompositionResult equal = compose_chain(f, {1.0, 1.0}, {0.1});
    CHECK(equal.fhat[0] - f[0] == Approx(0.15));
    CHECK(f[1] - equal.fhat[1] == Approx(0.15));
    const CompositionResult heavy = compose_chain(f, {1.0, 1000.0}, {0.1});
    const double moved0 = heavy.fhat[0] - f[0];
    const double moved1 = f[1] - heavy.fhat[1];
    CHECK(moved1 < 0.001);
    CHECK(moved1 / moved0 == Approx(1.0 / 1000.0));
    CHECK(heavy.fhat[0] - heavy.fhat[1] == Approx(0.1));
    // Gradients: grad fhat = weighted mean, dominated by the heavy layer.
    CHECK(heavy.coefficient(0, 1) == Approx(1000.0 / 1001.0));
}

TEST_CASE("general solver equals chain solver on chains", "[untangle][composition]") {
    Random rng;
    CompositionParams params;
    params.use_chain_fast_path = false;
    Composer chain, general(params);
    for (int trial = 0; trial < 2000; ++trial) {
        const std::size_t k = 1 + rng.index(10);
        const Vector f = rng.values(k, -1.0, 1.0);
        const Vector w = rng.weights(k);
        const Vector s = rng.values(k - 1, 0.0, 0.3);
        const CompositionResult& c = chain.compose_chain(f, w, s);
        const CompositionResult& g = general.compose(f, w, chain_constraints(s));
        REQUIRE(g.is_exact());
        CHECK(g.method == CompositionMethod::ActiveSet);
        CHECK(g.active == c.active);
        for (std::size_t i = 0; i < k; ++i) CHECK(g.fhat[i] == Approx(c.fhat[i]).margin(1e-12));
        for (std::size_t i = 0; i < k * k; ++i) {
            CHECK(g.gradient_coefficients[i] == Approx(c.gradient_coefficients[i]).margin(1e-12));
        }
        for (std::size_t i = 0; i + 1 < k; ++i) {
            CHECK(g.multipliers[i] == Approx(c.multipliers[i]).margin(1e-9));
        }
    }
}

TEST_CASE("two loops side by side inside a third match the brute-force projection",
          "[untangle][composition]") {
    // 0 and 1: two legs, side by side, both under 2: a skirt.
    Random rng;
    Composer composer;
    int active_beside = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const Constraints constraints{under(0, 2, rng.uniform(0.0, 0.2)),
                                      under(1, 2, rng.uniform(0.0, 0.2)),
                                      beside(0, 1, rng.uniform(0.0, 0.2))};
        const Vector f = rng.values(3, -0.5, 0.5);
        const Vector w = rng.weights(3);
        const CompositionResult& r = composer.compose(f, w, constraints);
        REQUIRE(r.is_exact());
        CHECK(r.method == CompositionMethod::ActiveSet);
        const Vector expected = brute_force_projection(f, w, constraints);
        REQUIRE(expected.size() == 3);
        for (std::size_t k = 0; k < 3; ++k) CHECK(r.fhat[k] == Approx(expected[k]).margin(1e-10));
        CHECK(r.residual <= 1e-12);
        CHECK(r.fhat[0] + r.fhat[1] >= constraints[2].separation - 1e-12);
        if (std::find(r.active.begin(), r.active.end(), 2u) != r.active.end()) ++active_beside;
    }
    CHECK(active_beside > 100);
}

TEST_CASE("general solver matches the brute-force projection on random constraint sets",
          "[untangle][composition]") {
    Random rng;
    Composer composer;
    for (int trial = 0; trial < 1500; ++trial) {
        const std::size_t k = 2 + rng.index(4);
        const std::size_t m = 1 + rng.index(std::min<std::size_t>(9, k * (k - 1)));
        const Constraints constraints = random_constraints(rng, k, m);
        const Vector f = rng.values(k, -0.5, 0.5);
        const Vector w = rng.weights(k);
        const CompositionResult& r = composer.compose(f, w, constraints);
        REQUIRE(r.is_exact());
        const Vector expected = brute_force_projection(f, w, constraints);
        REQUIRE(expected.size() == k);
        for (std::size_t j = 0; j < k; ++j) CHECK(r.fhat[j] == Approx(expected[j]).margin(1e-9));
        CHECK(r.residual <= 1e-12);
        for (double l : r.multipliers) CHECK(l >= 0.0);
    }
}

TEST_CASE("gradient coefficients match finite differences", "[untangle][composition]") {
    Random rng;
    CompositionParams general;
    general.use_chain_fast_path = false;
    int compared = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const std::size_t k = 2 + rng.index(5);
        const Vector f = rng.values(k, -0.5, 0.5);
        const Vector w = rng.weights(k);
        compared +=
            check_finite_differences(f, w, random_constraints(rng, k, 1 + rng.index(6)), {});
        compared +=
            check_finite_differences(f, w, chain_constraints(rng.values(k - 1, 0.0, 0.3)), general);
        compared +=
            check_finite_differences(f, w, chain_constraints(rng.values(k - 1, 0.0, 0.3)), {});
    }
    CHECK(compared > 2000);
}

TEST_CASE("redundant and degenerate constraints do not blow up", "[untangle][composition]") {
    CompositionParams general;
    general.use_chain_fast_path = false;

    SECTION("an implied constraint keeps the chain path; a tight redundant one the same answer") {
        const Vector f{0.0, 0.3, 0.1};
        const Vector w{1.0, 2.0, 3.0};
        const Constraints constraints{under(0, 1, 0.1), under(1, 2, 0.2), under(0, 2, 0.3)};
        const CompositionResult fast = compose(f, w, constraints);
        CHECK(fast.method == CompositionMethod::Chain);
        const CompositionResult exact = compose(f, w, constraints, general);
        REQUIRE(exact.is_exact());
        const CompositionResult plain = compose_chain(f, w, {0.1, 0.2});
        for (std::size_t k = 0; k < 3; ++k) {
            CHECK(fast.fhat[k] == plain.fhat[k]);
            CHECK(exact.fhat[k] == Approx(plain.fhat[k]).margin(1e-12));
            for (std::size_t j = 0; j < 3; ++j) {
                CHECK(exact.coefficient(k, j) == Approx(plain.coefficient(k, j)).margin(1e-12));
            }
        }
        // A stronger non-consecutive constraint is not implied: the general solver takes over.
        const Constraints stronger{under(0, 1, 0.1), under(1, 2, 0.2), under(0, 2, 0.5)};
        const CompositionResult r = compose(f, w, stronger);
        CHECK(r.method == CompositionMethod::ActiveSet);
        REQUIRE(r.is_exact());
        CHECK(r.fhat[0] - r.fhat[2] == Approx(0.5));
    }
    SECTION("duplicated constraints") {
        const Vector f{0.0, 0.3};
        const Constraints twice{under(0, 1, 0.1), under(0, 1, 0.1), under(0, 1, 0.05)};
        const CompositionResult r = compose(f, {1.0, 1.0}, twice, general);
        REQUIRE(r.is_exact());
        CHECK(r.fhat[0] == Approx(0.2));
        CHECK(r.fhat[1] == Approx(0.1));
        CHECK(r.active.size() == 1);
        CHECK(r.coefficient(0, 0) == Approx(0.5));
        const CompositionResult fast = compose(f, {1.0, 1.0}, twice);
        CHECK(fast.method == CompositionMethod::Chain);
        CHECK(fast.fhat[0] == Approx(0.2));
    }
    SECTION("opposite constraints with zero separation force equality") {
        const Vector f{0.0, 0.3};
        const Vector w{1.0, 2.0};
        const CompositionResult r = compose(f, w, {under(0, 1, 0.0), under(1, 0, 0.0)});
        REQUIRE(r.is_exact());
        CHECK(r.fhat[0] == Approx(0.2));
        CHECK(r.fhat[1] == Approx(0.2));
        CHECK(r.coefficient(0, 1) == Approx(2.0 / 3.0));
    }
    SECTION("equal values and zero separations are a tie: nothing moves") {
        const CompositionResult r = compose_chain({0.1, 0.1, 0.1}, {1.0, 1.0, 1.0}, {0.0, 0.0});
        CHECK(r.fhat == Vector{0.1, 0.1, 0.1});
        const CompositionResult g =
            compose({0.1, 0.1, 0.1}, {1.0, 1.0, 1.0}, chain_constraints({0.0, 0.0}), general);
        REQUIRE(g.is_exact());
        CHECK(g.fhat == Vector{0.1, 0.1, 0.1});
    }
    SECTION("weights twelve decades apart") {
        const Vector f{0.0, 0.2, 0.1};
        const Vector w{1e-6, 1e6, 1.0};
        const CompositionResult c = compose_chain(f, w, {0.1, 0.1});
        const CompositionResult g = compose(f, w, chain_constraints({0.1, 0.1}), general);
        REQUIRE(g.is_exact());
        for (std::size_t k = 0; k < 3; ++k) {
            CHECK(std::isfinite(g.fhat[k]));
            CHECK(g.fhat[k] == Approx(c.fhat[k]).margin(1e-9));
        }
        CHECK(c.fhat[1] == Approx(0.2).margin(1e-6));
    }
    SECTION("one layer, and layers without constraints") {
        const CompositionResult one = compose({0.4}, {2.0}, {});
        CHECK(one.fhat == Vector{0.4});
        CHECK(one.coefficient(0, 0) == 1.0);
        const CompositionResult none = compose({0.4, -0.3, 0.0}, {1.0, 1.0, 1.0}, {});
        CHECK(none.method == CompositionMethod::ActiveSet);
        CHECK(none.fhat == Vector{0.4, -0.3, 0.0});
    }
    SECTION("every pair constrained among six layers, side by side included") {
        Random rng;
        for (int trial = 0; trial < 50; ++trial) {
            Constraints all;
            for (std::size_t a = 0; a < 6; ++a) {
                for (std::size_t b = a + 1; b < 6; ++b) {
                    const double s = rng.uniform(0.0, 0.1);
                    all.push_back((a + b) % 4 == 1 ? beside(a, b, s) : under(a, b, s));
                }
            }
            const Vector f = rng.values(6, -0.3, 0.3);
            const CompositionResult r = compose(f, rng.weights(6), all);
            REQUIRE(r.is_exact());
            CHECK(r.residual <= 1e-12);
            CHECK(r.active.size() <= 6);
        }
    }
    SECTION("an infeasible cycle is reported, not hidden") {
        const CompositionResult r =
            compose({0.0, 0.0}, {1.0, 1.0}, {under(0, 1, 0.1), under(1, 0, 0.1)});
        CHECK(r.status == CompositionStatus::Infeasible);
        CHECK_FALSE(r.is_exact());
    }
    SECTION("an iteration cap is reported") {
        CompositionParams tight;
        tight.max_iterations = 1;
        const CompositionResult r = compose(
            {0.0, 0.3, 0.2, 0.5}, {1.0, 1.0, 1.0, 1.0},
            {under(0, 1, 0.1), under(1, 2, 0.1), under(2, 3, 0.1), beside(0, 3, 1.0)}, tight);
        CHECK(r.status == CompositionStatus::NotConverged);
        CHECK(r.residual > 0.0);
    }
    SECTION("more layers than the fixed-size workspace") {
        Random rng;
        const std::size_t k = 20;
        const Vector f = rng.values(k, -1.0, 1.0);
        const Vector w = rng.weights(k);
        const Vector s = rng.values(k - 1, 0.0, 0.1);
        const CompositionResult c = compose_chain(f, w, s);
        const CompositionResult g = compose(f, w, chain_constraints(s), general);
        REQUIRE(g.is_exact());
        for (std::size_t i = 0; i < k; ++i) CHECK(g.fhat[i] == Approx(c.fhat[i]).margin(1e-10));
    }
}

TEST_CASE("chains are detected whatever the layer and constraint order",
          "[untangle][composition]") {
    // Chain 2 < 0 < 3 < 1, constraints shuffled, plus an implied one (0.2 < 0.2 + 0.05).
    const Constraints constraints{under(3, 1, 0.1), under(2, 0, 0.2), under(2, 3, 0.2),
                                  under(0, 3, 0.05)};
    const Vector f{0.3, 0.1, 0.0, 0.4};
    const Vector w{1.0, 2.0, 0.5, 4.0};
    CompositionParams general;
    general.use_chain_fast_path = false;
    const CompositionResult fast = compose(f, w, constraints);
    const CompositionResult exact = compose(f, w, constraints, general);
    CHECK(fast.method == CompositionMethod::Chain);
    REQUIRE(exact.is_exact());
    CHECK(fast.active == exact.active);
    for (std::size_t k = 0; k < 4; ++k) {
        CHECK(fast.fhat[k] == Approx(exact.fhat[k]).margin(1e-12));
        for (std::size_t j = 0; j < 4; ++j) {
            CHECK(fast.coefficient(k, j) == Approx(exact.coefficient(k, j)).margin(1e-12));
        }
    }
    for (std::size_t i = 0; i < constraints.size(); ++i) {
        CHECK(fast.multipliers[i] == Approx(exact.multipliers[i]).margin(1e-9));
    }
}

TEST_CASE("a warmed-up Composer's chain paths do not allocate", "[untangle][composition]") {
    Random rng;
    Composer composer;
    const Vector s{0.1, 0.1, 0.1, 0.1};
    const Constraints constraints = chain_constraints(s);
    std::vector<Vector> fs;
    for (int i = 0; i < 100; ++i) fs.push_back(rng.values(5, -0.5, 0.5));
    const Vector w = rng.weights(5);
    for (const Vector& f : fs) {
        composer.compose_chain(f, w, s);
        composer.compose(f, w, constraints);
    }
    const long before = g_allocations.load();
    double sink = 0.0;
    for (const Vector& f : fs) {
        sink += composer.compose_chain(f, w, s).fhat[0];
        sink += composer.compose(f, w, constraints).fhat[0];
    }
    CHECK(g_allocations.load() == before);
    CHECK(std::isfinite(sink));
}

TEST_CASE("bad input is rejected naming the field", "[untangle][composition]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(compose_chain({0.0, nan}, {1.0, 1.0}, {0.1}), Contains("f[1]"));
    CHECK_THROWS_WITH(compose_chain({0.0, 0.0}, {1.0, 0.0}, {0.1}), Contains("weights[1]"));
    CHECK_THROWS_WITH(compose_chain({0.0, 0.0}, {1.0}, {0.1}), Contains("weights"));
    CHECK_THROWS_WITH(compose_chain({0.0, 0.0}, {1.0, 1.0}, {}), Contains("separations"));
    CHECK_THROWS_WITH(compose_chain({0.0, 0.0}, {1.0, 1.0}, {-0.1}), Contains("separations[0]"));
    CHECK_THROWS_WITH(compose_chain({}, {}, {}), Contains("f must"));
    CHECK_THROWS_WITH(compose({0.0, 0.0}, {1.0, 1.0}, {under(0, 0, 0.1)}),
                      Contains("constraints[0]"));
    CHECK_THROWS_WITH(compose({0.0, 0.0}, {1.0, 1.0}, {under(0, 2, 0.1)}),
                      Contains("constraints[0]"));
    CHECK_THROWS_WITH(compose({0.0, 0.0}, {1.0, 1.0}, {under(0, 1, nan)}),
                      Contains("constraints[0].separation"));
    CHECK_THROWS_AS(compose({0.0, 0.0}, {1.0, 1.0}, {under(0, 1, nan)}), InvalidInput);
    CompositionParams bad;
    bad.tolerance = 0.5;
    CHECK_THROWS_WITH(validate(bad), Contains("params.tolerance"));
    bad = {};
    bad.max_iterations = 0;
    CHECK_THROWS_WITH(Composer(bad), Contains("params.max_iterations"));
}
