#pragma once
/// @file The simplification driver's index of the live segments of every layer: a UniformGrid
/// of segment names (by bounding box) updated as vertices move or are removed. Private to
/// src/simplify.

#include "geometry/detail/uniform_grid.h"
#include "strata/core/types.h"

#include <cstddef>
#include <cstdint>

namespace strata::detail {

struct SegRef {
    std::uint32_t layer = 0, start = 0;  // segment from vertex `start` to its next alive vertex
    bool operator==(const SegRef& o) const { return layer == o.layer && start == o.start; }
};

using SegmentGrid = UniformGrid<SegRef>;

/// A live segment as LivePolylines files it: its name, its end vertex and both end points at
/// their live positions (LivePolylines files it again whenever one changes). A query then reads
/// what the checks need from the grid's cells, side by side in memory, instead of from the
/// per-vertex arrays at a random place per segment met (cache misses once the layers outgrow
/// the cache: measured at 8 x 125k, see docs/simplify.md).
struct LiveSegment {
    std::uint32_t layer = 0, start = 0;
    std::uint32_t end = 0;     // the next alive vertex after start
    bool end_is_last = false;  // end is the last vertex of an open layer
    Vec2 p{0.0}, q{0.0};       // positions of start and end
    bool operator==(const LiveSegment& o) const { return layer == o.layer && start == o.start; }
    Box2 box() const {
        Box2 b;
        b.extend(p);
        b.extend(q);
        return b;
    }
};

using LiveSegmentGrid = UniformGrid<LiveSegment>;

/// Cells per segment up to which make_segment_grid() keeps its cells in a dense array.
constexpr double kDenseCellsPerSegment = 4.0;

/// A grid of cells of side `cell` (scene units), hashed everywhere (a job's few segments).
template <class Id = SegRef>
UniformGrid<Id> make_segment_grid(double cell) {
    UniformGridParams p;
    p.cell = cell;
    return UniformGrid<Id>(p);
}

/// A grid of cells of side `cell` (scene units) for `segments` segments within `bounds`: the
/// cells over `bounds` a dense array when they are at most kDenseCellsPerSegment per segment
/// (stacks whose layers fill their box: no hashing, neighbouring cells side by side in
/// memory), every cell hashed elsewhere.
template <class Id = SegRef>
UniformGrid<Id> make_segment_grid(double cell, const Box2& bounds, std::size_t segments) {
    UniformGridParams p;
    p.cell = cell;
    p.dense_bounds = bounds;
    p.max_dense_cells = kDenseCellsPerSegment * static_cast<double>(segments) + 1024.0;
    return UniformGrid<Id>(p);
}

}  // namespace strata::detail
