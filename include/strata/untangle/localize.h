#pragma once
/// @file Localization (Gong et al. 2023, Algorithm 1): the pieces of each layer that an
/// untangling confined to a box may move, with their fixed collars.

#include "strata/core/types.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <vector>

namespace strata {

/// A run of consecutive vertices of one layer.
struct Piece {
    std::size_t layer = 0;
    /// Vertex indices in polyline order (a closed layer's run may wrap around 0).
    std::vector<std::size_t> vertices;
    /// is_free[k] != 0: vertices[k] lies in the box and may move; otherwise it belongs to the
    /// collar of n_out vertices on each side, which is fixed but takes part in the fields and
    /// the shape-matching fit.
    std::vector<char> is_free;
    /// True when the piece is a whole closed layer (its run and collars cover every vertex).
    bool is_whole_loop = false;
};

/// The pieces of every layer of `scene` that have vertices inside `box`: each run of vertices
/// inside the box is extended by `n_out` vertices on both sides (clamped at the ends of open
/// layers, wrapping around closed ones); runs whose extensions meet are one piece. A layer
/// may give several pieces. Pieces are ordered by layer, then by first vertex.
std::vector<Piece> localize(const Scene& scene, const Box2& box, std::size_t n_out);

/// Every layer as one piece with every vertex free (the global mode).
std::vector<Piece> whole_scene_pieces(const Scene& scene);

}  // namespace strata
