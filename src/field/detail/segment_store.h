#pragma once
/// @file Internal: a layer's segments in stable slots, the exact signed evaluation every
/// backend shares, and the splice that follows a PolylineEdit.

#include "strata/core/types.h"
#include "strata/field/field.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace strata::detail {

/// One segment [a, b] with what its signed evaluation needs from its neighbours.
struct Segment {
    Vec2 a{0.0}, b{0.0};
    Vec2 normal{0.0};       ///< Unit outward normal of this segment (zero if degenerate).
    Vec2 pseudo_a{0.0};     ///< Outward pseudo-normal at a (sum of adjacent normals).
    Vec2 pseudo_b{0.0};     ///< Outward pseudo-normal at b.
    bool a_is_end = false;  ///< a is the first vertex of an open layer.
    bool b_is_end = false;  ///< b is the last vertex of an open layer.
    bool live = false;      ///< False: a free slot.
    Box2 box() const {
        Box2 r;
        r.extend(a);
        r.extend(b);
        return r;
    }
};

/// The nearest segment of a query: squared distance and the tie-break key.
struct Nearest {
    double dist2 = std::numeric_limits<double>::infinity();
    std::uint32_t slot = std::numeric_limits<std::uint32_t>::max();
    double t = 0.0;  ///< Parameter of the closest point, in [0, 1].
    bool found() const { return slot != std::numeric_limits<std::uint32_t>::max(); }
};

/// Squared distance from x to segment s and the closest parameter (0 / 1 exactly at ends).
inline double segment_dist2(const Segment& s, const Vec2& x, double& t) {
    const Vec2 d = s.b - s.a;
    const double len2 = d.x * d.x + d.y * d.y;
    double u = 0.0;
    if (len2 > 0.0) u = ((x.x - s.a.x) * d.x + (x.y - s.a.y) * d.y) / len2;
    Vec2 c;
    if (u <= 0.0) {
        u = 0.0;
        c = s.a;
    } else if (u >= 1.0) {
        u = 1.0;
        c = s.b;
    } else {
        c = s.a + u * d;
    }
    t = u;
    const Vec2 e = x - c;
    return e.x * e.x + e.y * e.y;
}

/// True when candidate (dist2, s) beats the current best: smaller distance, then the
/// lexicographically smaller segment (a, b), then the smaller slot. Depends on geometry only
/// (except for identical segments), so every backend picks the same winner.
bool beats(double dist2, const Segment& s, std::uint32_t slot, const Nearest& best,
           const std::vector<Segment>& segments);

/// A sequence of slots (segment index -> slot) in blocks of at most 2 * kBlock entries with a
/// Fenwick tree of the block sizes, so a splice moves the tail of one block instead of the whole
/// layer's: O(kBlock + log blocks) per splice instead of a memmove of 4 bytes per segment (only
/// a block that empties or splits, once per kBlock edited entries at most, costs O(blocks)).
class SlotSequence {
  public:
    /// The identity 0, 1, ..., n - 1.
    void assign(std::size_t n);
    std::size_t size() const { return size_; }
    /// Entries [first, first + count) into `out` (replaced). Requires first + count <= size().
    void read(std::size_t first, std::size_t count, std::vector<std::uint32_t>& out) const;
    /// Replaces entries [first, first + count) by `values`. Requires first + count <= size().
    void replace(std::size_t first, std::size_t count, const std::vector<std::uint32_t>& values);
    std::size_t memory_bytes() const;

  private:
    static constexpr std::size_t kBlock = 1024;
    // Block and offset of entry k; with k == size() (insertion at the end), the end of the last
    // block.
    void locate(std::size_t k, std::size_t& block, std::size_t& offset) const;
    void rebuild_sums();
    void add_to_sums(std::size_t block, std::size_t count);
    void remove_from_sums(std::size_t block, std::size_t count);

    std::vector<std::vector<std::uint32_t>> blocks_;  // none empty
    std::vector<std::size_t> sums_;                   // Fenwick tree of the block sizes, 1-based
    std::size_t size_ = 0;
};

/// The layer's segments in slots that keep their index across edits.
class SegmentStore {
  public:
    /// Builds from a polyline; for closed layers the outside sign is derived from the
    /// winding and `outside_sign` is ignored.
    void build(const std::vector<Vec2>& points, bool closed, int outside_sign);

    /// Applies `edit` (points = the new polyline). Fills the slots removed (old geometry
    /// still readable in segments() until the next edit) and the slots added.
    /// Returns false when the edit is not local (wraps around a closed layer, flips its
    /// winding, or the layer is tiny): the caller rebuilds everything then (build() was called).
    bool splice(const std::vector<Vec2>& points, const PolylineEdit& edit,
                std::vector<std::uint32_t>& removed, std::vector<std::uint32_t>& added);

    const std::vector<Segment>& segments() const { return segments_; }
    std::size_t segment_count() const { return slot_of_.size(); }
    int outside_sign() const { return outside_sign_; }
    bool is_closed() const { return closed_; }
    std::size_t memory_bytes() const {
        return segments_.capacity() * sizeof(Segment) + slot_of_.memory_bytes() +
               free_.capacity() * sizeof(std::uint32_t);
    }

    /// Signed value, gradient and border for query x whose nearest segment is `n`.
    FieldSample evaluate(const Vec2& x, const Nearest& n) const;
    /// Border field b(x) (+inf for closed layers).
    double border(const Vec2& x) const;
    /// Offers slot `slot` to `best`.
    void offer(const Vec2& x, std::uint32_t slot, Nearest& best) const {
        const Segment& s = segments_[slot];
        double t = 0.0;
        const double d2 = segment_dist2(s, x, t);
        if (d2 > best.dist2) return;  // the usual case, without the out-of-line tie-break
        if (beats(d2, s, slot, best, segments_)) {
            best.dist2 = d2;
            best.slot = slot;
            best.t = t;
        }
    }

  private:
    Segment make_segment(const std::vector<Vec2>& points, std::size_t i) const;
    void update_ends(const std::vector<Vec2>& points);
    std::uint32_t allocate();

    std::vector<Segment> segments_;
    SlotSequence slot_of_;  // segment index -> slot
    std::vector<std::uint32_t> free_;
    bool closed_ = false;
    int outside_sign_ = 1;
    double twice_area_ = 0.0;  // closed layers: shoelace sum
    Vec2 end_c_[2]{Vec2(0.0), Vec2(0.0)}, end_t_[2]{Vec2(0.0), Vec2(0.0)};
};

/// Checks a polyline for make_field (finite, enough points).
void check_points(const std::vector<Vec2>& points, bool closed, const char* where);

}  // namespace strata::detail
