#pragma once
/// @file Müller et al. 2005 shape matching of a polyline piece, quadratic 2D modes
/// (Gong, Parakkat & Rohmer 2023, Eq. 4-6).

#include "strata/core/types.h"

#include <cstddef>
#include <vector>

namespace strata {

/// Parameters of shape_match(). Dimensionless.
struct ShapeMatchParams {
    double alpha = 0.8;  ///< Stiffness: share of the goal in the new position, [0, 1].
    double beta = 0.9;   ///< Share of the quadratic fit against the rigid rotation, [0, 1].
    /// Moment-matrix eigenvalues below this fraction of the largest are treated as zero
    /// (pseudo-inverse): straight or tiny pieces are degenerate. In (0, 1).
    double rank_tolerance = 1e-10;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const ShapeMatchParams& params);

/// What shape_match() fitted.
struct ShapeMatchReport {
    double rotation = 0.0;   ///< Angle of the closest rotation R, radians.
    int quadratic_rank = 0;  ///< Rank of the 5x5 moment matrix kept in the fit (0..5).
    double beta_used = 0.0;  ///< beta after the fall-back toward rigid (see shape_match()).
};

/// @brief One shape-matching step of a piece: moves `current` toward the goal positions
/// x_bar = (1 - alpha) x + alpha [(beta A~ + (1 - beta) R~) q~ + x_cm].
///
/// q are the rest positions relative to their weighted barycentre, p the current ones
/// relative to theirs; R is the closest rotation to A_pq = sum m p q^T (closed-form 2x2 polar,
/// det +1); A~ = (sum m p q~^T)(sum m q~ q~^T)^+ with q~ = [qx, qy, qx^2, qy^2, qx qy]
/// (q scaled by the piece size for conditioning, and the quadratic entries centred on their
/// weighted mean so that a quadratic deformation is fitted exactly); R~ = [R 0 0 0].
///
/// Fall-back toward rigid: a quadratic fit with as many points as fitted modes interpolates
/// and keeps no shape, so with m = n - 1 (n points; the barycentre takes one) and r the rank
/// of the fit, beta is scaled by (m - r) / r for r < m < 2r, and is 0 for m <= r.
///
/// @param rest     rest shape of the piece (e.g. the positions before untangling).
/// @param current  current positions, same size; replaced by the new positions.
/// @param masses   per-point weights > 0, same size (or empty: all 1).
/// @param fixed    optional, same size or empty: points with fixed[i] != 0 take part in the fit
///                 but keep their position.
/// @throws InvalidInput when sizes differ or a mass is not > 0.
ShapeMatchReport shape_match(const std::vector<Vec2>& rest, std::vector<Vec2>& current,
                             const std::vector<double>& masses, const std::vector<char>& fixed,
                             const ShapeMatchParams& params = {});

}  // namespace strata
