#pragma once
/// @file The composition operator of implicit untangling (Buffet et al. 2019, as used by
/// Gong, Parakkat & Rohmer 2023), evaluated at one point x.
///
/// At x, K layers take part, each with its signed distance f_k(x) (scene units, f > 0 outside
/// layer k) and its weight w_k > 0. The composed values fhat are the weighted least-squares
/// projection of f onto the pairwise order constraints
///
///     fhat = argmin_y sum_k w_k (y_k - f_k)^2   subject to
///         y_a >= y_b + s_ab   for "a under b"            (a is inside b)
///         y_a + y_b >= s_ab   for "a beside b"           (neither enters the other)
///
/// and grad fhat_k = sum_j P_kj grad f_j, P the Jacobian of the projection on its active set.
/// A chain of layers is solved by weighted antitonic regression (pool adjacent violators, O(K));
/// any other constraint set by an exact dual active-set method (Goldfarb & Idnani 1983) followed
/// by an exact solve on the active set. docs/composition.md gives the derivation.

#include <cstddef>
#include <memory>
#include <vector>

namespace strata {

/// One pairwise constraint between participating layers a and b (indices into f and w).
struct CompositionConstraint {
    std::size_t a = 0;          ///< First layer, < K, != b.
    std::size_t b = 0;          ///< Second layer, < K, != a.
    bool side_by_side = false;  ///< false: a under b, f_a >= f_b + s. true: f_a + f_b >= s.
    double separation = 0.0;    ///< s, scene units, finite and >= 0.
};

/// Parameters of compose() and compose_chain().
struct CompositionParams {
    /// Relative tolerance of the general solver: a constraint counts as met when its violation
    /// is <= tolerance * scale, a multiplier as non-negative when >= -tolerance * scale * w_max,
    /// where scale = max(max_k |f_k|, max separation) (1 when both are 0). In (0, 1e-3].
    double tolerance = 1e-10;
    /// Cap on the active-set changes (one constraint added or dropped) of the general solver;
    /// reaching it gives status NotConverged. >= 1.
    int max_iterations = 500;
    /// compose(): use pool-adjacent-violators when the "under" constraints, once the ones
    /// implied by others are dropped, form one chain through all layers and no constraint is
    /// side by side. false: always use the general solver (for comparisons).
    bool use_chain_fast_path = true;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const CompositionParams& params);

/// How the composition was computed.
enum class CompositionMethod {
    Chain,      ///< Pool adjacent violators on a chain.
    ActiveSet,  ///< Dual active set + exact solve on the active set.
};

/// How exactly the composition was solved.
enum class CompositionStatus {
    Exact,         ///< Feasible and KKT to the tolerance: fhat is the projection.
    NotConverged,  ///< max_iterations reached, or the final check failed; see residual.
    Infeasible,    ///< No y meets the constraints (a cycle of "under" with positive separation).
};

/// What compose() and compose_chain() return. Layer indices are those of f and w.
struct CompositionResult {
    std::size_t layer_count = 0;  ///< K.
    std::vector<double> fhat;     ///< K composed values, scene units.
    /// K * K, row-major: grad fhat_k = sum_j gradient_coefficients[k * K + j] * grad f_j.
    /// Every row sums to 1 on a chain (pooled weighted means); in general P = I - W^-1 A_S^T
    /// (A_S W^-1 A_S^T)^+ A_S for the active constraints S.
    std::vector<double> gradient_coefficients;
    /// One Lagrange multiplier per constraint (per link i -- i+1 for compose_chain), >= 0;
    /// units of weight * scene units. Zero for inactive constraints. Not unique when active
    /// constraints are linearly dependent; then the ones the solver kept carry it.
    std::vector<double> multipliers;
    /// Indices of the active constraints (links for compose_chain) in increasing order: the
    /// linearly independent set the solver holds at equality, multipliers >= 0. P is computed
    /// from it. Implied, duplicate or dependent constraints that are also tight are not listed.
    std::vector<std::size_t> active;
    CompositionMethod method = CompositionMethod::Chain;
    CompositionStatus status = CompositionStatus::Exact;
    /// Largest constraint violation of fhat, scene units (0 when all constraints hold).
    double residual = 0.0;
    /// Active-set changes of the general solver (0 on the chain path).
    int iterations = 0;

    bool is_exact() const { return status == CompositionStatus::Exact; }
    /// P_kj, the coefficient of grad f_j in grad fhat_k.
    double coefficient(std::size_t k, std::size_t j) const {
        return gradient_coefficients[k * layer_count + j];
    }
};

namespace detail {
struct ComposerWorkspace;
}

/// @brief Reusable composition engine: keeps its buffers between calls, so that after the
/// first calls at a given K neither path allocates (the general path up to K = 16 layers;
/// beyond, Eigen allocates its small matrices). Not thread-safe: one Composer per thread.
class Composer {
  public:
    /// @throws InvalidInput when `params` is out of range.
    explicit Composer(const CompositionParams& params = {});
    ~Composer();
    Composer(Composer&&) noexcept;
    Composer& operator=(Composer&&) noexcept;
    Composer(const Composer&) = delete;
    Composer& operator=(const Composer&) = delete;

    const CompositionParams& params() const { return params_; }

    /// @brief Chain: layer 0 innermost ... layer K-1 outermost, f_i >= f_{i+1} + s_i.
    /// @param f            K >= 1 signed distances at x, scene units, finite.
    /// @param weights      K weights, finite, > 0.
    /// @param separations  K - 1 separations, s_i between layers i and i + 1, scene units,
    ///                     finite, >= 0.
    /// @return a reference to this Composer's result, valid until the next call.
    /// @throws InvalidInput on wrong sizes or values out of range.
    const CompositionResult& compose_chain(const std::vector<double>& f,
                                           const std::vector<double>& weights,
                                           const std::vector<double>& separations);

    /// @brief Any constraint set: PAVA when it is a chain (see CompositionParams), otherwise the
    /// exact active-set projection.
    /// @param f            K >= 1 signed distances at x, scene units, finite.
    /// @param weights      K weights, finite, > 0.
    /// @param constraints  pairwise constraints among the K layers; duplicates and redundant
    ///                     ones are allowed.
    /// @return a reference to this Composer's result, valid until the next call.
    /// @throws InvalidInput on wrong sizes or values out of range.
    const CompositionResult& compose(const std::vector<double>& f,
                                     const std::vector<double>& weights,
                                     const std::vector<CompositionConstraint>& constraints);

    /// The result of the last call.
    const CompositionResult& result() const { return result_; }

  private:
    CompositionParams params_;
    CompositionResult result_;
    std::unique_ptr<detail::ComposerWorkspace> workspace_;
};

/// One-shot Composer::compose_chain(): allocates its result.
CompositionResult compose_chain(const std::vector<double>& f, const std::vector<double>& weights,
                                const std::vector<double>& separations,
                                const CompositionParams& params = {});

/// One-shot Composer::compose(): allocates its result.
CompositionResult compose(const std::vector<double>& f, const std::vector<double>& weights,
                          const std::vector<CompositionConstraint>& constraints,
                          const CompositionParams& params = {});

}  // namespace strata
