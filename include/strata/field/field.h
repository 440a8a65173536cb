#pragma once
/// @file Per-layer signed distance fields: the values and gradients the untangling queries.
///
/// Sign convention (every backend, see docs/field.md):
/// - f_i(x) > 0 outside ("above") layer i, < 0 inside ("below"), 0 on the polyline, and
///   |f_i(x)| is the distance to the polyline where the nearest feature is a segment interior or
///   an interior vertex.
/// - Closed layers: inside (the bounded side) is negative whatever the winding of the input.
/// - Open layers: the outside is the right of the direction of travel when `outside_sign` is +1,
///   the left when -1 (see strata::outside_side()). The sign comes from the nearest feature:
///   the segment's outward normal, or at a vertex the angle-weighted pseudo-normal (in 2D the
///   normalised sum of the two adjacent outward normals), so it is right everywhere near the
///   curve.
/// - Open layers beyond their ends: where the nearest feature is an end vertex c with outward
///   tangent t (pointing away from the layer) and outward normal n (the end segment's), the
///   value is the extended value (x - c).n, so the zero set continues straight past the end.
/// - Border field of an open layer: b(x) = (c - x).t for the end c nearest to x (Euclidean
///   distance to the two end vertices). b > 0 over the layer, b < 0 beyond that end, 0 on the
///   line through c normal to t. It is meant to be read near the ends (within the band); far
///   from both ends of a strongly curved layer its sign says nothing. +inf for closed layers.

#include "strata/core/types.h"
#include "strata/geometry/layer.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace strata {

/// One query of a layer's field.
struct FieldSample {
    double value = 0.0;    ///< f(x), scene units (clamped to +-band_width outside the band).
    Vec2 gradient{0.0};    ///< grad f(x), unit length up to the backend's error.
    bool in_band = false;  ///< Exact backends: |distance| <= band_width. Grid: all four
                           ///< bilinear corners are active (band) voxels.
    /// b(x) of the file comment for open layers (scene units), +inf for closed layers.
    double border = std::numeric_limits<double>::infinity();
    /// Open layers: x is past an end. Exact backends: the nearest feature is an end vertex (then
    /// b(x) <= 0); away from the ends b(x) can be negative too (a layer folded back near its
    /// end), and this stays false there. Grid: b(x) < 0 (it does not know the nearest feature).
    bool past_end = false;
};

/// How the fields are evaluated.
enum class FieldBackend {
    Grid,          ///< OpenVDB narrow-band grid, bilinear interpolation (the default).
    ExactBrute,    ///< Exact, loops over every segment: O(n) per query (the paper's evaluation).
    ExactIndexed,  ///< Exact, through uniform buckets of segments; same answers as ExactBrute.
};

/// Parameters of the fields. Lengths are in scene units (the units of the input points).
struct FieldParams {
    FieldBackend backend = FieldBackend::Grid;  ///< Evaluation backend.
    /// Grid voxel size h, scene units, >= 0. 0 = automatic: a quarter of the median segment
    /// length of the scene, capped at half the smallest nonzero required separation.
    double voxel_size = 0.0;
    /// Half-width of the narrow band, scene units, >= 0. 0 = automatic: the total thickness of
    /// the layers + expected_penetration + band_margin_voxels * h, and at least 3 h.
    double band_width = 0.0;
    /// Largest penetration the untangling is expected to resolve, scene units, >= 0.
    /// 0 = automatic: twice the median segment length (a decimation moves the curve by about a
    /// segment length). Only used by the automatic band width.
    double expected_penetration = 0.0;
    /// Extra voxels of band for the bilinear interpolation, >= 0.
    double band_margin_voxels = 2.0;
    /// Bucket size of the segment index, scene units, >= 0. 0 = automatic: for ExactIndexed
    /// the band width, but at least twice and at most 8 times the median segment length; for
    /// Grid (the index its voxel values are computed from) twice the median segment length.
    /// Speed only: the samples do not depend on it.
    double bucket_size = 0.0;
    /// Grid backend: where the caller will sample, scene units (empty, the default: anywhere).
    /// The grid is then built and updated only within `region` grown by the band width, so a
    /// local untangling pays for its box, not for the whole scene. Samples there equal a whole
    /// grid's (open layers out of the band aside: +band_width past the region's right edge);
    /// farther out they read out of the band, with a closed layer's exact sign. Ignored by the
    /// exact backends. Finite when not empty.
    Box2 region = {};
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const FieldParams& params);

/// FieldParams with every automatic value resolved (all lengths > 0).
struct ResolvedFieldParams {
    FieldBackend backend = FieldBackend::Grid;
    double voxel_size = 0.0;   ///< h, scene units, > 0.
    double band_width = 0.0;   ///< Band half-width, scene units, > 0.
    double bucket_size = 0.0;  ///< ExactIndexed bucket size, scene units, > 0.
    Box2 region;               ///< FieldParams::region (empty: the whole scene).
};

/// Resolves the automatic values of `params` from `scene`.
/// @throws InvalidInput bad params, or an empty scene with automatic values.
ResolvedFieldParams resolve(const FieldParams& params, const Scene& scene);

/// A local edit of a polyline: vertices [first, first + removed) of the previous polyline
/// became vertices [first, first + inserted) of the new one. Moving vertices i..j is
/// {i, j - i + 1, j - i + 1}; removing vertex i is {i, 1, 0}.
struct PolylineEdit {
    std::size_t first = 0;
    std::size_t removed = 0;
    std::size_t inserted = 0;
};

/// Size and extent of a field's storage (LayerField::stats(): one layer;
/// SceneFields::total_stats(): the scene).
struct FieldStats {
    std::size_t segments = 0;  ///< Segments of the layer.
    /// Segment store + bucket index of the layer; Grid: plus its share of the grid that all
    /// layers of a SceneFields share (OpenVDB memUsage x the layer's fraction of the band
    /// voxels). SceneFields::total_stats() counts the shared grid once.
    std::size_t memory_bytes = 0;
    std::size_t active_voxels = 0;  ///< Grid only: band voxels of the layer.
    /// Grid only: 8x8x8 leaf nodes holding band voxels of the layer (they may hold other layers'
    /// too); total_stats(): leaves of the shared grid.
    std::size_t leaves = 0;
    Box2 bounds;              ///< Grid: active voxel bounding box; exact: layer bounds.
    double voxel_size = 0.0;  ///< Scene units (0 for exact backends).
    double band_width = 0.0;  ///< Scene units.
};

/// @brief The signed distance field of one layer (see the file comment for the convention).
/// sample() is const and safe to call from several threads at once; update() is not.
class LayerField {
  public:
    virtual ~LayerField() = default;
    LayerField(const LayerField&) = delete;
    LayerField& operator=(const LayerField&) = delete;

    /// Value, gradient, band membership and border field at `x` (scene units).
    virtual FieldSample sample(const Vec2& x) const = 0;

    /// sample(x) when `x` is in the band; otherwise only `in_band` (false) is meaningful, the
    /// other members are unspecified. The composition needs nothing more from a layer that is
    /// out of band, and the exact indexed backend then stops searching at the band's edge.
    virtual FieldSample sample_in_band(const Vec2& x) const { return sample(x); }

    /// Follows a local edit of the polyline: `points` is the whole new polyline, `edit` says
    /// which vertices changed. Only the part of the field near the edit is recomputed; the
    /// result equals a field built from scratch on `points`.
    /// @throws InvalidInput when `edit` does not fit the old and new point counts or an edited
    ///         point is not finite; the field is unchanged then.
    virtual void update(const std::vector<Vec2>& points, const PolylineEdit& edit) = 0;

    virtual FieldStats stats() const = 0;

    const std::string& name() const { return name_; }
    bool is_closed() const { return closed_; }
    /// +1 when the outside is on the right of the direction of travel (for closed layers,
    /// derived from the winding), -1 when on the left.
    int outside_sign() const { return outside_sign_; }

  protected:
    LayerField(std::string name, bool closed, int outside_sign)
        : name_(std::move(name)), closed_(closed), outside_sign_(outside_sign) {}
    void set_outside_sign(int sign) { outside_sign_ = sign; }

  private:
    std::string name_;
    bool closed_ = false;
    int outside_sign_ = 1;
};

/// Builds the field of `layer` with the backend of `params`. `outside_sign` (+1 or -1) is the
/// side of the outside of an open layer (+1: right of the direction of travel); it is ignored
/// for closed layers, whose outside is their unbounded side.
/// @throws InvalidInput bad sign, too few or non-finite points, or a layer too large for the
///         grid's 32-bit voxel coordinates.
std::unique_ptr<LayerField> make_field(const Layer& layer, int outside_sign,
                                       const ResolvedFieldParams& params);

namespace detail {
class GridStack;
}

/// @brief One field per layer of a scene, built with the same resolved parameters.
/// Grid backend: the layers share one grid (layer i at index z = i); each field reads and
/// updates its own plane of it, so the fields of one SceneFields must not be updated while
/// another of them is sampled (see LayerField: update() is not thread safe).
class SceneFields {
  public:
    /// Builds every layer's field; open layers take their outside side from `outside_signs`
    /// (one entry per layer, +1 or -1; empty = +1 for every layer).
    /// @throws InvalidInput see make_field() and resolve().
    SceneFields(const Scene& scene, const FieldParams& params = {},
                const std::vector<int>& outside_signs = {});

    std::size_t size() const { return fields_.size(); }
    const LayerField& field(std::size_t i) const { return *fields_.at(i); }
    LayerField& field(std::size_t i) { return *fields_.at(i); }
    const ResolvedFieldParams& params() const { return params_; }

    /// Every layer's sample at `x`, in layer order (resized to size()); equal to each field's
    /// sample(x). Grid backend: one grid probe per bilinear corner serves 8 layers.
    void sample_all(const Vec2& x, std::vector<FieldSample>& out) const;

    /// Totals over the layers: segments, band voxels, memory (the shared grid counted once, plus
    /// every layer's segment store and index), leaves of the shared grid (Grid), union of the
    /// bounds; voxel size and band width.
    FieldStats total_stats() const;

  private:
    ResolvedFieldParams params_;
    std::shared_ptr<detail::GridStack> grid_;  // Grid backend: the grid fields_ share
    std::vector<std::unique_ptr<LayerField>> fields_;
};

}  // namespace strata
