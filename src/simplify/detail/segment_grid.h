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

/// Cells per segment up to which make_segment_grid() keeps its cells in a dense array.
constexpr double kDenseCellsPerSegment = 4.0;

/// A grid of cells of side `cell` (scene units), hashed everywhere (a job's few segments).
inline SegmentGrid make_segment_grid(double cell) {
    UniformGridParams p;
    p.cell = cell;
    return SegmentGrid(p);
}

/// A grid of cells of side `cell` (scene units) for `segments` segments within `bounds`: the
/// cells over `bounds` a dense array when they are at most kDenseCellsPerSegment per segment
/// (stacks whose layers fill their box: no hashing, neighbouring cells side by side in
/// memory), every cell hashed elsewhere.
inline SegmentGrid make_segment_grid(double cell, const Box2& bounds, std::size_t segments) {
    UniformGridParams p;
    p.cell = cell;
    p.dense_bounds = bounds;
    p.max_dense_cells = kDenseCellsPerSegment * static_cast<double>(segments) + 1024.0;
    return SegmentGrid(p);
}

}  // namespace strata::detail
