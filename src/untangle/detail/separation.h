#pragma once
/// @file The untangling's finishing stage: exact separation constraints on the polylines.
///
/// The implicit projection decides which side of every other layer each vertex belongs to,
/// but with its fields frozen within a pass it approaches the required gaps only slowly. This
/// stage takes a work scene whose layers no longer cross near the free vertices and pushes
/// apart every vertex and segment of two constrained layers that are closer than the gap
/// aimed for, by projected Gauss-Seidel on point-segment distance constraints (Müller et al.
/// 2007, position-based dynamics), weighted by the layer weights. A vertex is pushed only when
/// it lies on the side of the other layer that the nesting asks for (the composition's side);
/// one on the wrong side is left to the projection. Where no side is asked of an open
/// side-by-side layer, a vertex whose run of its layer pokes through
/// it (bounded by two segments that cross the same segment of it, or by one and an end of
/// its own open layer) belongs on the side of the rest of its layer. Every move is validated
/// exactly before it is made: the moved vertex's two new segments meet each other segment no
/// more often than its two old ones did, and the old ones sweep over no other vertex, so no
/// layer tunnels through another and no crossing is ever added.

#include "untangle/detail/engine.h"

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace strata::detail {

/// Settings of finish_separations().
struct SeparationParams {
    /// Gap aimed for between constrained layers a and b: max(required(a, b), min_separation),
    /// scene units, >= 0.
    double min_separation = 0.0;
    int max_sweeps = 60;  ///< Gauss-Seidel sweeps over all constraints, at most. >= 1.
    /// A sweep that leaves every pair within this fraction of its aim ends the stage.
    double tolerance = 0.02;
    /// Vertices on the wrong side of another layer are seen (and pushed back over it) up to
    /// max(largest aim, this many median segment lengths of the work scene) from it; 0: only
    /// within the aims. (0 and 0.5 were tried for untangle(), where nothing rolls a bad
    /// result back: no more scenes of strata_bench_untangle came out clean, and 0 left the
    /// small folded stack of the tests tangled.)
    double tangle_reach = 1.0;
    /// Leave the scene as it is when a close vertex lies on the wrong side of another layer
    /// (a tangle the projection has yet to take out): the run then costs one measuring sweep.
    bool only_when_untangled = false;
    /// Stop the sweeps once this many have run and the last left at least as many close
    /// vertices on the wrong side of another layer as the run found (a tangle that pushing
    /// does not take out: the projection has to); 0: never. The simplification driver's jobs
    /// with rolled vertices use 1 (EngineSettings::finish_stop_when_wrong_stays).
    int stop_when_wrong_stays = 0;
    /// Outside side of each work layer (+1: on the right of its direction of travel), see
    /// outside_side(); it says on which side of another layer a vertex belongs.
    const std::vector<int>* outside_signs = nullptr;
    /// A vertex whose closest point on an open layer m is a hairpin's tip (an interior vertex
    /// of m where its two segments are more than 120 degrees apart: a bend the decimation cut
    /// to one vertex) and that lies outside the hairpin's wedge, within the tangle reach, while
    /// its side of m asks for the inside: the tip moves past the vertex by the aim (the bend
    /// opens around it), and the vertex stays (it moves onto the tip's far side only when the
    /// tip is fixed). Only with RelationSource::local_sides (a scene with rolled vertices);
    /// sides recorded in an original (UntangleParams::open_cut_bends).
    bool open_cut_bends = false;
};

/// What finish_separations() did.
struct SeparationResult {
    int sweeps = 0;
    std::size_t moves = 0;       ///< Vertex moves made and kept (each validated).
    std::size_t refused = 0;     ///< Moves refused because they would have tunnelled.
    std::size_t wrong_side = 0;  ///< Close vertices on the wrong side at the last sweep.
    double worst = 0.0;  ///< Largest remaining shortfall, as a fraction of the aim (0: none).
    /// The sweeps left the worst pair worse (or more vertices on the wrong side) than they
    /// found it, so every move was undone.
    bool reverted = false;
};

/// What finish_separations() keeps from one call to the next on the same work scene and
/// pieces (the engine's calls), where only the free vertices of the pieces move in between:
/// the lengths of the segments between two fixed vertices, which the median segment length
/// of every call reads. A local untangling's pieces hold a few percent of the scene; the
/// lengths of the rest are then measured and sorted once, not at every call.
struct FinishCache {
    bool is_set = false;
    /// When the fixed segments are most of the scene: their lengths, sorted; the segments with
    /// a free end are (layer, first vertex) in `moving`. Else both empty (every call measures
    /// every segment).
    std::vector<double> fixed_lengths;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> moving;
};

/// Pushes the layers of `work` apart where they are closer than aimed for. Only the free
/// vertices of `pieces` move. Deterministic (sequential, in layer and vertex order).
/// `cache`: see FinishCache (nullptr: none); pass the same one only with the same `work`
/// and `pieces`, with nothing but the free vertices moved since the last call.
SeparationResult finish_separations(Scene& work, const std::vector<Piece>& pieces,
                                    const RelationSource& relations, const SeparationParams& params,
                                    FinishCache* cache = nullptr);

}  // namespace strata::detail
