#pragma once
/// @file Shape-preserving implicit untangling (Gong, Parakkat & Rohmer 2023, sections 3-4, on
/// Buffet et al. 2019 and Müller et al. 2005): vertices are projected onto the zero sets of the
/// composed fields fhat_i, interleaved with shape matching, so that layers stop crossing and
/// keep their order, separations and shapes.

#include "strata/core/progress.h"
#include "strata/field/field.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"
#include "strata/untangle/composition.h"
#include "strata/untangle/localize.h"
#include "strata/untangle/outside_sides.h"

#include <cstddef>
#include <vector>

namespace strata {

/// What keeps a layer's shape between projection steps.
enum class ShapeMode {
    ShapeMatching,  ///< Müller-style quadratic shape matching per piece (the paper).
    None,           ///< Pure projection (shows the artefacts of the paper's Fig. 2).
};

/// Parameters of untangle() and Untangler. Lengths are in scene units.
struct UntangleParams {
    int gradient_steps = 10;  ///< N_gd: projection steps per round (then one shape matching). >= 1.
    double step = 0.5;        ///< dt: damping of each normalised projection step, (0, 1].
    /// Each vertex step is clamped to this fraction of the shorter adjacent edge. (0, 1].
    double max_step_fraction = 0.25;
    /// An edge shorter than this fraction of the median segment length (of the layers being
    /// untangled, at the start of each pass) does not bound the steps of its vertices
    /// (max_step_fraction): the bound reaches past it, to the first vertex along the layer at
    /// least that far away (at most 8 edges on). Nearly coincident vertices (a slice of a mesh
    /// cut close to its vertices) would otherwise hold each other still. 0: every adjacent
    /// edge bounds. >= 0, finite. docs/untangle.md, "Short edges".
    double short_edge_fraction = 0.0;
    /// Interior points tested on each edge, at least (1 = the midpoint): a chord between two
    /// good vertices can still cut a neighbour. >= 0.
    int edge_samples = 1;
    /// Longer edges get more points, one every 4 x `sample_spacing` (scene units, >= 0), plus
    /// the feet of the other layers' vertices closer to the edge than the largest required
    /// separation (at least min_separation) + 2 x `sample_spacing`, and than half the edge's
    /// length, so that a neighbour's vertex poking through a long chord is seen; at most 64 of
    /// each per edge.
    /// 0 = automatic: the smallest per-layer median segment length (the finest layer's detail).
    double sample_spacing = 0.0;
    ShapeMode shape = ShapeMode::ShapeMatching;  ///< Shape preservation between projections.
    double alpha = 0.8;  ///< Shape-matching stiffness for layers without their own, [0, 1].
    double beta = 0.9;   ///< Quadratic share for layers without their own, [0, 1].
    /// epsilon: a pass has converged when the mean displacement of the free vertices in the last
    /// projection step of a round (V, Eq. 7) is <= tolerance * scene diagonal. > 0.
    double tolerance = 1e-6;
    int max_rounds = 1;  ///< Cap on rounds per pass. >= 1.
    /// Passes: when a pass ends with the region still tangled, the fields are brought up to
    /// date with the current geometry and the untangling runs again. >= 1.
    /// The defaults (64 passes of one round of 10 steps; shape matching toward the input
    /// before every round but the first) refresh the fields often: with the finishing stage,
    /// 12 concentric loops of 15 vertices (172 crossings) untangled in 1.3 s on one core
    /// against 26 s with 8 passes of 60 rounds of 30 steps (docs/untangle.md).
    int max_passes = 64;
    /// Smallest separation the untangling aims for between any two constrained layers, scene
    /// units, >= 0, used where the thicknesses ask for less: layers of zero thickness would
    /// otherwise be projected onto each other and touch. 0 = automatic: 1% of the median
    /// segment length of the scene, and with the grid backend at least a quarter voxel (the
    /// grid cannot see a smaller gap through its interpolation error).
    double min_separation = 0.0;
    /// Guarantee: a separation passes when gap >= required * (1 - tol). [0, 1).
    double separation_tolerance = 0.1;
    /// Give up early on an untangling that would not finish in time: from the fifth pass on,
    /// the worst violation |fhat - f| over the samples of a pass's first projection step,
    /// extrapolated to the last pass at the geometric mean of its last two rates of decrease,
    /// would still exceed what the final check tolerates below the separation aimed for
    /// (separation_tolerance x the smallest required separation of the constrained pairs).
    /// Never when a constrained pair requires less than min_separation (zero thickness: only
    /// crossings fail, and the violation does not tell). The untangling then ends as not
    /// collision-free. false: every pass runs. simplify() leaves it off, but its untanglings of
    /// rolled vertices give up this way (docs/simplify.md).
    bool give_up_when_stalled = false;
    /// Finishing stage: before every check, the layers still closer than the gap aimed for
    /// (max(required, min_separation)) are pushed apart exactly on the polylines, by
    /// Gauss-Seidel projection of point-segment distance constraints weighted by the layer
    /// weights, on the side the nesting asks for, with every move validated so that nothing
    /// tunnels or crosses. The projection takes the crossings out, this stage brings the
    /// gaps. false: projection and shape matching only (the paper).
    bool finish_separations = true;
    /// untangle_inferring_sides() only: when neither the inferred sides nor the global order
    /// come out clean, at most this many other readings of the input's regions are tried
    /// (InputSides::region_alternatives(), two tries each). 0: none (a caller with another
    /// attempt of its own left, e.g. strata simplify's untangling of a crossing input with
    /// the gap rule before the one without it).
    std::size_t other_readings = 4;
    /// untangle_inferring_sides() without an original, when every try has failed, the
    /// retries included: the readings of InputSides::loop_readings() of the inferred sides
    /// (a small closed loop read on both sides of an open layer, all on one side), each as a
    /// first try then as a second try; the first clean result is kept (report.loop_reading).
    bool loop_readings = true;
    /// untangle_inferring_sides(), when every try has failed and the least tangled result (the
    /// input, when no try was less tangled) has self-crossings (which neither the projection
    /// nor the finishing stage takes out): each moved by one vertex straight across the other
    /// segment's line, or off it when on it (the shortest such move that leaves fewer segments
    /// of the layer met and no more of other layers), then one more
    /// try from there by the same sides, with no self-crossing made; kept when clean
    /// (report.untwisted).
    bool untwist = true;
    /// untangle_inferring_sides(), when every try has failed (the untwisting too, if it ran):
    /// the ends of open layers of the least tangled result (the input, when no try was less
    /// tangled) whose end segment meets another segment or whose end vertex is on the wrong
    /// side of a layer or too close to it, moved back along their own end segment where the
    /// check (by the sides that result was tried with) counts fewer crossings, self-crossings,
    /// nesting violations or separation violations (in that order), then one more try from
    /// there by the same sides, with no self-crossing made; kept when clean
    /// (report.ends_retracted). An end moves by less than its end segment's length.
    bool retract_ends = true;
    /// untangle_inferring_sides(), when every try has failed (the untwisting too, if it ran)
    /// and the least tangled result is not the input: untangle()'s two tries, long rounds and
    /// the retry with more passes once more from that result, by the sides it was tried with;
    /// kept when clean (report.restarted).
    bool restart = true;
    /// untangle_inferring_sides() only: when every try fails (without params.input_sides:
    /// inferred sides, global order, other readings; first and second tries), all of them
    /// run once more from the input with gradient_steps x this factor (rounds this many times
    /// longer, so shape matching, which pulls toward the tangled input, comes this many times
    /// less often per projection step); the first clean result of those is kept. <= 1: no such
    /// retry. A scene that an earlier try cleans never gets here (its output is unchanged). A
    /// scene with rolled regions by its inferred sides instead runs the tries by those sides
    /// with long rounds when their first two fail, before the global order's, and not after
    /// every try (where the sides are in question, longer rounds by the global order or another
    /// reading let a wrong reading hold). untangle() itself does not retry. docs/untangle.md,
    /// "Longer rounds when every try fails".
    int long_rounds_factor = 3;
    /// untangle_inferring_sides() only: when every try fails, long rounds and more_passes_factor's
    /// retry included, all of them (as above, long rounds too) run once more from the input with
    /// max_passes x this factor (rounded down); the first clean result of those is kept. The
    /// projection of a fold cut by chords can wander for more than max_passes passes before it
    /// comes out clean, under any reading; more passes for every try from the start would let wrong
    /// readings hold that fewer passes leave failing (docs/untangle.md, "More passes when every try
    /// fails"). <= 1 (or max_passes x this below max_passes + 1): no such retry.
    double retry_passes_factor = 1.5;
    /// untangle_inferring_sides() without params.input_sides only, for a scene without rolled
    /// regions by its inferred sides (the global order is its reading): when every try has
    /// failed, long rounds included (before retry_passes_factor's retry), the global order's
    /// second try (no self-crossing made) runs once more from the input with max_passes x this
    /// factor (the projection of a fold cut by chords wanders for a while before it comes out
    /// clean). <= 1: no such retry. docs/untangle.md, "More passes when every try fails".
    int more_passes_factor = 4;
    /// untangle_inferring_sides() only: when every try has failed (all of the above, with or
    /// without params.input_sides), the last retry: by params' own sides (the global order, or
    /// the original's), with an open layer left out of the composition past one of its ends
    /// only where its nearest feature is that end (not wherever its border field is negative,
    /// which far from the ends says nothing: a layer folded back beside its own end), the
    /// first try, then the second (no self-crossing made). false: no such retry.
    /// docs/untangle.md, "Ends read by the nearest feature".
    bool retry_ends_by_nearest = true;
    /// untangle_inferring_sides() only: when everything else has failed, the last resorts
    /// included, untangle()'s first and second tries once more from the input, by params' own
    /// sides, with short_edge_fraction at this value; the first clean result is kept
    /// (report.short_edges). Not above short_edge_fraction: no such retry. >= 0, finite.
    double retry_short_edge_fraction = 0.1;
    /// untangle_inferring_sides() without params.input_sides only, on a scene with both closed
    /// and open layers, when the call comes out clean: untangle()'s tries once more from the
    /// input by the sides the result kept (the same reading), with every closed layer's weight
    /// times this factor (a closed layer is the cross-section of a body, a limb or a cord,
    /// stiffer than the open sheets around it); that result is kept when it is clean and its
    /// vertices moved less on average (report.stiffer_closed). Where an open layer's chord cut
    /// across a closed layer, equal weights let the closed layer cave in under it. Off by
    /// default, not yet measured on every workload: docs/untangle.md, "Closed layers stiffer".
    /// <= 1: no such call.
    double stiffer_closed = 1.0;
    /// Field backend and resolution. The exact indexed backend is the default here: on the
    /// local scenes of the untangling it builds 40-100x faster than the grid and answers
    /// queries as fast (docs/field.md, README "Benchmarks"). FieldParams::region is set by the
    /// untangling: the box of the free vertices and their neighbours where they lie in a part
    /// of the scene (untangle_local(), the simplification's jobs; a region given here is
    /// added to it), none where every vertex is free.
    FieldParams field = {FieldBackend::ExactIndexed};
    CompositionParams composition;  ///< Composition solver settings.
    /// Outside sides of the open layers (+1 or -1 per layer, see outside_side(); entries of
    /// closed layers are ignored), e.g. those of the original a decimated scene comes from:
    /// they orient the open layers' fields and say which side of them is "over". Empty:
    /// outside_side() of the scene being untangled. simplify() takes its input's (leave empty).
    std::vector<int> outside_sides;
    /// Sides to keep, recorded in the scene the untangled one comes from (record_input_sides())
    /// and carried onto its vertices (InputSides::renumbered(), or InputSides::matched() when
    /// the vertex correspondence is not known), or nullptr. Where a vertex has a recorded side
    /// of an open layer under or over its own that is not the global order's (a rolled or
    /// folded-over part), the untangling keeps it there: the composition takes that layer's
    /// field with its sign changed, the finishing stage pushes the vertex toward that side, and
    /// the final check judges nesting against the recorded sides (CheckParams::input_sides);
    /// around an end of that layer only the distance counts. Elsewhere the global order
    /// decides, as without it. Not owned; must outlive the call. simplify() records its own
    /// input's (leave nullptr).
    const InputSides* input_sides = nullptr;
    /// With params.input_sides recorded in the original (not inferred from the tangled scene
    /// itself): where the decimation cut a roll's bend, leaving a sharp hairpin of an open layer
    /// (the two segments at an interior vertex more than 120 degrees apart) and a vertex of
    /// another layer near its tip, outside its wedge, whose side asks to be inside it, the
    /// finishing stage moves the tip past that vertex (the bend opens again) instead of leaving
    /// the projection to drag the vertex, and its layer, around the tip into the wedge
    /// (docs/untangle.md, "Cut bends"). Only in scenes with rolled vertices (a side that is not
    /// the global order's). untangle_inferring_sides() and `strata untangle --infer-sides` turn
    /// it off: inferred sides can be wrong exactly there. simplify() does not use it.
    bool open_cut_bends = true;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const UntangleParams& params);

/// What an untangling did.
struct UntangleReport {
    /// Untanglings run from the input: 1, or more where untangle() and
    /// untangle_inferring_sides() try again (a second try, other readings, long rounds).
    /// passes, rounds, finishes, finish_moves and the seconds count all of them; the other
    /// fields are those of the result kept.
    int tries = 0;
    int passes = 0;          ///< Passes run (fields built from the current geometry).
    int rounds = 0;          ///< Rounds run, over all passes.
    bool converged = false;  ///< The last pass met the tolerance before max_rounds.
    bool collision_free =
        false;  ///< Final exact check: no crossing, nesting kept, separations within tolerance.
    std::size_t free_vertices = 0;   ///< Vertices allowed to move.
    std::size_t moved_vertices = 0;  ///< Vertices that moved by more than 1e-12 * diagonal.
    double max_displacement = 0.0;   ///< Largest distance of a vertex from its start, scene units.
    double mean_speed = 0.0;         ///< Last round's V (Eq. 7), scene units per step.
    bool gave_up = false;            ///< Ended early by UntangleParams::give_up_when_stalled.
    std::size_t crossings_before = 0, crossings_after = 0;  ///< Between layers (check_scene).
    std::size_t self_crossings_before = 0, self_crossings_after = 0;  ///< check_scene's.
    /// check_scene's, judged by the sides the untangling keeps (input_sides, outside sides).
    std::size_t nesting_violations_before = 0, nesting_violations_after = 0;
    /// check_scene's, +inf when nothing is required.
    double min_separation_ratio_before = 0.0, min_separation_ratio_after = 0.0;
    int finishes = 0;              ///< Runs of the finishing stage (finish_separations).
    std::size_t finish_moves = 0;  ///< Vertex moves the finishing stage made.
    double seconds_fields = 0.0, seconds_untangle = 0.0, seconds_check = 0.0;
    double seconds_finish = 0.0;  ///< Time in the finishing stage.
    /// With params.input_sides: vertices whose recorded side of an open layer is not the one
    /// the global order gives (rolled or folded over; once per other layer, as
    /// InputSides::rolled_count()), and of those, the ones still on that side at the end (not a
    /// nesting violation of the final check).
    std::size_t rolled_vertices = 0, rolled_kept = 0;
    /// Of rolled_vertices, the ones on that side in the input (whole-scene untanglings only).
    std::size_t rolled_kept_before = 0;
    /// untangle_inferring_sides(): the result kept the sides inferred per region of the input
    /// (infer_input_sides()), which has rolled regions; when every try failed, the result kept
    /// is a try by those sides (its counts are judged by them).
    bool inferred_sides = false;
    /// With inferred_sides: 0 when the kept sides are the input's regions as inferred
    /// (InputSides::by_region()); i > 0 when neither those nor the global order came out clean
    /// and the kept sides are the i-th other reading (InputSides::region_alternatives()), or
    /// with end_sides_dropped, the first without its sides around the ends.
    std::size_t sides_reading = 0;
    /// untangle_inferring_sides() without an original: the input has rolled regions, the
    /// tries by them failed, and the result is that of the first other reading of the regions
    /// with no side around another layer's end (InputSides::without_end_sides()), tried
    /// before the global order (sides_reading 1).
    bool end_sides_dropped = false;
    /// untangle_inferring_sides(): the result is that of the tries once more with the closed
    /// layers stiffer (UntangleParams::stiffer_closed), which moved the vertices less on average
    /// than the first clean result; the other flags are the first result's (its reading), the
    /// counts after and the displacement the second's.
    bool stiffer_closed = false;
    /// untangle(): the first try did not come out clean, and the result is the second, from
    /// the input, in which no vertex move makes a self-crossing.
    bool kept_simple = false;
    /// untangle_inferring_sides(): the tries with params.gradient_steps failed (where rolled
    /// regions are read, those by the inferred sides), and the result is that of the tries with
    /// params.long_rounds_factor times as many.
    bool long_rounds = false;
    /// untangle_inferring_sides(): every try failed, long rounds and the more_passes retry
    /// included, and the result is that of their retry with params.retry_passes_factor times
    /// the passes.
    bool retry_passes = false;
    /// untangle_inferring_sides() without an original: every try failed, the retries included,
    /// and the result is a try by a reading that puts a small closed loop read on both sides
    /// of an open layer all on one side (InputSides::loop_readings(); sides_reading: its
    /// number there, from 1; params.loop_readings).
    bool loop_reading = false;
    /// untangle_inferring_sides(): every try failed, and the least tangled result had
    /// self-crossings; the result is that one with them taken out one vertex move at a time,
    /// then one more try from there (params.untwist).
    bool untwisted = false;
    /// untangle_inferring_sides(): every try failed (untwisted too, if tried); the result is
    /// the least tangled one with this many ends of open layers moved back along their end
    /// segments, then one more try from there (params.retract_ends). 0 otherwise.
    std::size_t ends_retracted = 0;
    /// untangle_inferring_sides(): every try failed (untwisted too, if tried), and the result
    /// is that of untangle()'s tries, long rounds and more passes once more from the least
    /// tangled result, by the sides it was tried with (params.restart).
    bool restarted = false;
    /// untangle_inferring_sides(): every try failed, long rounds included, and the result is the
    /// global order's second try with params.more_passes_factor times the passes.
    bool more_passes = false;
    /// untangle_inferring_sides(): every try failed, and the result is one of the last retry,
    /// with the ends read by the nearest feature (UntangleParams::retry_ends_by_nearest).
    bool ends_by_nearest = false;
    /// untangle_inferring_sides(): everything else failed, and the result is one of the tries
    /// with the short edges passed (UntangleParams::retry_short_edge_fraction).
    bool short_edges = false;
    /// untangle(), untangle_inferring_sides(): no try came out clean and none was less tangled
    /// than the input, which is the result, unchanged (moved_vertices 0; the counts after are
    /// the input's). When every try fails, the result kept is the least tangled of theirs and
    /// the input (docs/untangle.md, "When every try fails").
    bool input_kept = false;
    /// untangle_inferring_sides() with params.input_sides: how many vertex sides (one per
    /// vertex and other layer) the result kept leaves out, the sides read at a fold's other
    /// sheet (InputSides::off_other_sheets()); 0 when it kept every side.
    std::size_t sides_left_out = 0;
};

/// @brief Untangles the whole scene (the global mode): every vertex may move. Layers keep the
/// global order, except where params.input_sides gives a vertex another side. When the first
/// try is not clean, a second from the input (report.kept_simple); when neither is, the result
/// is the least tangled of the two and the input (report.input_kept: the input, unchanged),
/// by crossings between layers plus self-crossings, then nesting violations, then the larger
/// min separation ratio, then the smaller max displacement; on a tie the earlier try, the input
/// only when strictly less tangled. The report's counts after are the result's.
/// @param scene     modified in place; unchanged on throw.
/// @param progress  called once per round ("untangle", fraction; from the second try on, the
/// stage is "untangle, try N"); false cancels (throws Cancelled).
/// @throws InvalidInput bad params, or params.outside_sides / params.input_sides not of the
/// scene's layer count.  @throws Cancelled.
UntangleReport untangle(Scene& scene, const UntangleParams& params = {},
                        const ProgressFn& progress = {});

/// @brief untangle() when no original is at hand (what `strata untangle` does by default):
/// where the input has regions on the other side of an open layer than the global order says
/// (a part rolled or folded over an open layer, which the global order pushes back), by the
/// sides inferred per region of the input (infer_input_sides()), so that a rolled part stays
/// rolled, both of untangle()'s tries (the second when the first is not clean), then both with
/// params.long_rounds_factor times the gradient steps (report.long_rounds); a result is kept
/// when it is clean against those sides (report.inferred_sides). When none is clean (and
/// params.other_readings > 0), both tries by the first other reading of the regions (below)
/// with no side around another layer's end (InputSides::without_end_sides(); their failed
/// results are not kept; report.end_sides_dropped). Otherwise, or when none is
/// clean, by the global order (untangle() from the input); where nothing is read rolled and the
/// global order's try is not clean, by the inferred sides, which are then the global order's but
/// give no side to the vertices around another layer's end (there only the distance counts),
/// each first try before the second. When neither is clean, by
/// each of the first 4 other readings of the inferred regions (InputSides::region_alternatives() of
/// the input's recorded sides: a region whose vertices' sides disagree, split in two or given the
/// other side), first as untangle()'s first try, then as its second; the first round with a clean
/// result keeps the clean one that moves a vertex least (report.inferred_sides, `kept` those
/// sides). When every try fails and nothing is read rolled, they all run once more with
/// params.long_rounds_factor times the gradient steps (report.long_rounds); when those fail too
/// (and nothing is read rolled), the global order's second try with
/// params.more_passes_factor times the passes (report.more_passes); when that fails too, all of
/// the tries and long rounds once more with params.retry_passes_factor times the passes
/// (report.retry_passes). With params.input_sides given (an original's sides, not in question),
/// untangle(), when it fails once more with the long rounds, and when those fail all of that
/// with params.retry_passes_factor times the passes; all of that first without the sides read
/// at a fold's other sheet (InputSides::off_other_sheets(); report.sides_left_out, `kept` those
/// sides), then, when some were left out and that is not clean, with every side. When all of
/// that fails: params' own sides' first and second tries with the ends read by the nearest
/// feature (params.retry_ends_by_nearest, report.ends_by_nearest); without an original, the
/// loop readings (params.loop_readings); then, with or without, the least tangled result's
/// self-crossings untwisted and one more try from there (params.untwist), then its ends that
/// poke through or lie on the wrong side retracted and one more try (params.retract_ends),
/// then untangle()'s
/// tries once more from that result (params.restart), each kept when clean; then, from the
/// input, params' own sides' first and second tries with the short edges passed
/// (params.retry_short_edge_fraction, report.short_edges). When every try
/// fails, the result is the least tangled of all their results and the input, as untangle()
/// orders them, each try judged by the sides it untangled toward (report.inferred_sides and
/// sides_reading say which). Once a try has failed, the tries of a list that all start from
/// the same input (first and second tries, the inferred sides and the global order, the other
/// readings, the ends read by the nearest feature, the loop readings) run two at a time where a
/// TBB worker thread is idle (none with tbb::global_control's max_allowed_parallelism at 1):
/// the result, the report and the progress calls are those of one try at a time, but the
/// seconds, summed over the tries, can exceed the call's time. `progress` is called from the
/// calling thread only, the calls of one try after another's; a try started ahead that is not
/// needed (an earlier one came out clean) is stopped, and neither counts nor is seen.
/// Same params, progress and throws as untangle(). `kept`: if given,
/// receives the inferred sides when they were kept (a clean result's, or a failed one's), for
/// judging the result (check_scene() with them and params' outside sides, or outside_sides() of
/// the input); left alone otherwise.
UntangleReport untangle_inferring_sides(Scene& scene, const UntangleParams& params = {},
                                        const ProgressFn& progress = {},
                                        InputSides* kept = nullptr);

/// @brief Untangles only the vertices of `scene` inside `box`, with collars of `n_out` fixed
/// vertices (localize()). The fields are built for whole layers here; the simplification
/// driver keeps them and updates them only inside its boxes. The input is checked whole once;
/// the later checks look only near the pieces (RegionCheck over their box grown by half its
/// larger side), with the verdicts and counts of whole checks.
UntangleReport untangle_local(Scene& scene, const Box2& box, std::size_t n_out = 7,
                              const UntangleParams& params = {}, const ProgressFn& progress = {});

}  // namespace strata
