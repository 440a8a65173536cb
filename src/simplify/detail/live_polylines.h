#pragma once
/// @file The polylines being simplified: one WorkLayer per input layer (its alive vertices
/// linked in order) and the LiveSegmentGrid of their live segments, kept in step as vertices are
/// unlinked, relinked or moved. Private to src/simplify.

#include "simplify/detail/segment_grid.h"
#include "simplify/detail/work_layer.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace strata::detail {

class LivePolylines {
  public:
    /// Every vertex of `scene` alive; targets[l]: the vertex count layer l should come down to.
    LivePolylines(const Scene& scene, const std::vector<std::size_t>& targets);

    std::size_t size() const { return layers_.size(); }
    const WorkLayer& layer(std::size_t l) const { return layers_[l]; }
    /// The live segments, each indexed by its bounding box.
    const LiveSegmentGrid& grid() const { return grid_; }
    /// Vertex v of layer l is not to be removed any more.
    void lock(std::size_t l, std::size_t v) { layers_[l].locked[v] = 1; }

    /// Takes alive vertex v (not an end of an open layer) out: its neighbours are joined.
    void unlink(std::size_t l, std::size_t v);
    /// Undoes unlink(l, v) (its neighbours then are still linked to each other).
    void relink(std::size_t l, std::size_t v);
    /// Moves vertex v of layer l to `to`.
    void move(std::size_t l, std::size_t v, const Vec2& to);

    /// Calls f(layer, start) once per live segment whose box meets `box`.
    template <class F>
    void segments_near(const Box2& box, F&& f) const {
        live_segments_near(box, [&](const LiveSegment& s) {
            f(static_cast<std::size_t>(s.layer), static_cast<std::size_t>(s.start));
        });
    }
    /// Calls f(segment) once per live segment whose box meets `box`. Marks nothing: a segment
    /// filed in several cells is reported from one of them, by the box its record holds
    /// (UniformGrid::query_once).
    template <class F>
    void live_segments_near(const Box2& box, F&& f) const {
        grid_.query_once(
            box, [](const LiveSegment& s) { return s.box(); }, f);
    }

    /// The cells of side input_cell() (4 median segment lengths of the input, corner of cell
    /// (0, 0) at the origin) that a box touches: columns i0..i1, rows j0..j1, as the grid
    /// built for the input numbers them.
    struct CellRange {
        long long i0 = 0, i1 = 0, j0 = 0, j1 = 0;
        bool meets(const CellRange& o) const {
            return i0 <= o.i1 && o.i0 <= i1 && j0 <= o.j1 && o.j0 <= j1;
        }
    };
    double input_cell() const { return input_cell_; }
    CellRange input_cells(const Box2& box) const {
        return {input_cell_index(box.min.x), input_cell_index(box.max.x),
                input_cell_index(box.min.y), input_cell_index(box.max.y)};
    }

    /// `input` (layers, metadata) with the alive vertices of every layer, in order.
    Scene to_scene(const Scene& input) const;
    /// Per layer, the input id of every vertex of to_scene(), in the same order.
    std::vector<std::vector<std::size_t>> origins() const;

    /// The grid's name of the segment starting at vertex i of layer l.
    static SegRef ref(std::size_t l, std::size_t i) {
        return {static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(i)};
    }

    /// The box segment (l, i) is filed with in grid(): its end points' box.
    Box2 seg_box(std::size_t l, std::size_t i) const {
        Box2 box;
        box.extend(layers_[l].pos[i]);
        box.extend(layers_[l].pos[layers_[l].next[i]]);
        return box;
    }

  private:
    bool has_segment(std::size_t l, std::size_t i) const {
        return layers_[l].alive[i] && layers_[l].next[i] != kNone;
    }
    // The number of the cell of side input_cell_ (from 0) holding x, as the grid numbers it.
    long long input_cell_index(double x) const { return LiveSegmentGrid::to_cell(x / input_cell_); }
    /// Builds grid_ again for the live segments; unlink() calls it when they are down to a
    /// quarter of those it was built for (fewer builds; a half was no faster).
    void regrid();
    std::vector<WorkLayer> layers_;
    /// Segment (l, i) as grid_ files it (alive, not the last vertex of an open layer).
    LiveSegment record(std::size_t l, std::size_t i) const;
    /// The name grid_.erase() matches segment (l, i) by.
    static LiveSegment key(std::size_t l, std::size_t i) {
        LiveSegment s;
        s.layer = static_cast<std::uint32_t>(l);
        s.start = static_cast<std::uint32_t>(i);
        return s;
    }
    LiveSegmentGrid grid_;
    double input_cell_ = 1.0;  // the cell of the grid built for the input
    Box2 bounds_;              // the input's: where grid_ keeps its cells in a dense array
    std::size_t live_segments_ = 0, gridded_segments_ = 0;  // now, and when grid_ was built
};

}  // namespace strata::detail
