#pragma once
// SegmentIndex: the segments of one layer in a uniform grid, with the nearest-point queries
// and the side rule that check_scene() and record_input_sides() share (so that the recorded
// sides and the checked ones are decided by the same code). Internal to the geometry module
// (checks.cpp, input_sides.cpp).

#include "geometry/detail/uniform_grid.h"
#include "strata/core/types.h"
#include "strata/geometry/input_sides.h"
#include "strata/geometry/predicates.h"
#include "strata/geometry/scene.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace strata::detail {
// Internal linkage (each of the two files that use it has its own copy, and a function one of
// them does not call is [[maybe_unused]]): with inline functions of external linkage instead,
// `strata check` of the 8 x 125k stack took 3% more CPU (0.84 s against 0.81 s user, 7 runs
// each); the queries are the checks' hot path.
namespace {

constexpr std::size_t kNoSegment = std::numeric_limits<std::size_t>::max();
constexpr double kFar = std::numeric_limits<double>::infinity();

// Cells of a grid over `bounds` for `count` segments of median length `median`: about the
// median, at most four cells a segment (scene units).
[[maybe_unused]] double cell_size(const Box2& bounds, double median, std::size_t count) {
    const Vec2 size = bounds.size();
    double h =
        std::max({median, 1e-9 * std::max(size.x, size.y), std::numeric_limits<double>::min()});
    const double budget = 4.0 * static_cast<double>(count) + 16.0;
    while ((size.x / h + 1.0) * (size.y / h + 1.0) > budget) h *= 2.0;
    return h;
}

// A uniform grid for `count` segments within `bounds`, cells dense over them.
[[maybe_unused]] UniformGrid<std::uint32_t> segment_grid(const Box2& bounds, double median,
                                                         std::size_t count) {
    UniformGridParams p;
    p.cell = cell_size(bounds, median, count);
    p.origin = bounds.min;
    p.dense_bounds = bounds;
    return UniformGrid<std::uint32_t>(p);
}

[[maybe_unused]] double median_of(std::vector<double>& values) {
    if (values.empty()) return 0.0;
    auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

// The segments of one layer that take part in the checks, in a uniform grid. Zero-length
// segments (left by Scene::set_points, which keeps duplicates) are skipped: their point is an
// end of their neighbours. A layer all of whose segments have zero length keeps its first one.
class SegmentIndex {
  public:
    SegmentIndex() = default;

    explicit SegmentIndex(const Layer& layer) : layer_(&layer) {
        static std::atomic<std::uint64_t> serials{0};
        serial_ = ++serials;
        const std::size_t count = layer.segment_count();
        position_.assign(count, kNoSegment);
        segments_.reserve(count);
        for (std::size_t s = 0; s < count; ++s)
            if (layer.segment_start(s) != layer.segment_end(s)) add(s);
        if (segments_.empty() && count > 0) add(0);
        Box2 bounds;
        std::vector<double> lengths;
        lengths.reserve(segments_.size());
        for (std::size_t s : segments_) {
            bounds.extend(box(s));
            const Vec2 d = end(s) - start(s);
            lengths.push_back(std::sqrt(d.x * d.x + d.y * d.y));  // sizes the cells only
        }
        const double median = median_of(lengths);
        ends_.reserve(segments_.size());
        for (std::size_t s : segments_) ends_.push_back({start(s), end(s)});
        // The chunks of kChunk consecutive kept segments: what the grid files.
        std::vector<std::uint32_t> ids;
        ids.reserve(segments_.size() / kChunk + 1);
        chunk_boxes_.reserve(segments_.size() / kChunk + 1);
        for (std::size_t q = 0; q < segments_.size(); q += kChunk) {
            Box2 b;
            for (std::size_t r = q; r < std::min(q + kChunk, segments_.size()); ++r)
                b.extend(box(segments_[r]));
            ids.push_back(static_cast<std::uint32_t>(chunk_boxes_.size()));
            chunk_boxes_.push_back(b);
        }
        for (const Vec2& v : layer.points)
            magnitude_ = std::max({magnitude_, std::abs(v.x), std::abs(v.y)});
        chunk_length_ = static_cast<double>(kChunk) * median;
        chunk_grid_ = segment_grid(bounds, median, chunk_boxes_.size());
        chunk_grid_.build(ids, [&](std::uint32_t c) { return chunk_boxes_[c]; });
    }

    const Layer& layer() const { return *layer_; }
    /// Indices of the kept segments, increasing.
    const std::vector<std::size_t>& segments() const { return segments_; }
    Vec2 start(std::size_t s) const { return layer_->segment_start(s); }
    /// layer().segment_end(s) without its modulo (a division: this is the inner loop).
    Vec2 end(std::size_t s) const {
        const std::vector<Vec2>& points = layer_->points;
        return s + 1 < points.size() ? points[s + 1] : points[0];
    }
    Box2 box(std::size_t s) const {
        Box2 b;
        b.extend(start(s));
        b.extend(end(s));
        return b;
    }

    /// The kept segment after / before kept segment `s` (cyclic when closed), or kNoSegment.
    std::size_t next(std::size_t s) const {
        const std::size_t k = position_[s];
        if (k + 1 < segments_.size()) return segments_[k + 1];
        return layer_->closed && segments_.size() > 1 ? segments_.front() : kNoSegment;
    }
    std::size_t previous(std::size_t s) const {
        const std::size_t k = position_[s];
        if (k > 0) return segments_[k - 1];
        return layer_->closed && segments_.size() > 1 ? segments_.back() : kNoSegment;
    }
    bool is_first(std::size_t s) const { return segments_.front() == s; }
    bool is_last(std::size_t s) const { return segments_.back() == s; }

    struct Nearest {
        double distance = kFar;
        std::size_t segment = kNoSegment;
        Vec2 point{0.0};
        bool found() const { return segment != kNoSegment; }
    };

    /// What nearest() keeps from one query to the next along a polyline: the last nearest
    /// segment (where the next search starts) and the chunks within `radius` of `center`.
    struct Cursor {
        std::uint64_t owner = 0;  // the index it was used with (0: none)
        std::size_t hint = kNoSegment;
        Vec2 center{0.0};
        double radius = -1.0;  // none gathered yet
        std::vector<std::uint32_t> chunks;
    };

    /// The closest point of the layer to `p` if closer than `cutoff` (the segment of smallest
    /// index among equally close ones). With a cursor (the previous vertex's query), the
    /// search starts from its segment: it and the kept segments after and before it while
    /// they get nearer bound the distance d, and only the chunks the cursor gathered are read
    /// when they hold every segment within d of p (else it gathers them again around p). The
    /// result does not depend on the cursor.
    Nearest nearest(const Vec2& p, double cutoff, Cursor* cursor = nullptr) const {
        if (cursor && cursor->owner != serial_) {  // a cursor of another index: start afresh
            *cursor = Cursor{};
            cursor->owner = serial_;
        }
        const std::size_t hint = cursor ? cursor->hint : kNoSegment;
        Nearest best;
        double best2 = kFar;
        // A segment or chunk is measured only when it may be as near as the best: what is
        // set aside is farther than `guard`, the best plus a slack far above the rounding of
        // the distances (ties are all measured, so the tie-break sees them).
        const double slack = 1e-9 * (std::abs(p.x) + std::abs(p.y) + magnitude_);
        double guard2 = kFar;
        // Farther than the guard, told without a division or a square root: the distance to
        // the end nearer along the segment, or to its line.
        auto far = [&](const Vec2& a, const Vec2& b) {
            const double dx = b.x - a.x, dy = b.y - a.y;
            const double wx = p.x - a.x, wy = p.y - a.y;
            const double dot = wx * dx + wy * dy, len2 = dx * dx + dy * dy;
            if (dot <= 0.0) return wx * wx + wy * wy > guard2;
            if (dot >= len2) {
                const double ex = p.x - b.x, ey = p.y - b.y;
                return ex * ex + ey * ey > guard2;
            }
            const double cross = wx * dy - wy * dx;
            return cross * cross > guard2 * len2;
        };
        // Kept segments are offered by their position q: their indices increase with it.
        std::size_t best_q = kNoSegment;
        auto offer = [&](std::size_t q) {
            const Ends& e = ends_[q];
            if (far(e.a, e.b)) return;
            Vec2 closest;
            const double d = point_segment_distance(p, e.a, e.b, &closest);
            if (d < best.distance || (d == best.distance && q < best_q)) {
                best.distance = d;
                best_q = q;
                best.point = closest;
                best2 = d * d;
                const double guard = d + 1e-9 * d + slack;
                guard2 = guard * guard;
            }
        };
        const std::size_t count = segments_.size();
        std::size_t lo = 1, hi = 0;  // positions the walk offered: [lo, hi]
        if (hint != kNoSegment) {
            lo = hi = position_[hint];
            offer(lo);
            while (hi + 1 < count) {
                offer(++hi);
                if (best_q != hi) break;
            }
            while (lo > 0) {
                offer(--lo);
                if (best_q != lo) break;
            }
            if (!(best.distance < cutoff)) {
                best = Nearest{};
                best_q = kNoSegment;
                best2 = kFar;
                lo = 1;
                hi = 0;
            }
        }
        auto beyond = [&](const Box2& b) {
            const double dx = std::max(std::max(b.min.x - p.x, p.x - b.max.x), 0.0);
            const double dy = std::max(std::max(b.min.y - p.y, p.y - b.max.y), 0.0);
            return dx * dx + dy * dy > guard2;
        };
        auto offer_chunk = [&](std::uint32_t c) {
            if (beyond(chunk_boxes_[c])) return best2;
            const std::size_t q0 = std::size_t{c} * kChunk;
            const std::size_t q1 = std::min(q0 + kChunk, count);
            for (std::size_t q = q0; q < q1; ++q) {
                if (lo <= q && q <= hi) continue;  // offered by the walk
                offer(q);
            }
            return best2;
        };
        if (best_q != kNoSegment && cursor) {
            // The gathered chunks hold every segment within d of p when p moved at most
            // radius - d from the center (slack: the rounding of these sums).
            const Vec2 m = p - cursor->center;
            const double room = cursor->radius - best.distance - slack;
            if (!(room >= 0.0 && m.x * m.x + m.y * m.y <= room * room)) {
                // Gathered with room for the next vertices (measured on the 8 x 10k stack).
                cursor->center = p;
                cursor->radius = 1.5 * best.distance + 0.5 * chunk_length_;
                cursor->chunks.clear();
                Box2 square;
                const double r = cursor->radius + slack;
                square.extend(p - Vec2(r));
                square.extend(p + Vec2(r));
                // A chunk filed in several cells comes once per cell: sorted, made unique.
                chunk_grid_.query(square, [&](std::uint32_t c) {
                    const Box2& b = chunk_boxes_[c];
                    const double dx = std::max(std::max(b.min.x - p.x, p.x - b.max.x), 0.0);
                    const double dy = std::max(std::max(b.min.y - p.y, p.y - b.max.y), 0.0);
                    if (dx * dx + dy * dy <= r * r) cursor->chunks.push_back(c);
                });
                std::sort(cursor->chunks.begin(), cursor->chunks.end());
                cursor->chunks.erase(std::unique(cursor->chunks.begin(), cursor->chunks.end()),
                                     cursor->chunks.end());
            }
            for (const std::uint32_t c : cursor->chunks) offer_chunk(c);
        } else if (best_q != kNoSegment) {
            chunk_grid_.nearest_within(p, best.distance, offer_chunk);
        } else {
            chunk_grid_.nearest(p, cutoff, offer_chunk);
        }
        if (best.distance < cutoff)
            best.segment = segments_[best_q];
        else
            best = Nearest{};
        if (cursor) cursor->hint = best.segment;
        return best;
    }

    /// Calls f(s) once per kept segment s whose box meets `b` (in no particular order).
    template <class F>
    void segments_meeting(const Box2& b, F&& f) const {
        chunk_grid_.query_once(
            b, [&](std::uint32_t c) { return chunk_boxes_[c]; },
            [&](std::uint32_t c) {
                const std::size_t q0 = std::size_t{c} * kChunk;
                const std::size_t q1 = std::min(q0 + kChunk, segments_.size());
                for (std::size_t q = q0; q < q1; ++q)
                    if (box(segments_[q]).overlaps(b)) f(segments_[q]);
            });
    }

  private:
    void add(std::size_t s) {
        position_[s] = segments_.size();
        segments_.push_back(s);
    }

    const Layer* layer_ = nullptr;
    std::vector<std::size_t> segments_;
    std::vector<std::size_t> position_;
    static constexpr std::size_t kChunk = 8;
    struct Ends {
        Vec2 a, b;
    };
    std::vector<Ends> ends_;    // the ends of each kept segment, by position
    std::uint64_t serial_ = 0;  // tells the cursors of this index (and its copies) from others
    double magnitude_ = 0.0;    // largest absolute coordinate of the layer
    double chunk_length_ = 0.0;
    std::vector<Box2> chunk_boxes_;  // chunk c: kept segments [c kChunk, (c + 1) kChunk)
    UniformGrid<std::uint32_t> chunk_grid_;
};

using Nearest = SegmentIndex::Nearest;

// Closest point of the indexed layer to `p` if closer than `cutoff`.
[[maybe_unused]] Nearest nearest_on(const SegmentIndex& index, const Vec2& p, double cutoff = kFar,
                                    SegmentIndex::Cursor* cursor = nullptr) {
    return index.nearest(p, cutoff, cursor);
}

[[maybe_unused]] double automatic_near(const Scene& scene) {
    double max_required = 0.0;
    for (std::size_t a = 0; a < scene.size(); ++a)
        for (std::size_t b = a + 1; b < scene.size(); ++b)
            max_required = std::max(max_required, scene.required_separation(a, b));
    const Vec2 size = scene.bounds().size();
    return std::max(0.05 * std::hypot(size.x, size.y), 2.0 * max_required);
}

// Side of `v` with respect to the open or closed layer of `index`, given `n`, its closest
// point there within `near` (not found when farther): +1 right of the direction of travel, -1
// left, 0 when not decided (farther than `near`, on the layer, or closest to an end point of
// an open layer).
[[maybe_unused]] int side_of(const SegmentIndex& index, const Vec2& v, const Nearest& n) {
    if (!n.found() || n.distance == 0.0) return 0;
    const std::size_t s = n.segment;
    const Vec2 a = index.start(s), b = index.end(s);
    const bool open = !index.layer().closed;
    std::size_t before = kNoSegment, after = kNoSegment;  // segments meeting at the closest vertex
    if (n.point == a) {
        if (open && index.is_first(s)) return 0;
        before = index.previous(s);
        after = s;
    } else if (n.point == b) {
        if (open && index.is_last(s)) return 0;
        before = s;
        after = index.next(s);
    }
    if (before == kNoSegment || after == kNoSegment) return segment_side(a, b, v);
    return corner_side(index.start(before), index.end(before), index.end(after), v);
}

// side_of() at the closest point within `near`; `cursor`: the previous vertex's query along
// a polyline (see SegmentIndex::nearest()).
[[maybe_unused]] int side_at(const SegmentIndex& index, const Vec2& v, double near,
                             SegmentIndex::Cursor& cursor) {
    return side_of(index, v, nearest_on(index, v, near, &cursor));
}

// The reach of record_input_sides() and of the second vote of open_outside(), in near
// distances: a layer a few gaps off another is within it.
constexpr double kSideReach = 3.0;

}  // namespace
}  // namespace strata::detail
