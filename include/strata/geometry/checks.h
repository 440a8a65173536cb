#pragma once
/// @file Exact checks that tell whether a multi-layered scene is collision-free: crossings,
/// self-crossings, separations and nesting.

#include "strata/core/types.h"
#include "strata/geometry/hausdorff.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <limits>
#include <vector>

namespace strata {

/// Parameters of check_scene(). Lengths are in scene units.
struct CheckParams {
    /// Pairs of layers farther apart than this are not "near" and get no separation entry.
    /// 0 = automatic: max(5% of the scene's bounding-box diagonal, 2 x the largest required
    /// separation). >= 0.
    double near_distance = 0.0;
    /// Relative tolerance on separations: a gap passes when gap >= required * (1 - tol). [0, 1).
    double separation_tolerance = 0.0;
    /// Cap on the locations and vertices listed in the report (counts are never capped). >= 0.
    std::size_t max_listed = 1000;
    /// Outside sides of the open layers (+1 or -1 per layer, see outside_side(); entries of
    /// closed layers are ignored), e.g. those of the input a simplified scene came from: the
    /// vote of outside_side() is unreliable on an open layer simplified to 2 or 3 vertices.
    /// Empty: outside_side() of `scene` itself.
    std::vector<int> outside_sides;
    /// Sides recorded in the scene the checked one comes from (record_input_sides(), then
    /// InputSides::renumbered() to the checked scene's vertices), or nullptr. Where a vertex
    /// has a recorded side of an open layer, the nesting against that layer asks for that side
    /// (a rolled part stays rolled); elsewhere the global order decides, as without it. Not
    /// owned; must outlive the call.
    const InputSides* input_sides = nullptr;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const CheckParams& params);

/// A point where two segments meet (layer_a == layer_b for a self-crossing).
struct Crossing {
    std::size_t layer_a = 0, segment_a = 0;  ///< Segment i joins point i to point i + 1 (mod n).
    std::size_t layer_b = 0, segment_b = 0;
    Vec2 point{0.0};        ///< Where they meet (rounded for proper crossings).
    bool is_touch = false;  ///< True: they touch or overlap (SegmentContact::Touch), not cross.
};

/// Closest approach of two near layers that must keep apart.
struct PairSeparation {
    std::size_t layer_a = 0, layer_b = 0;
    Relation relation = Relation::SideBySide;  ///< relation(layer_a, layer_b).
    double gap = 0.0;           ///< Minimum distance between the two polylines (0 if they meet).
    double required = 0.0;      ///< Scene::required_separation(layer_a, layer_b).
    Vec2 at_a{0.0}, at_b{0.0};  ///< Closest points.
    /// gap / required; +inf when required == 0.
    double ratio() const {
        return required > 0.0 ? gap / required : std::numeric_limits<double>::infinity();
    }
};

/// A vertex closer to another layer than required (tolerance applied).
struct SeparationViolation {
    std::size_t layer = 0, vertex = 0, other = 0;
    double distance = 0.0, required = 0.0;
};

/// A vertex on the wrong side of a layer it must stay under, over, or beside.
struct NestingViolation {
    std::size_t layer = 0, vertex = 0, other = 0;
    Relation expected = Relation::Under;  ///< relation(layer, other) that the vertex breaks.
};

/// What check_scene() found.
struct CheckReport {
    /// Contacts between different layers (all). Every properly crossing segment pair counts
    /// once. Touches (SegmentContact::Touch) count once per contact location: touches of the
    /// same two layers whose intersections have the same lexicographically smallest point
    /// (x, then y) merge, so a vertex lying on another layer, which touches two adjacent
    /// segments, or a shared corner, counts once. A collinear overlap counts once per pair of
    /// overlapping segments that starts it at a different point.
    std::size_t crossing_count = 0;
    std::size_t touch_count = 0;  ///< Of which touches / overlaps, not proper crossings.
    /// Listed ones (at most params.max_listed), in (layer_a, segment_a, layer_b, segment_b)
    /// order with layer_a < layer_b.
    std::vector<Crossing> crossings;
    /// Per layer: non-adjacent segments that meet (counted like crossing_count), plus adjacent
    /// segments that fold back onto each other (collinear, opposite directions). Segment n-1
    /// and 0 of a closed layer are adjacent; zero-length segments are skipped (their
    /// neighbours count as adjacent).
    std::vector<std::size_t> self_crossing_count;
    std::vector<Crossing> self_crossings;  ///< Listed ones, in (layer, segment) order.
    /// Near pairs (gap < near_distance, any relation), in (layer_a, layer_b) order with
    /// layer_a < layer_b. The gap is exact up to rounding: 0 when the layers meet, else the
    /// minimum over the vertices of each layer of the distance to the other layer.
    std::vector<PairSeparation> pairs;
    double min_separation_ratio = std::numeric_limits<double>::infinity();  ///< Over `pairs`.
    /// Vertices of a near pair's layer closer to the other layer than required * (1 - tol),
    /// for pairs with required > 0 (a vertex counts once per other layer).
    std::size_t separation_violation_count = 0;
    std::vector<SeparationViolation> separation_violations;  ///< Listed ones.
    /// Vertices on the wrong side of another layer (once per vertex and other layer). A vertex
    /// lying exactly on the other layer is a contact, not a nesting violation.
    std::size_t nesting_violation_count = 0;
    std::vector<NestingViolation> nesting_violations;  ///< Listed ones.
    double near_distance = 0.0;                        ///< The near distance used.

    std::size_t total_self_crossings() const;
    /// No crossing or touch between layers, no self-crossing, nesting kept.
    bool is_collision_free() const;
    /// Every near pair keeps its required separation (within the tolerance).
    bool separations_hold() const { return separation_violation_count == 0; }
};

/// @brief Checks `scene` exactly: crossings and touches between layers, self-crossings,
/// separations of near pairs, and nesting.
///
/// Nesting: a layer under a closed layer has every vertex strictly inside it; a layer over a
/// closed layer has every vertex outside it; two side-by-side layers have no vertex inside
/// the other if it is closed. A layer under or over an *open* layer is checked on the side
/// of it given by its outside side (see outside_side()), at vertices whose closest point on
/// the open layer is within near_distance and not its end point. Inside / outside a closed
/// layer is decided exactly (non-zero winding number with orient2d). Side-by-side pairs are
/// not checked against open layers. With params.input_sides, a vertex with a recorded side of
/// an open layer is checked against that side instead of the global one.
///
/// Cost: a uniform-grid broad phase for the contacts, about O(n + k) for n segments of
/// similar lengths and k contacts; a nearest-segment query in a per-layer uniform grid per
/// vertex and near layer (one query serves both the separation and, against an open layer,
/// the side); one point-in-polygon ray query per vertex and closed layer whose box holds it.
/// Pairs of layers are scanned in parallel (TBB, within the caller's
/// max_allowed_parallelism); the report does not depend on the number of threads.
/// @throws InvalidInput bad params.
CheckReport check_scene(const Scene& scene, const CheckParams& params = {});

/// The automatic near distance of CheckParams::near_distance: max(5% of the bounding-box
/// diagonal of `scene`, 2 x the largest required separation of two of its layers).
double automatic_near_distance(const Scene& scene);

/// +1 when the outside (the "over" side) of layer `i` is on the right of its direction of
/// travel, -1 when on the left. Closed layers: their outside. Open layers: the side away from
/// the layers directly under it (majority of their near vertices), else the side towards the
/// layers directly over it, else +1.
///
/// Closed: the sign of the signed area (counter-clockwise: +1). Open: each vertex of the
/// layers directly under `i` whose closest point on `i` is closer than the near distance and
/// not an end point of `i` votes for the side opposite to it; a tie (or no vote) passes to
/// the vertices of the layers directly over `i`, which vote for their own side. When neither
/// gives a vote, the same two votes are taken again within 3 x the near distance (neighbours
/// at about the near distance, e.g. a gap equal to it). The near distance is
/// automatic_near_distance(scene).
int outside_side(const Scene& scene, std::size_t i);
/// outside_side() with an explicit near distance (scene units, >= 0; 0 = automatic), as
/// check_scene() uses it.  @throws InvalidInput bad near_distance.
int outside_side(const Scene& scene, std::size_t i, double near_distance);
/// outside_side() of every layer of `scene`, in layer order (CheckParams::outside_sides,
/// UntangleParams::outside_sides).  @throws InvalidInput bad near_distance.
std::vector<int> outside_sides(const Scene& scene, double near_distance = 0.0);

}  // namespace strata
