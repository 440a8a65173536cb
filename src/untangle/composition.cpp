#include "strata/untangle/composition.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace strata {

namespace {

/// Above this many layers the general solver's Eigen matrices live on the heap.
constexpr int kMaxFixedLayers = 16;
/// A new constraint normal whose component orthogonal to the active normals is below this
/// fraction of its length is treated as linearly dependent on them (scaled coordinates).
constexpr double kDependenceTolerance = 1e-9;
/// Relative threshold of the rank-revealing decomposition of the active normals.
constexpr double kRankThreshold = 1e-12;
/// Entries of the dual step below this fraction of its largest entry are rounding noise.
constexpr double kDualStepNoise = 1e-12;

[[noreturn]] void fail(const char* function, const std::string& what) {
    throw InvalidInput(std::string(function) + ": " + what);
}

std::string indexed(const char* name, std::size_t i) {
    return std::string(name) + "[" + std::to_string(i) + "]";
}

void check_values(const char* function, const std::vector<double>& f,
                  const std::vector<double>& weights) {
    if (f.empty()) fail(function, "f must hold at least one value (got 0)");
    if (weights.size() != f.size()) {
        fail(function, "weights must hold one value per layer (" + std::to_string(f.size()) +
                           ", got " + std::to_string(weights.size()) + ")");
    }
    for (std::size_t k = 0; k < f.size(); ++k) {
        if (!std::isfinite(f[k])) {
            fail(function, indexed("f", k) + " must be finite (got " + format_number(f[k]) + ")");
        }
        if (!std::isfinite(weights[k]) || !(weights[k] > 0.0)) {
            fail(function, indexed("weights", k) + " must be finite and > 0 (got " +
                               format_number(weights[k]) + ")");
        }
    }
}

bool is_valid_separation(double s) {
    return std::isfinite(s) && s >= 0.0;
}

[[noreturn]] void fail_separation(const char* function, const std::string& name, double s) {
    fail(function, name + " must be finite and >= 0 (got " + format_number(s) + ")");
}

/// scale = max(max |f_k|, max separation), 1 when both are 0: lengths are compared to it.
double length_scale(const std::vector<double>& f, double max_separation) {
    double scale = max_separation;
    for (double v : f) scale = std::max(scale, std::abs(v));
    return scale > 0.0 ? scale : 1.0;
}

}  // namespace

namespace detail {

/// Buffers of one Composer, reused from call to call.
struct ComposerWorkspace {
    // Chain, in chain order (position i = layer order[i]).
    std::vector<std::size_t> order;            ///< Chain position -> layer.
    std::vector<double> link_separation;       ///< s_i between positions i and i + 1.
    std::vector<std::size_t> link_constraint;  ///< compose(): constraint giving link i.
    std::vector<double> offset;                ///< C_i = s_i + ... + s_{K-2}.
    std::vector<double> block_sum;             ///< PAVA stack: sum of w g over the block.
    std::vector<double> block_weight;          ///< PAVA stack: sum of w over the block.
    std::vector<double> block_value;           ///< PAVA stack: block weighted mean.
    std::vector<std::size_t> block_start;      ///< PAVA stack: first position of the block.
    std::vector<std::size_t> in_degree;        ///< Chain detection (Kahn).
    std::vector<std::size_t> position;         ///< Chain detection: layer -> chain position.
    std::vector<char> is_placed;               ///< Chain detection.

    // General solver, per constraint, in scaled coordinates z = W^1/2 y where the constraint
    // reads coef_a z_a + coef_b z_b >= rhs.
    std::vector<double> coef_a;
    std::vector<double> coef_b;
    std::vector<double> rhs;
    std::vector<double> normal_norm;
    std::vector<double> lambda;
    std::vector<char> is_active;
    std::vector<std::size_t> active;
    std::vector<double> sqrt_w;
    std::vector<double> z;

    template <int MaxK>
    struct Dense {
        using Mat =
            Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, MaxK, MaxK>;
        using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxK, 1>;
        Mat normals;  ///< K x q: the active normals as columns.
        Mat pinv;     ///< q x K: pseudo-inverse of `normals`.
        Mat range;    ///< K x K: normals * pinv, the projector onto their span.
        Vec np, qtn, r, d, rhs_s, lam_s, tmp;
        Eigen::HouseholderQR<Mat> qr;
        Eigen::CompleteOrthogonalDecomposition<Mat> cod;
    };
    Dense<kMaxFixedLayers> small;
    std::unique_ptr<Dense<Eigen::Dynamic>> large;
};

}  // namespace detail

namespace {

using detail::ComposerWorkspace;

void prepare_result(CompositionResult& result, std::size_t k, std::size_t m,
                    CompositionMethod method) {
    result.layer_count = k;
    result.fhat.resize(k);
    result.gradient_coefficients.assign(k * k, 0.0);
    result.multipliers.assign(m, 0.0);
    result.active.clear();
    result.method = method;
    result.status = CompositionStatus::Exact;
    result.residual = 0.0;
    result.iterations = 0;
}

/// Weighted antitonic regression of g_i = f_{order[i]} - C_i by pool adjacent violators;
/// fills fhat, P, and the link multipliers (indexed by chain link) into `link_lambda`.
/// Links inside a pooled block are reported through `on_active_link(i)`.
template <class OnActiveLink>
void pava(const std::vector<double>& f, const std::vector<double>& weights, ComposerWorkspace& ws,
          CompositionResult& result, std::vector<double>& link_lambda,
          OnActiveLink on_active_link) {
    const std::size_t k = f.size();
    const std::vector<std::size_t>& order = ws.order;
    std::vector<double>& offset = ws.offset;
    offset.resize(k);
    offset[k - 1] = 0.0;
    for (std::size_t i = k - 1; i-- > 0;) offset[i] = offset[i + 1] + ws.link_separation[i];

    ws.block_sum.resize(k);
    ws.block_weight.resize(k);
    ws.block_value.resize(k);
    ws.block_start.resize(k + 1);
    std::size_t blocks = 0;
    for (std::size_t i = 0; i < k; ++i) {
        const double w = weights[order[i]];
        const double g = f[order[i]] - offset[i];
        ws.block_sum[blocks] = w * g;
        ws.block_weight[blocks] = w;
        ws.block_value[blocks] = g;
        ws.block_start[blocks] = i;
        ++blocks;
        // Antitonic: a block may not have a larger value than the block before it.
        while (blocks >= 2 && ws.block_value[blocks - 2] < ws.block_value[blocks - 1]) {
            ws.block_sum[blocks - 2] += ws.block_sum[blocks - 1];
            ws.block_weight[blocks - 2] += ws.block_weight[blocks - 1];
            ws.block_value[blocks - 2] = ws.block_sum[blocks - 2] / ws.block_weight[blocks - 2];
            --blocks;
        }
    }
    ws.block_start[blocks] = k;

    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t begin = ws.block_start[b];
        const std::size_t end = ws.block_start[b + 1];
        if (end - begin == 1) {
            // Where the order holds nothing changes, bit for bit.
            result.fhat[order[begin]] = f[order[begin]];
            result.gradient_coefficients[order[begin] * k + order[begin]] = 1.0;
            if (begin + 1 < k) link_lambda[begin] = 0.0;
            continue;
        }
        const double value = ws.block_value[b];
        const double total = ws.block_weight[b];
        double flow = 0.0;  // lambda_i = lambda_{i-1} + w_i (fhat_i - f_i)
        for (std::size_t i = begin; i < end; ++i) {
            const std::size_t layer = order[i];
            result.fhat[layer] = value + offset[i];
            for (std::size_t j = begin; j < end; ++j) {
                result.gradient_coefficients[layer * k + order[j]] = weights[order[j]] / total;
            }
            if (i + 1 < k) {
                if (i + 1 < end) {
                    flow += weights[layer] * (result.fhat[layer] - f[layer]);
                    link_lambda[i] = std::max(flow, 0.0);
                    on_active_link(i);
                } else {
                    link_lambda[i] = 0.0;
                }
            }
        }
    }
}

/// Detects whether the constraints, once implied ones are dropped, are one chain through all
/// layers; fills ws.order, ws.link_separation and ws.link_constraint when they are.
bool find_chain(std::size_t k, const std::vector<CompositionConstraint>& constraints,
                ComposerWorkspace& ws) {
    for (const CompositionConstraint& c : constraints) {
        if (c.side_by_side) return false;
    }
    ws.in_degree.assign(k, 0);
    ws.is_placed.assign(k, 0);
    for (const CompositionConstraint& c : constraints) ++ws.in_degree[c.b];
    ws.order.resize(k);
    // Kahn's topological sort; a chain is a DAG whose topological order is unique.
    for (std::size_t pos = 0; pos < k; ++pos) {
        std::size_t next = k;
        for (std::size_t v = 0; v < k; ++v) {
            if (ws.is_placed[v] || ws.in_degree[v] != 0) continue;
            if (next != k) return false;  // two candidates: not a total order
            next = v;
        }
        if (next == k) return false;  // a cycle
        ws.order[pos] = next;
        ws.is_placed[next] = 1;
        for (const CompositionConstraint& c : constraints) {
            if (c.a == next) --ws.in_degree[c.b];
        }
    }
    ws.position.resize(k);
    for (std::size_t pos = 0; pos < k; ++pos) ws.position[ws.order[pos]] = pos;
    ws.link_separation.assign(k - 1, -1.0);
    ws.link_constraint.assign(k - 1, constraints.size());
    for (std::size_t i = 0; i < constraints.size(); ++i) {
        const CompositionConstraint& c = constraints[i];
        const std::size_t pa = ws.position[c.a];
        if (ws.position[c.b] == pa + 1 && c.separation > ws.link_separation[pa]) {
            ws.link_separation[pa] = c.separation;
            ws.link_constraint[pa] = i;
        }
    }
    // A unique topological order has a direct constraint on every link.
    double total = 0.0;
    for (double s : ws.link_separation) total += s;
    // Every other constraint must be implied by the links it spans.
    const double slack = 8.0 * std::numeric_limits<double>::epsilon() * total;
    for (const CompositionConstraint& c : constraints) {
        const std::size_t pa = ws.position[c.a];
        const std::size_t pb = ws.position[c.b];
        double spanned = 0.0;
        for (std::size_t i = pa; i < pb; ++i) spanned += ws.link_separation[i];
        if (c.separation > spanned + slack) return false;
    }
    return true;
}

double constraint_value(const CompositionConstraint& c, const std::vector<double>& y) {
    return c.side_by_side ? y[c.a] + y[c.b] : y[c.a] - y[c.b];
}

double max_violation(const std::vector<CompositionConstraint>& constraints,
                     const std::vector<double>& y) {
    double worst = 0.0;
    for (const CompositionConstraint& c : constraints) {
        worst = std::max(worst, c.separation - constraint_value(c, y));
    }
    return worst;
}

/// The exact projection: Goldfarb-Idnani dual active set in z = W^1/2 y (identity Hessian),
/// then the equality-constrained solve on the final active set, checked and repaired.
template <int MaxK>
void solve_general(const std::vector<double>& f, const std::vector<double>& weights,
                   const std::vector<CompositionConstraint>& constraints,
                   const CompositionParams& params, ComposerWorkspace& ws,
                   ComposerWorkspace::Dense<MaxK>& dense, CompositionResult& result) {
    const std::size_t k = f.size();
    const std::size_t m = constraints.size();
    const Eigen::Index ki = static_cast<Eigen::Index>(k);

    double max_separation = 0.0;
    double max_weight = 0.0;
    for (const CompositionConstraint& c : constraints) {
        max_separation = std::max(max_separation, c.separation);
    }
    for (double w : weights) max_weight = std::max(max_weight, w);
    const double scale = length_scale(f, max_separation);
    const double length_tol = params.tolerance * scale;
    const double lambda_tol = params.tolerance * scale * max_weight;

    ws.sqrt_w.resize(k);
    ws.z.resize(k);
    for (std::size_t j = 0; j < k; ++j) {
        ws.sqrt_w[j] = std::sqrt(weights[j]);
        ws.z[j] = ws.sqrt_w[j] * f[j];
    }
    ws.coef_a.resize(m);
    ws.coef_b.resize(m);
    ws.rhs.resize(m);
    ws.normal_norm.resize(m);
    ws.lambda.assign(m, 0.0);
    ws.is_active.assign(m, 0);
    ws.active.clear();
    for (std::size_t i = 0; i < m; ++i) {
        const CompositionConstraint& c = constraints[i];
        ws.coef_a[i] = 1.0 / ws.sqrt_w[c.a];
        ws.coef_b[i] = (c.side_by_side ? 1.0 : -1.0) / ws.sqrt_w[c.b];
        ws.rhs[i] = c.separation;
        ws.normal_norm[i] = std::hypot(ws.coef_a[i], ws.coef_b[i]);
    }
    auto value = [&](std::size_t i) {
        const CompositionConstraint& c = constraints[i];
        return ws.coef_a[i] * ws.z[c.a] + ws.coef_b[i] * ws.z[c.b];
    };
    auto set_normal = [&](auto& column, std::size_t i) {
        column.setZero();
        column(static_cast<Eigen::Index>(constraints[i].a)) = ws.coef_a[i];
        column(static_cast<Eigen::Index>(constraints[i].b)) += ws.coef_b[i];
    };
    auto build_normals = [&]() {
        const Eigen::Index q = static_cast<Eigen::Index>(ws.active.size());
        dense.normals.resize(ki, q);
        for (Eigen::Index c = 0; c < q; ++c) {
            auto column = dense.normals.col(c);
            set_normal(column, ws.active[static_cast<std::size_t>(c)]);
        }
    };
    auto drop = [&](std::size_t position) {
        const std::size_t i = ws.active[position];
        ws.is_active[i] = 0;
        ws.lambda[i] = 0.0;
        ws.active.erase(ws.active.begin() + static_cast<std::ptrdiff_t>(position));
    };

    int iterations = 0;
    CompositionStatus status = CompositionStatus::Exact;
    std::vector<double>& y = result.fhat;

    // Equality-constrained projection on the active set, from f (not from the iterate):
    // lambda_S = (N^T N)^+ (b_S - N^T z0), y = f + W^-1 A_S^T lambda_S.
    auto polish = [&]() {
        const Eigen::Index q = static_cast<Eigen::Index>(ws.active.size());
        for (std::size_t i : ws.active) ws.lambda[i] = 0.0;
        if (q > 0) {
            build_normals();
            dense.rhs_s.resize(q);
            for (Eigen::Index c = 0; c < q; ++c) {
                const std::size_t i = ws.active[static_cast<std::size_t>(c)];
                dense.rhs_s(c) = ws.rhs[i] - constraint_value(constraints[i], f);
            }
            dense.cod.setThreshold(kRankThreshold);
            dense.cod.compute(dense.normals);
            dense.pinv = dense.cod.pseudoInverse();
            dense.tmp.noalias() = dense.pinv.transpose() * dense.rhs_s;
            dense.lam_s.noalias() = dense.pinv * dense.tmp;
            for (Eigen::Index c = 0; c < q; ++c) {
                ws.lambda[ws.active[static_cast<std::size_t>(c)]] = dense.lam_s(c);
            }
        }
        for (std::size_t j = 0; j < k; ++j) y[j] = 0.0;
        for (std::size_t i : ws.active) {
            const CompositionConstraint& c = constraints[i];
            y[c.a] += ws.lambda[i];
            y[c.b] += (c.side_by_side ? 1.0 : -1.0) * ws.lambda[i];
        }
        for (std::size_t j = 0; j < k; ++j) {
            y[j] = f[j] + y[j] / weights[j];
            ws.z[j] = ws.sqrt_w[j] * y[j];
        }
    };

    for (;;) {
        // Goldfarb-Idnani: add the most violated constraint, dropping blocking ones.
        for (;;) {
            std::size_t p = m;
            double worst = 0.0;
            for (std::size_t i = 0; i < m; ++i) {
                if (ws.is_active[i]) continue;
                const double violation = ws.rhs[i] - value(i);
                if (violation > length_tol && violation / ws.normal_norm[i] > worst) {
                    worst = violation / ws.normal_norm[i];
                    p = i;
                }
            }
            if (p == m) break;
            bool is_added = false;
            while (!is_added) {
                if (++iterations > params.max_iterations) {
                    status = CompositionStatus::NotConverged;
                    break;
                }
                const Eigen::Index q = static_cast<Eigen::Index>(ws.active.size());
                dense.np.resize(ki);
                set_normal(dense.np, p);
                dense.r.resize(q);
                dense.d = dense.np;
                if (q > 0) {
                    build_normals();
                    dense.qr.compute(dense.normals);
                    dense.qtn = dense.qr.householderQ().transpose() * dense.np;
                    dense.r = dense.qr.matrixQR()
                                  .topLeftCorner(q, q)
                                  .template triangularView<Eigen::Upper>()
                                  .solve(dense.qtn.head(q));
                    dense.d.noalias() -= dense.normals * dense.r;
                }
                const double d_norm = dense.d.norm();
                const bool is_dependent =
                    ws.active.size() >= k || d_norm <= kDependenceTolerance * ws.normal_norm[p];
                const double full_step = is_dependent ? std::numeric_limits<double>::infinity()
                                                      : (ws.rhs[p] - value(p)) / (d_norm * d_norm);
                double partial_step = std::numeric_limits<double>::infinity();
                std::size_t blocking = ws.active.size();
                const double r_max = q > 0 ? dense.r.cwiseAbs().maxCoeff() : 0.0;
                for (std::size_t c = 0; c < ws.active.size(); ++c) {
                    const double rc = dense.r(static_cast<Eigen::Index>(c));
                    if (rc <= kDualStepNoise * r_max) continue;
                    const double ratio = ws.lambda[ws.active[c]] / rc;
                    if (ratio < partial_step) {
                        partial_step = ratio;
                        blocking = c;
                    }
                }
                if (std::isinf(full_step) && std::isinf(partial_step)) {
                    status = CompositionStatus::Infeasible;
                    break;
                }
                const double step = std::min(full_step, partial_step);
                if (!is_dependent) {
                    for (std::size_t j = 0; j < k; ++j) {
                        ws.z[j] += step * dense.d(static_cast<Eigen::Index>(j));
                    }
                }
                for (std::size_t c = 0; c < ws.active.size(); ++c) {
                    ws.lambda[ws.active[c]] -= step * dense.r(static_cast<Eigen::Index>(c));
                }
                ws.lambda[p] += step;
                if (full_step <= partial_step) {
                    ws.is_active[p] = 1;
                    ws.active.push_back(p);
                    is_added = true;
                } else {
                    drop(blocking);
                }
            }
            if (status != CompositionStatus::Exact) break;
        }
        if (status == CompositionStatus::Infeasible) {
            for (std::size_t j = 0; j < k; ++j) y[j] = ws.z[j] / ws.sqrt_w[j];
            break;
        }
        polish();
        if (status == CompositionStatus::NotConverged) break;
        // Check and repair. Multipliers < 0: drop the most negative one and re-solve, until
        // none is left; the polished point is then a valid Goldfarb-Idnani state, from which
        // violated constraints are added again.
        for (;;) {
            std::size_t negative = ws.active.size();
            double most_negative = -lambda_tol;
            for (std::size_t c = 0; c < ws.active.size(); ++c) {
                if (ws.lambda[ws.active[c]] < most_negative) {
                    most_negative = ws.lambda[ws.active[c]];
                    negative = c;
                }
            }
            if (negative == ws.active.size()) break;
            if (++iterations > params.max_iterations) {
                status = CompositionStatus::NotConverged;
                break;
            }
            drop(negative);
            polish();
        }
        if (status != CompositionStatus::Exact) break;
        if (max_violation(constraints, y) <= length_tol) break;
        if (++iterations > params.max_iterations) {
            status = CompositionStatus::NotConverged;
            break;
        }
    }

    result.iterations = iterations;
    result.status = status;
    result.residual = max_violation(constraints, y);
    if (status == CompositionStatus::Exact && result.residual > length_tol) {
        result.status = CompositionStatus::NotConverged;
    }
    for (std::size_t i = 0; i < m; ++i) {
        result.multipliers[i] = ws.is_active[i] ? std::max(ws.lambda[i], 0.0) : 0.0;
    }
    for (std::size_t i : ws.active) result.active.push_back(i);
    std::sort(result.active.begin(), result.active.end());

    // P = W^-1/2 (I - N N^+) W^1/2 for the active normals N (in z coordinates).
    for (std::size_t j = 0; j < k; ++j) result.gradient_coefficients[j * k + j] = 1.0;
    if (!ws.active.empty()) {
        if (status != CompositionStatus::Exact) {
            build_normals();
            dense.cod.setThreshold(kRankThreshold);
            dense.cod.compute(dense.normals);
            dense.pinv = dense.cod.pseudoInverse();
        }
        dense.range.noalias() = dense.normals * dense.pinv;
        for (std::size_t r = 0; r < k; ++r) {
            for (std::size_t c = 0; c < k; ++c) {
                result.gradient_coefficients[r * k + c] -=
                    ws.sqrt_w[c] / ws.sqrt_w[r] *
                    dense.range(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
            }
        }
    }
}

}  // namespace

void validate(const CompositionParams& params) {
    if (!(params.tolerance > 0.0 && params.tolerance <= 1e-3)) {
        fail("compose",
             "params.tolerance must be in (0, 1e-3] (got " + format_number(params.tolerance) + ")");
    }
    if (params.max_iterations < 1) {
        fail("compose", "params.max_iterations must be >= 1 (got " +
                            std::to_string(params.max_iterations) + ")");
    }
}

Composer::Composer(const CompositionParams& params)
    : params_(params), workspace_(std::make_unique<detail::ComposerWorkspace>()) {
    validate(params_);
}

Composer::~Composer() = default;
Composer::Composer(Composer&&) noexcept = default;
Composer& Composer::operator=(Composer&&) noexcept = default;

const CompositionResult& Composer::compose_chain(const std::vector<double>& f,
                                                 const std::vector<double>& weights,
                                                 const std::vector<double>& separations) {
    constexpr const char* kFunction = "compose_chain";
    check_values(kFunction, f, weights);
    const std::size_t k = f.size();
    if (separations.size() != k - 1) {
        fail(kFunction, "separations must hold K - 1 = " + std::to_string(k - 1) + " values (got " +
                            std::to_string(separations.size()) + ")");
    }
    for (std::size_t i = 0; i + 1 < k; ++i) {
        if (!is_valid_separation(separations[i])) {
            fail_separation(kFunction, indexed("separations", i), separations[i]);
        }
    }
    ComposerWorkspace& ws = *workspace_;
    prepare_result(result_, k, k - 1, CompositionMethod::Chain);
    ws.order.resize(k);
    for (std::size_t i = 0; i < k; ++i) ws.order[i] = i;
    ws.link_separation.assign(separations.begin(), separations.end());
    pava(f, weights, ws, result_, result_.multipliers,
         [this](std::size_t link) { result_.active.push_back(link); });
    double residual = 0.0;
    for (std::size_t i = 0; i + 1 < k; ++i) {
        residual = std::max(residual, separations[i] - (result_.fhat[i] - result_.fhat[i + 1]));
    }
    result_.residual = residual;
    return result_;
}

const CompositionResult& Composer::compose(const std::vector<double>& f,
                                           const std::vector<double>& weights,
                                           const std::vector<CompositionConstraint>& constraints) {
    constexpr const char* kFunction = "compose";
    check_values(kFunction, f, weights);
    const std::size_t k = f.size();
    for (std::size_t i = 0; i < constraints.size(); ++i) {
        const CompositionConstraint& c = constraints[i];
        if (c.a >= k || c.b >= k || c.a == c.b) {
            fail(kFunction, indexed("constraints", i) + " must join two distinct layers < " +
                                std::to_string(k) + " (got " + std::to_string(c.a) + ", " +
                                std::to_string(c.b) + ")");
        }
        if (!is_valid_separation(c.separation)) {
            fail_separation(kFunction, indexed("constraints", i) + ".separation", c.separation);
        }
    }
    ComposerWorkspace& ws = *workspace_;
    const std::size_t m = constraints.size();
    if (params_.use_chain_fast_path && find_chain(k, constraints, ws)) {
        prepare_result(result_, k, m, CompositionMethod::Chain);
        // Link multipliers first go to a per-link buffer (reusing `lambda`), then to the
        // constraint that gave the link.
        ws.lambda.assign(k - 1, 0.0);
        pava(f, weights, ws, result_, ws.lambda,
             [this, &ws](std::size_t link) { result_.active.push_back(ws.link_constraint[link]); });
        for (std::size_t i = 0; i + 1 < k; ++i) {
            result_.multipliers[ws.link_constraint[i]] = ws.lambda[i];
        }
        std::sort(result_.active.begin(), result_.active.end());
        result_.residual = max_violation(constraints, result_.fhat);
        return result_;
    }
    prepare_result(result_, k, m, CompositionMethod::ActiveSet);
    if (k <= static_cast<std::size_t>(kMaxFixedLayers)) {
        solve_general(f, weights, constraints, params_, ws, ws.small, result_);
    } else {
        if (!ws.large) ws.large = std::make_unique<ComposerWorkspace::Dense<Eigen::Dynamic>>();
        solve_general(f, weights, constraints, params_, ws, *ws.large, result_);
    }
    return result_;
}

CompositionResult compose_chain(const std::vector<double>& f, const std::vector<double>& weights,
                                const std::vector<double>& separations,
                                const CompositionParams& params) {
    Composer composer(params);
    return composer.compose_chain(f, weights, separations);
}

CompositionResult compose(const std::vector<double>& f, const std::vector<double>& weights,
                          const std::vector<CompositionConstraint>& constraints,
                          const CompositionParams& params) {
    Composer composer(params);
    return composer.compose(f, weights, constraints);
}

}  // namespace strata
