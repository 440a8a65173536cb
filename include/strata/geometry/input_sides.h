#pragma once
/// @file Sides from the input: for each vertex near an open layer, the side of that layer it
/// lies on in the input. A rolled sleeve or a turned-back cuff has part of an inner layer lying
/// on top of an outer one without any crossing; there the global order (every vertex of a
/// layer below every layer above it) does not hold, and the input's own local side is the
/// order to keep. Far from the other layer the input says nothing and the global order
/// decides, as it does everywhere for closed layers (inside / outside is global there).

#include "strata/geometry/predicates.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace strata {

/// Parameters of record_input_sides(). Lengths are in scene units.
struct InputSideParams {
    /// A vertex gets a side of an open layer when its closest point there is closer than this
    /// (and not an end point of the layer). 0 = automatic: 3 x the exact check's automatic
    /// near distance (automatic_near_distance(): max(5% of the bounding-box diagonal, 2 x the
    /// largest required separation)), the distance within which check_scene() judges sides.
    /// More than that distance, so that a rolled part lying a few gaps over the other layer
    /// (farther than the near distance in the input) keeps its side when the simplification
    /// brings it closer. A vertex farther than the reach is judged by the global order. >= 0.
    double reach = 0.0;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const InputSideParams& params);

/// The recorded sides. side(a, k, b) is the side of open layer b that vertex k of layer a lies
/// on: +1 right of b's direction of travel, -1 left, 0 nothing recorded (b closed, a and b side
/// by side, farther than the reach, closest to an end point of b, or on b).
///
/// Sides are found when first asked for (one nearest query in the recorded scene, then kept):
/// a simplification asks only for the vertices it moves and the ones it keeps, a few percent
/// of the input. Copies share what was found. Safe to query from several threads at once.
class InputSides {
  public:
    InputSides() = default;

    /// Number of layers (0: nothing recorded).
    std::size_t size() const { return n_; }
    bool empty() const { return n_ == 0; }
    /// See the class comment; 0 for indices out of range.
    int side(std::size_t a, std::size_t k, std::size_t b) const {
        const int s = code(a, k, b);
        return s == kBeyondEnd ? 0 : s;
    }
    /// Vertex k of layer a is within the reach of open layer b but closest to one of its end
    /// points (around the end of b, e.g. on the bend of a roll): it has no side of b.
    bool beyond_end(std::size_t a, std::size_t k, std::size_t b) const {
        return code(a, k, b) == kBeyondEnd;
    }
    /// The same sides for a scene with the same layers whose vertex k of layer a is vertex
    /// origin[a][k] of this one (a simplification keeps vertices and their order).
    /// @throws InvalidInput when origin has the wrong layer count or an index out of range.
    InputSides renumbered(const std::vector<std::vector<std::size_t>>& origin) const;
    /// The sides for `scene`, whose layers are those of `reference` (the scene these sides were
    /// recorded in) matched by name, when the vertex correspondence is not known (`strata
    /// check --reference`): each vertex takes the sides of the reference vertex that ends the
    /// closest segment of its layer's reference nearest to it, except that on an open layer a
    /// run of vertices that moved (not on a reference vertex), between two that did not, whose
    /// matches leave the reference's order (a vertex nearer another sheet of a roll) takes the
    /// reference vertices in order nearest in all, each vertex choosing among those near it on
    /// every sheet of the stretch that passes near it (so that a vertex moved nearer another
    /// sheet than its own, such as a roll's end pulled toward the layer's main part, keeps its
    /// own sheet where the order says so). Layers without a namesake get none.
    static InputSides matched(const InputSides& recorded, const Scene& reference,
                              const Scene& scene);
    /// These sides (recorded in another scene, e.g. matched()'s) for `scene`, the scene they
    /// are for, except that a vertex of layer a whose side of open layer b in `scene` is not
    /// its recorded one, whose closest segment of b in `scene` runs against the one closest to
    /// its recorded vertex in the recorded scene (negative dot product of the directions), and
    /// whose recorded vertex has the other side of the stretch of b between the recorded
    /// vertices of that segment's ends, gets no side of b, as around b's end: it lies outside a
    /// fold of b that the decimation closed, nearer the fold's other sheet than its own, and
    /// its side read at that sheet asks for the wrong side of both sheets. (A vertex between
    /// the sheets, such as a jacket's end in a shirt's roll, has the same side of both and
    /// keeps it.) Sides as codes of `scene` (no query later).
    /// @throws InvalidInput a scene of another layer count.
    InputSides off_other_sheets(const Scene& scene) const;
    /// The same sides made consistent along each layer, for sides recorded in a scene that is
    /// itself tangled (`scene`, the one recorded): the vertices of layer a with a side of open
    /// layer b fall into regions, runs of consecutive vertices joined by a segment that keeps
    /// its side or crosses b (a tangle: one end is on the wrong side); a segment that changes
    /// side without meeting b goes around b's end and starts another region (a roll). Every
    /// vertex of a region takes the side of the majority of its vertices (a tie: no side),
    /// except that a closed layer whose vertices all form one region and disagree (a loop all
    /// within reach of b, e.g. a cord in a fold of b) takes the side of its vertex centroid
    /// (its bulk), when that side is defined (the centroid's closest point on b not an end).
    /// A closed layer at most half b's size (bounding-box diagonals) in a fold of b takes, all
    /// of it but its vertices around b's end, the side its vertices are on by every segment of
    /// b nearer than the automatic near distance whose closest point is inside the segment
    /// (both arms of the fold, not only the nearest), when those segments include two that run
    /// opposite ways (a fold) and the count is not a tie.
    ///
    /// With `outside_sides` (outside_side() per layer of `scene`, e.g.
    /// untangling_outside_sides()), an open layer all of whose vertices with a side of b come
    /// out on the other side than the global order's takes the global order's side of b: a
    /// roll is part of a layer, and a whole layer read over the one above it is their order
    /// read inside out. So does a closed layer larger than half b's size (no fold of b can
    /// hold it: a body wrapped by b). Unless the open layer turns back around b's end (a
    /// vertex within the reach of b's end point, reached travelling out past that end and
    /// left travelling back, whether its bend is around the end or the decimation cut it
    /// across b): a layer that goes around b's end comes back on b's other side, so its parts
    /// between such turns lie on b's sides in turn; of the two readings that alternate, the
    /// one with more of the vertices recorded with a side on the global order's side is kept
    /// (a tie: all on that side). And a region of an open layer read on the other side, next
    /// to one on the global order's side with no such turn in their span, takes the global
    /// order's side: the layer did not go around b to get there (a chord of b cut across it).
    /// Empty: no such rule. @throws
    /// InvalidInput a scene or `outside_sides` of another layer count.
    InputSides by_region(const Scene& scene, const std::vector<int>& outside_sides = {}) const;
    /// Other readings of the sides by_region(scene) infers, for when the untangling by those
    /// is not clean: one per region whose vertices' recorded sides disagree, each the sides of
    /// by_region() with that one region read otherwise. A region of an open layer whose
    /// recorded sides two runs fit better than one side (the most vertices agreeing, e.g. a
    /// roll whose bend the decimation cut across the other layer, which by_region() takes for
    /// a tangle) is split in two there, unless its vertices disagree only by pokes (a run on
    /// the other side of b entered and left across one and the same segment of b: b's chord
    /// cut across the layer, not a cut bend, which crosses b once), then it is not read
    /// otherwise; any other takes the side by_region() did not give it (both sides on a tie).
    /// Ordered by the share of the region's vertices the reading agrees with, less the majority's
    /// share, highest first (a split first, then the closest votes). With `outside_sides` (as
    /// by_region()'s), first of all: for each closed layer larger than half open layer b's size
    /// read on the global order's side of b in part only, all of it on that side (no fold of b
    /// holds any part of it, so the rest is likely a tangle).
    std::vector<InputSides> region_alternatives(const Scene& scene,
                                                const std::vector<int>& outside_sides = {}) const;
    /// Readings of the small closed loops these sides (for `scene`, e.g. by_region()'s) put
    /// on both sides of an open layer b: a loop at most half b's size (bounding-box
    /// diagonals) whose vertices with a side of b have both signs lies on one side of b,
    /// unless it runs around b's end. Per such pair (layer order), two readings, each these
    /// sides with every signed side of the loop's vertices made one: first the side most of
    /// them have (a tie: +1), then the other. by_region() splits a loop into regions where a
    /// segment changes side without meeting b, and region_alternatives() reads no region
    /// otherwise when each agrees with itself: the collar at 95%, seed 57 (out of sample),
    /// had its cord read `-+++-` (the original: `+++++`). Empty: no such loop.
    /// @throws InvalidInput a scene of another layer count.
    std::vector<InputSides> loop_readings(const Scene& scene) const;
    /// These sides (for `scene`, e.g. a reading of region_alternatives()) with no vertex
    /// around an end: where beyond_end() holds, the vertex has no side, and the global order
    /// judges it, as it does a far one. A reading that is wrong only around a decimated end
    /// (the shirt at 95%, seed 60, out of sample: body vertices read around the shirt's end
    /// held the shirt's roll open) may be right without those.
    /// @throws InvalidInput a scene of another layer count.
    InputSides without_end_sides(const Scene& scene) const;
    /// Vertices whose recorded side is not the one the global order asks for (`outside_sides`:
    /// outside_side() per layer of `scene`, the scene these sides are for): the rolled or
    /// folded-over vertices, once per other layer. Finds the side of every vertex.
    std::size_t rolled_count(const Scene& scene, const std::vector<int>& outside_sides) const;

  private:
    static constexpr signed char kBeyondEnd = 2;
    /// The recorded scene, its segment indices and the sides found so far (input_sides.cpp).
    struct Recorded;
    /// The side code of vertex k of layer a against layer b (0, +-1 or kBeyondEnd).
    int code(std::size_t a, std::size_t k, std::size_t b) const;
    /// Vertices of layer a of the scene these sides are for.
    std::size_t vertex_count(std::size_t a) const;
    /// Sides for `scene` given as codes: codes[a * n + b][k] for vertex k of layer a against
    /// layer b (empty: none).
    static InputSides from_codes(const Scene& scene, std::vector<std::vector<signed char>> codes);
    /// These sides for `scene` as codes (from_codes()'s); a pair with no code but 0 is empty.
    /// `what`: the caller, named in the error. @throws InvalidInput another layer count.
    std::vector<std::vector<signed char>> codes_for(const Scene& scene, const char* what) const;
    /// One other reading of a region (region_alternatives()): pair a * n + b, the region's
    /// first vertex, its vertices' sides, and the agreement score it is ordered by.
    struct Alternative {
        std::size_t pair = 0, first = 0;
        std::vector<signed char> sides;
        double score = 0.0;
    };
    /// The codes of by_region(scene); with `split`, the other readings of its regions too.
    std::vector<std::vector<signed char>> region_codes(const Scene& scene,
                                                       const std::vector<int>& outside_sides,
                                                       std::vector<Alternative>* split) const;
    friend InputSides record_input_sides(const Scene&, const InputSideParams&);

    static constexpr std::size_t kNoLayer = static_cast<std::size_t>(-1);
    std::size_t n_ = 0;
    std::shared_ptr<const Recorded> recorded_;
    /// Layer of this view -> recorded layer (kNoLayer: none); empty: the same layers.
    std::vector<std::size_t> layer_;
    /// Per layer of this view, the recorded vertex of each vertex; empty: the same vertices.
    std::vector<std::vector<std::size_t>> origin_;
};

/// @brief Records the side of every vertex of `scene` against every open layer under or over
/// its own layer within params.reach, with the rule check_scene() uses (the side at the
/// closest point; at a corner, the side of the corner's wedge). Keeps a copy of `scene`; each
/// side is found when first asked for (see InputSides).
/// @throws InvalidInput bad params.
InputSides record_input_sides(const Scene& scene, const InputSideParams& params = {});

/// @brief Sides inferred from a tangled scene alone (no original at hand):
/// record_input_sides(scene, params).by_region(scene, outside_sides). A rolled part, a whole
/// region on the other side of an open layer, keeps that side; a vertex that a tangle put on
/// the wrong side takes its region's. @throws InvalidInput bad params.
InputSides infer_input_sides(const Scene& scene, const InputSideParams& params = {},
                             const std::vector<int>& outside_sides = {});

/// The side rule of check_scene() where the closest point of a polyline to `v` is the corner
/// `w` between its segments (u, w) and (w, x): +1 right of the direction of travel, -1 left.
/// The side of the corner's inner wedge is the one v is on when it lies in that wedge (on both
/// segments' inner side); straight corners fall back to the segments' own sides. Always inlined:
/// check_scene() asks it for every vertex near an open layer (called, its check was 6% slower).
[[gnu::always_inline]] inline int corner_side(const Vec2& u, const Vec2& w, const Vec2& x,
                                              const Vec2& v) {
    const int turn = orient2d(u, w, x);
    const int o1 = orient2d(u, w, v);
    const int o2 = orient2d(w, x, v);
    if (turn > 0) return (o1 > 0 && o2 > 0) ? -1 : 1;  // the left side is the inner wedge
    if (turn < 0) return (o1 < 0 && o2 < 0) ? 1 : -1;  // the right side is the inner wedge
    return o1 != 0 ? -o1 : -o2;
}
/// The side rule where the closest point is inside segment (a, b): -orient2d(a, b, v).
[[gnu::always_inline]] inline int segment_side(const Vec2& a, const Vec2& b, const Vec2& v) {
    return -orient2d(a, b, v);
}

/// The side of open layer b that a vertex of layer a must lie on by the global order:
/// -outside (the inside) when a is under b, +outside when over, 0 otherwise (side by side,
/// same layer). `outside`: outside_side() of b.
int global_side(Relation relation_of_a_to_b, int outside);

}  // namespace strata
