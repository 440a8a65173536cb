#pragma once
/// @file Internal: the field backends' spatial index of a SegmentStore's live slots (a
/// UniformGrid of slot numbers) and the exact nearest-segment search through it (the
/// ExactIndexed backend; the Grid backend's voxel values and out-of-band signs).

#include "field/detail/segment_store.h"
#include "geometry/detail/uniform_grid.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace strata::detail {

/// A store's live slots filed by their boxes. The store is not owned: pass the same one to
/// every call.
using SegmentIndex = UniformGrid<std::uint32_t>;

/// Buckets a slot may touch before it goes to the grid's list of large items.
constexpr double kMaxSlotCells = 4096.0;

/// An empty index of square cells of side `cell` (scene units) counted from `origin` (e.g. the
/// layer's corner: far from the scene origin, cell numbers stay small).
inline SegmentIndex make_segment_index(double cell, const Vec2& origin = Vec2(0.0)) {
    UniformGridParams p;
    p.cell = cell;
    p.origin = origin;
    p.max_item_cells = kMaxSlotCells;
    return SegmentIndex(p);
}

/// Adds slot `slot` of `store` if live (its geometry as it is in the store now).
inline void insert_slot(SegmentIndex& index, const SegmentStore& store, std::uint32_t slot) {
    const Segment& s = store.segments()[slot];
    if (s.live) index.insert(slot, s.box());
}

/// Removes slot `slot` (its geometry as it was when inserted, still in the store).
inline void erase_slot(SegmentIndex& index, const SegmentStore& store, std::uint32_t slot) {
    index.erase(slot, store.segments()[slot].box());
}

/// Indexes every live slot of `store` (replaces the content of `index`, cells included).
inline void index_store(SegmentIndex& index, const SegmentStore& store) {
    index = SegmentIndex(index.params());
    for (std::uint32_t s = 0; s < store.segments().size(); ++s) insert_slot(index, store, s);
}

/// The nearest live slot to x into `best` (store.offer()'s tie-break, so the brute-force
/// winner), or, when nothing is within `limit` (scene units), possibly none.
inline void nearest_slot(const SegmentIndex& index, const SegmentStore& store, const Vec2& x,
                         Nearest& best, double limit = std::numeric_limits<double>::infinity()) {
    index.nearest(x, limit, [&](std::uint32_t s) {
        store.offer(x, s, best);
        return best.dist2;
    });
}

/// The slots filed in the cells that `box` touches, sorted, without repeats (`out` is
/// replaced): a superset of the segments that have a point in `box`.
inline void slot_candidates(const SegmentIndex& index, const Box2& box,
                            std::vector<std::uint32_t>& out) {
    out.clear();
    index.query(box, [&](std::uint32_t s) { out.push_back(s); });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace strata::detail
