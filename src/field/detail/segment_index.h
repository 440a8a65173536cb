#pragma once
/// @file Internal: uniform buckets over a SegmentStore's slots and the exact nearest-segment
/// search through them (the ExactIndexed backend; the Grid backend's voxel values and
/// out-of-band signs).

#include "field/detail/segment_store.h"

#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

namespace strata::detail {

/// Square buckets of side `cell` (scene units) listing the live slots whose bounding box
/// touches them; a slot whose box would touch more than kMaxCells buckets (a vertex carried
/// far away) is kept in a plain list that every query reads instead, so that memory stays
/// bounded. The store is not owned: pass the same one to every call.
class SegmentIndex {
  public:
    /// Buckets counted from `origin` (e.g. the layer's corner: far from the scene origin,
    /// bucket numbers stay small).
    explicit SegmentIndex(double cell = 1.0, const Vec2& origin = Vec2(0.0))
        : cell_(cell), origin_(origin) {}

    /// Indexes every live slot of `store` (replaces the current content).
    void build(const SegmentStore& store);
    /// Adds / removes one slot (its geometry as it is in the store now / was when inserted).
    void insert(const SegmentStore& store, std::uint32_t slot);
    void erase(const SegmentStore& store, std::uint32_t slot);

    /// Rings of buckets around x, clipped to the occupied ones, until no unvisited segment can be
    /// as near as the best one (ties included, so the winner is the brute-force one), or, when
    /// nothing within `limit` (scene units) has been found, none can be within `limit` either.
    void search(const SegmentStore& store, const Vec2& x, Nearest& best,
                double limit = std::numeric_limits<double>::infinity()) const;

    /// The slots listed in the buckets that `box` touches, sorted, without repeats (`out` is
    /// replaced): a superset of the segments that have a point in `box`.
    void candidates(const Box2& box, std::vector<std::uint32_t>& out) const;

    /// Buckets, their slot lists and the hash table's nodes and bucket array, in bytes.
    std::size_t memory_bytes() const;

    /// Buckets a slot may touch before it goes to the plain list.
    static constexpr double kMaxCells = 4096.0;

  private:
    bool is_large(const Box2& box) const;
    long column(double x) const;
    long row(double y) const;
    template <typename F>
    void for_cells(const Box2& box, F&& f) const;
    void visit(const SegmentStore& store, const Vec2& x, long i, long j, Nearest& best) const;

    double cell_ = 1.0;
    Vec2 origin_{0.0};
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets_;
    std::vector<std::uint32_t> large_;  // slots too large for the buckets
    // Bounding range of the buckets ever occupied since the last build (not shrunk by erase).
    long imin_ = std::numeric_limits<long>::max(), imax_ = std::numeric_limits<long>::min();
    long jmin_ = std::numeric_limits<long>::max(), jmax_ = std::numeric_limits<long>::min();
};

}  // namespace strata::detail
