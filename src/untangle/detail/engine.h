#pragma once
/// @file The untangling engine shared by untangle() and the simplification driver: passes of
/// projection + shape matching over fields built from a work scene whose layers may stand for
/// layers (or parts of layers) of another scene.

#include "strata/geometry/input_sides.h"
#include "strata/untangle/untangle.h"

#include <functional>
#include <vector>

namespace strata::detail {

/// Where the layers of a work scene take their nesting, separations and weights from.
struct RelationSource {
    const Scene* scene = nullptr;     ///< The scene that holds the nesting.
    std::vector<std::size_t> parent;  ///< Work layer -> layer of `scene`; empty: identity.

    std::size_t of(std::size_t i) const { return parent.empty() ? i : parent[i]; }
    /// Parts of one layer do not constrain each other.
    Relation relation(std::size_t a, std::size_t b) const {
        return of(a) == of(b) ? Relation::Same : scene->relation(of(a), of(b));
    }
    double separation(std::size_t a, std::size_t b) const {
        return of(a) == of(b) ? 0.0 : scene->required_separation(of(a), of(b));
    }
    double weight(std::size_t a) const { return scene->layer(of(a)).weight; }

    /// How a vertex takes the field of another layer (local sides, input_sides.h).
    enum class Side : unsigned char {
        Global,   ///< As the global order says.
        Flipped,  ///< On the other side: f_j with its sign changed (a rolled part).
        AnySide,  ///< Around an end of open layer j: only the distance counts.
    };
    struct LocalSide {
        std::size_t layer = 0;  ///< The other work layer j (open).
        Side side = Side::Global;
    };
    /// local_sides[i][k]: the work layers whose field vertex k of work layer i takes otherwise
    /// than the global order says, as the input has it. There the composition takes f_j with
    /// its sign changed (Flipped) or with the sign the nesting wants (AnySide: |f_j| kept),
    /// and the finishing stage wants the other side (Flipped) or any side (AnySide).
    /// Empty (or an empty entry): the global order.
    std::vector<std::vector<std::vector<LocalSide>>> local_sides;

    /// The local sides of vertex k of work layer i, or nullptr when none.
    const std::vector<LocalSide>* local_at(std::size_t i, std::size_t k) const {
        if (i >= local_sides.size() || k >= local_sides[i].size() || local_sides[i][k].empty())
            return nullptr;
        return &local_sides[i][k];
    }
    /// How vertex k of work layer i takes work layer j.
    Side side_of(std::size_t i, std::size_t k, std::size_t j) const {
        if (const std::vector<LocalSide>* all = local_at(i, k))
            for (const LocalSide& x : *all)
                if (x.layer == j) return x.side;
        return Side::Global;
    }
};

/// Sets relations.local_sides from sides recorded in relations.scene (input_sides.h): a vertex
/// whose recorded side of an open layer under or over its own is not the one the global order
/// gives (`outside_signs`: outside_side() of every layer of relations.scene) takes that layer's
/// work layers on its own side (Flipped), and a vertex around an end of that layer keeps its
/// distance on any side (AnySide). Vertex k of work layer i is vertex id_of(i, k) of layer
/// relations.of(i) (empty id_of: k itself); `work` gives the work layers' vertex counts.
/// Nothing is set when no vertex has such a side (local_sides stays empty). Shared by
/// untangle() (the whole scene) and the simplification driver (a job's runs).
void take_input_sides(RelationSource& relations, const Scene& work, const InputSides& sides,
                      const std::vector<int>& outside_signs,
                      const std::function<std::size_t(std::size_t, std::size_t)>& id_of = {});

/// Scene-wide settings of the engine, resolved once.
struct EngineSettings {
    double min_separation = 0.0;     ///< Resolved UntangleParams::min_separation (> 0).
    double sample_spacing = 0.0;     ///< Resolved UntangleParams::sample_spacing.
    std::vector<int> outside_signs;  ///< Per work layer, see outside_side().
    double diagonal = 1.0;           ///< Scene scale for the tolerance.
    /// Calls is_ok after every projection step rather than after every round: for callers
    /// whose check is local and cheap, a region stops as soon as it is good.
    bool check_every_step = false;
    /// Shape matching pulls toward the shape the engine started from, before every round but
    /// the very first, across passes. false: toward the shape at the start of each pass, from
    /// its second round on (untangle(), whose passes are long: each pass settles from where
    /// the previous one left the layers).
    bool rest_at_start = false;
    /// The projection steps and shape matching move no vertex so that its segments meet more
    /// segments of its own layer than before (the moves are taken one vertex at a time, in
    /// order): no self-crossing is made. untangle() only; the driver's untanglings (which
    /// check a region, whole layers being long) leave it off.
    bool keep_simple = false;
    /// Gives up on a stalled run as UntangleParams::give_up_when_stalled does (from the fifth
    /// pass, the same extrapolation), whatever the params say, but only while the last run of
    /// the finishing stage left a close vertex on the wrong side of another layer (a tangle
    /// that the projection does not take out; not gaps still short). The driver sets it for
    /// the jobs that hold a rolled vertex (a Flipped local side, RelationSource::local_sides),
    /// see JobRunner::local_sides().
    bool give_up_when_stalled = false;
    /// SeparationParams::stop_when_wrong_stays of the finishing stage (0: the sweeps run until
    /// they stall). The driver sets 1 for the jobs that hold a rolled vertex.
    int finish_stop_when_wrong_stays = 0;
    /// The composition leaves out an open layer at a point past one of its ends (border field
    /// b(x) <= 0) only where the layer's nearest feature is that end vertex
    /// (FieldSample::past_end; the grid cannot tell and leaves it out wherever b(x) < 0).
    /// false: wherever b(x) <= 0, which far from the ends says nothing (a layer folded back
    /// beside its own end: the folded stack's left fold past the ends of its bottom sheets).
    /// untangle_inferring_sides()' last retry (docs/untangle.md).
    bool ends_by_nearest = false;
    /// SeparationParams::open_cut_bends of the finishing stage: untangle() sets it from
    /// UntangleParams::open_cut_bends when sides are given; the driver leaves it off.
    bool open_cut_bends = false;
};

/// What run_engine() did.
struct EngineResult {
    int passes = 0, rounds = 0;
    bool converged = false;  ///< The last pass met the tolerance.
    bool ok = false;         ///< is_ok(work) held at the end.
    double mean_speed = 0.0;
    bool gave_up = false;  ///< Stopped by UntangleParams::give_up_when_stalled.
    int finishes = 0;              ///< Runs of the finishing stage (finish_separations()).
    std::size_t finish_moves = 0;  ///< Vertex moves it made.
    double seconds_fields = 0.0, seconds_untangle = 0.0, seconds_check = 0.0;
    double seconds_finish = 0.0;
};

/// The upper median of the segment lengths of `scene`, zero-length ones included (0 for
/// none): the scale of UntangleParams' automatic lengths.
double median_segment_length(const Scene& scene);

/// Resolves the automatic min_separation and sample_spacing from `scene` and the params, and
/// the outside signs (params.outside_sides where given, else outside_side() of `scene`).
EngineSettings resolve_settings(const Scene& scene, const UntangleParams& params);

/// Runs passes (fields built from `work` at the start of each) until is_ok(work) holds or
/// params.max_passes is reached. Only the free vertices of `pieces` move.
/// @throws Cancelled when `progress` returns false (work is then partly moved).
EngineResult run_engine(Scene& work, const std::vector<Piece>& pieces, const UntangleParams& params,
                        const RelationSource& relations, const EngineSettings& settings,
                        const std::function<bool(const Scene&)>& is_ok, const ProgressFn& progress);

}  // namespace strata::detail
