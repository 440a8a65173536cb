#pragma once
/// @file Collision-free simplification (Gong, Parakkat & Rohmer 2023, Algorithm 1): vertex
/// decimation, and after each removal that makes layers cross or come too close, a localized
/// untangling; a removal that cannot be made collision-free is rolled back.

#include "strata/core/progress.h"
#include "strata/geometry/scene.h"
#include "strata/untangle/untangle.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace strata {

/// When simplify() untangles a removal that makes layers cross or come too close.
enum class UntangleSchedule {
    /// Set the removal aside and go on with the removals that need no untangling; the ones set
    /// aside are tried again, untangling locally, only for layers that would otherwise miss
    /// their target. The fast default: most conflicts never need untangling, because another
    /// vertex of the same layer can go instead.
    Deferred,
    /// Untangle locally right after every removal that needs it (the paper's Algorithm 1: one
    /// decimation, then one localized untangling).
    Immediate,
};

/// Parameters of simplify(). Lengths are in scene units.
struct SimplifyParams {
    /// "random" (the paper's experiments), "visvalingam" or "max-error"; see decimator.h.
    std::string decimator = "visvalingam";
    /// Fraction of each layer's vertices to remove, [0, 1]. Ignored when `keep` > 0.
    double remove = 0.9;
    /// Vertices to keep per layer (0: use `remove`).
    std::size_t keep = 0;
    /// > 0: never remove a vertex whose removal leaves an input vertex farther than this from
    /// the simplified layer (span_error()); with `remove` = 1 this is the target itself.
    double max_error = 0.0;
    /// Gap rule for layers without thickness (keep_input_gaps(), applied when `untangle` is
    /// set, before the first removal): a near pair of layers whose thicknesses require no
    /// separation keeps at least this share of its smallest gap in the input. Its required
    /// separation becomes min(1, keep_input_gaps / (1 - untangling.separation_tolerance)) x
    /// that gap (1.0 x the gap with the defaults), so that the untangler and the exact checks,
    /// which pass a gap at required x (1 - separation_tolerance), keep this share. [0, 1];
    /// 0 = off (such pairs may then come as close as the untangler's min_separation).
    double keep_input_gaps = 0.9;
    /// When the run leaves a layer above its target (every removal left refused by the local
    /// checks and their untanglings, then by the exact check of the whole scene), an open
    /// layer may lose end vertices: first the end whose removal leaves it nearer its input
    /// (Hausdorff), kept only where the exact check of the whole scene passes
    /// (docs/simplify.md, *Meeting the budget*). The trimmed piece is part of the one before:
    /// it crosses nothing new and keeps every gap, but it is shorter (an open piece wrapped
    /// around another layer, whose wrap needs more vertices than its target, loses its ends
    /// instead). false: open layers keep both ends, whatever their target. No effect on a run
    /// that meets every target, nor with `max_error` (whose layers stay above their target
    /// where the error bound says so).
    bool trim_ends = true;
    std::uint64_t seed = 1;  ///< Seed of the random decimator.
    bool untangle = true;    ///< false: naive decimation (the paper's left-hand images).
    bool global = false;     ///< Untangle the whole scene instead of a box (for comparison).
    std::size_t n_out = 7;   ///< N_out: fixed collar vertices on both sides of a piece.
    UntangleSchedule schedule = UntangleSchedule::Deferred;  ///< See UntangleSchedule.
    /// Removals that need untangling wait in a batch of up to this many, whose untanglings
    /// run side by side (TBB) when their regions keep apart by the largest separation a layer
    /// needs; the batch is committed in order, so the output is the same at any thread count
    /// (not the same as another batch size). 1: one removal at a time, the paper's order.
    /// Not used by `global`, nor by the first sweep of the deferred schedule (it untangles
    /// nothing).
    std::size_t batch = 16;
    /// Untangling settings. Defaults differ from untangle()'s: rounds of 10 projection steps,
    /// one round per pass, 16 passes. Every pass brings the fields up to date with the moved
    /// vertices (LayerField::update()), and within a pass each layer's own frozen field pulls
    /// it back toward where the pass began; on generated 5/8-layer stacks this untangled 2.6x
    /// more removals in 1/5 of the time of 2 passes of 8 rounds of 30 steps (closing note of
    /// issue 5). The finishing stage (UntangleParams::finish_separations) runs before the
    /// first check and at the end of every pass. A removal that does not untangle within them
    /// is rolled back. give_up_when_stalled is off: with the finishing stage it gave up on
    /// untanglings that succeed (8 x 10k at 98%: 20 refused with it, 4 without, 1.16x the
    /// time, when this was decided; at 6cd7220, 1 refused either way and none given up:
    /// docs/simplify.md). Only the untanglings of rolled vertices give up, while a close
    /// vertex stays on the wrong side (docs/untangle.md, *Rolled families, measured*).
    UntangleParams untangling = default_untangling();

    static UntangleParams default_untangling() {
        UntangleParams p;
        p.gradient_steps = 10;
        p.max_rounds = 1;
        p.max_passes = 16;
        p.field.backend = FieldBackend::ExactIndexed;
        return p;
    }
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const SimplifyParams& params);

/// Per-layer outcome.
struct LayerSimplifyReport {
    std::string name;
    std::size_t before = 0, after = 0, target = 0;  ///< Vertex counts.
    std::size_t refused = 0;        ///< Removals rolled back (their vertex is kept).
    std::size_t untangled = 0;      ///< Removals that needed a local untangling.
    double hausdorff = 0.0;         ///< Symmetric Hausdorff distance to the input layer.
    double max_displacement = 0.0;  ///< Largest move of a kept vertex.
};

/// What simplify() did.
struct SimplifyReport {
    std::vector<LayerSimplifyReport> layers;
    std::size_t removed = 0;         ///< Removals kept.
    std::size_t untangle_calls = 0;  ///< Local untanglings run.
    std::size_t refused = 0;         ///< Removals rolled back.
    /// Of the refused removals, those whose untangling gave up before its last pass
    /// (UntangleParams::give_up_when_stalled).
    std::size_t gave_up = 0;
    /// Of the untangle_calls, removals on a rolled part kept by moving the two ends of their
    /// chord toward the removed vertex, out of what it cut into, without an untangling pass
    /// (docs/simplify.md, *Rolled parts: shifting a chord*).
    std::size_t chord_shifts = 0;
    /// Of the refused removals, those on a rolled part whose untangling succeeded but left the
    /// shape around it farther from the input than the removal alone by more than the layer's
    /// separation (docs/simplify.md, *Rolled parts: the shape error bound*).
    std::size_t shape_refused = 0;
    std::size_t deferred = 0;        ///< Removals set aside (UntangleSchedule::Deferred).
    int rounds = 0;                  ///< Untangling rounds over all calls.
    /// Untanglings of a batch run once more alone, because their vertices came within reach
    /// of another job's (or of a removal made while they waited).
    std::size_t batch_reruns = 0;
    /// Batches run; untangle_calls / batches is the mean number of jobs per batch.
    std::size_t batches = 0;
    bool targets_met = true;         ///< Every layer reached its target.
    /// Pairs of layers whose required separation the gap rule raised (keep_input_gaps).
    std::size_t raised_separations = 0;
    // Final exact check of the whole output (check_scene()).
    std::size_t crossings = 0, self_crossings = 0, nesting_violations = 0;
    double min_separation_ratio = 0.0;  ///< +inf when nothing is required.
    bool collision_free = false;
    /// Vertices of the output that lie, as they did in the input, on the side of an open
    /// layer that the global order does not give them (rolled or folded-over parts; once per
    /// other layer): the simplification keeps the input's sides (strata/geometry/input_sides.h).
    /// The nesting violations above are vertices that changed side relative to the input.
    std::size_t rolled_vertices = 0;
    /// Input vertices put back (or moved back to their input position) by the last resort:
    /// where the exact check of the whole result still failed (what the local checks do not
    /// see: a vertex that did not move whose closest point on an open layer moved), the input
    /// came back within a radius of each violation, doubled until the check passed. 0 almost
    /// always; 0 when untangle is false (naive decimation keeps its collisions) and when even
    /// the whole input fails the check (a tangled input: the result is returned as it is).
    std::size_t restored = 0;
    /// End vertices of open layers taken out to meet their target (SimplifyParams::trim_ends).
    /// `restored` above is counted before them.
    std::size_t trimmed_ends = 0;
    /// Per layer, the input index of every output vertex, in output order (a simplification
    /// keeps vertices and their order; InputSides::renumbered() takes it).
    std::vector<std::vector<std::size_t>> origins;
    /// Time per phase (s). The untangling phases (fields, untangle, and the check inside an
    /// untangling) are summed over the untanglings, which run side by side in batches: with
    /// several threads their sum can exceed seconds_total.
    double seconds_decimate = 0.0, seconds_fields = 0.0, seconds_untangle = 0.0,
           seconds_check = 0.0, seconds_total = 0.0;
    /// Time in the untanglings' finishing stage (UntangleParams::finish_separations), summed
    /// like the untangling phases.
    double seconds_finish = 0.0;
};

/// @brief Simplifies `scene` in place to the targets of `params`, keeping it collision-free
/// when params.untangle is set (see the file comment); open layers keep their end vertices
/// (never removed nor moved), closed layers at least 3 vertices.
/// @param progress  ("simplify", fraction of the removals done); false cancels.
/// @throws InvalidInput bad params.  @throws Cancelled (scene unchanged).
SimplifyReport simplify(Scene& scene, const SimplifyParams& params = {},
                        const ProgressFn& progress = {});

/// Generated test scene: `layers` open layers offset by `spacing` along the normal of one
/// folded curve over x in [0, width] (y = 0.5 sin 0.6x + 0.18 sin(2.3x + 0.5) + 0.07 sin 6.1x),
/// `points` vertices each, thickness `thickness`, innermost first, one implicit stack. Where
/// the folds bend the layers come close, and a decimation that cuts a fold's corner cuts into
/// the neighbouring layer. Lengths in scene units.
/// `spacing` 0 = automatic: 0.04, or less when the outermost offset would pass 80% of the
/// curve's smallest radius of curvature (0.268), beyond which the outer layers loop over
/// themselves (8 layers at 0.04 do): 0.04 up to 6 layers, 0.0306 for 8.
Scene folded_stack(std::size_t layers, std::size_t points, double width = 10.0,
                   double spacing = 0.0, double thickness = 0.01);

/// The built-in demo (after the paper's Fig. 1): folded_stack(5, points), units "dm".
Scene demo_scene(std::size_t points = 600);

}  // namespace strata
