#include "strata/geometry/checks.h"

#include "geometry/detail/region_check.h"
#include "geometry/detail/uniform_grid.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

namespace strata {

namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool lex_less(const Vec2& a, const Vec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

// Cells of a grid over `bounds` for `count` segments of median length `median`: about the
// median, at most four cells a segment (scene units).
double cell_size(const Box2& bounds, double median, std::size_t count) {
    const Vec2 size = bounds.size();
    double h =
        std::max({median, 1e-9 * std::max(size.x, size.y), std::numeric_limits<double>::min()});
    const double budget = 4.0 * static_cast<double>(count) + 16.0;
    while ((size.x / h + 1.0) * (size.y / h + 1.0) > budget) h *= 2.0;
    return h;
}

// A uniform grid for `count` segments within `bounds`, cells dense over them.
detail::UniformGrid<std::uint32_t> segment_grid(const Box2& bounds, double median,
                                                std::size_t count) {
    detail::UniformGridParams p;
    p.cell = cell_size(bounds, median, count);
    p.origin = bounds.min;
    p.dense_bounds = bounds;
    return detail::UniformGrid<std::uint32_t>(p);
}

double median_of(std::vector<double>& values) {
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
        position_.assign(count, kNone);
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

    /// The kept segment after / before kept segment `s` (cyclic when closed), or kNone.
    std::size_t next(std::size_t s) const {
        const std::size_t k = position_[s];
        if (k + 1 < segments_.size()) return segments_[k + 1];
        return layer_->closed && segments_.size() > 1 ? segments_.front() : kNone;
    }
    std::size_t previous(std::size_t s) const {
        const std::size_t k = position_[s];
        if (k > 0) return segments_[k - 1];
        return layer_->closed && segments_.size() > 1 ? segments_.back() : kNone;
    }
    bool is_first(std::size_t s) const { return segments_.front() == s; }
    bool is_last(std::size_t s) const { return segments_.back() == s; }

    struct Nearest {
        double distance = kInf;
        std::size_t segment = kNone;
        Vec2 point{0.0};
        bool found() const { return segment != kNone; }
    };

    /// What nearest() keeps from one query to the next along a polyline: the last nearest
    /// segment (where the next search starts) and the chunks within `radius` of `center`.
    struct Cursor {
        std::uint64_t owner = 0;  // the index it was used with (0: none)
        std::size_t hint = kNone;
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
        const std::size_t hint = cursor ? cursor->hint : kNone;
        Nearest best;
        double best2 = kInf;
        // A segment or chunk is measured only when it may be as near as the best: what is
        // set aside is farther than `guard`, the best plus a slack far above the rounding of
        // the distances (ties are all measured, so the tie-break sees them).
        const double slack = 1e-9 * (std::abs(p.x) + std::abs(p.y) + magnitude_);
        double guard2 = kInf;
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
        std::size_t best_q = kNone;
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
        if (hint != kNone) {
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
                best_q = kNone;
                best2 = kInf;
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
        if (best_q != kNone && cursor) {
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
        } else if (best_q != kNone) {
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
    detail::UniformGrid<std::uint32_t> chunk_grid_;
};

using Nearest = SegmentIndex::Nearest;

// Closest point of the indexed layer to `p` if closer than `cutoff`.
Nearest nearest_on(const SegmentIndex& index, const Vec2& p, double cutoff = kInf,
                   SegmentIndex::Cursor* cursor = nullptr) {
    return index.nearest(p, cutoff, cursor);
}

double automatic_near(const Scene& scene) {
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
int side_of(const SegmentIndex& index, const Vec2& v, const Nearest& n) {
    if (!n.found() || n.distance == 0.0) return 0;
    const std::size_t s = n.segment;
    const Vec2 a = index.start(s), b = index.end(s);
    const bool open = !index.layer().closed;
    std::size_t before = kNone, after = kNone;  // segments meeting at the closest vertex
    if (n.point == a) {
        if (open && index.is_first(s)) return 0;
        before = index.previous(s);
        after = s;
    } else if (n.point == b) {
        if (open && index.is_last(s)) return 0;
        before = s;
        after = index.next(s);
    }
    if (before == kNone || after == kNone) return segment_side(a, b, v);
    return corner_side(index.start(before), index.end(before), index.end(after), v);
}

// side_of() at the closest point within `near`; `cursor`: the previous vertex's query along
// a polyline (see SegmentIndex::nearest()).
int side_at(const SegmentIndex& index, const Vec2& v, double near, SegmentIndex::Cursor& cursor) {
    return side_of(index, v, nearest_on(index, v, near, &cursor));
}

int closed_outside(const Layer& layer) {
    // Shoelace sum; positive: counter-clockwise, interior on the left, outside on the right.
    long double area = 0.0L;
    const std::size_t n = layer.points.size();
    for (std::size_t k = 0; k < n; ++k) {
        const Vec2& p = layer.points[k];
        const Vec2& q = layer.points[(k + 1) % n];
        area += static_cast<long double>(p.x) * q.y - static_cast<long double>(q.x) * p.y;
    }
    return area < 0.0L ? -1 : 1;
}

// The reach of record_input_sides() and of the second vote of open_outside(), in near
// distances: a layer a few gaps off another is within it.
constexpr double kSideReach = 3.0;

int open_outside(const Scene& scene, std::size_t i, const SegmentIndex& index, double near) {
    // The sum of sign x side over the vertices of `layers`; it stops once the vertices left
    // (each -1, 0 or +1) can no longer change its sign.
    auto tally = [&](const std::vector<std::size_t>& layers, int sign, double reach) {
        long vote = 0, left = 0;
        for (std::size_t j : layers) left += static_cast<long>(scene.layer(j).points.size());
        for (std::size_t j : layers) {
            SegmentIndex::Cursor cursor;
            for (const Vec2& v : scene.layer(j).points) {
                vote += sign * side_at(index, v, reach, cursor);
                if (std::abs(vote) > --left) return vote;
            }
        }
        return vote;
    };
    // Within near; when that gives no vote either way (the neighbours lie at about the near
    // distance), within kSideReach x near.
    for (const double reach : {near, kSideReach * near}) {
        if (const long vote = tally(scene.inner_of(i), -1, reach); vote != 0)
            return vote > 0 ? 1 : -1;
        if (const long vote = tally(scene.outer_of(i), 1, reach); vote != 0)
            return vote > 0 ? 1 : -1;
    }
    return 1;
}

enum class Placement { Inside, Outside, OnBoundary };

// Exact placement of `v` with respect to the closed layer of `index` (non-zero winding rule).
Placement placement(const SegmentIndex& index, const Box2& bounds, const Vec2& v) {
    if (!bounds.contains(v)) return Placement::Outside;
    // A ray from v to the nearer of the left and right sides of the bounds: to the left, the
    // winding number of the layer mirrored by x -> -x (exact; its sign changes, not whether
    // it is zero).
    const bool leftwards = v.x - bounds.min.x < bounds.max.x - v.x;
    const double sign = leftwards ? -1.0 : 1.0;
    auto seen = [sign](const Vec2& p) { return Vec2(sign * p.x, p.y); };
    Box2 ray;
    ray.extend(v);
    ray.extend(Vec2(leftwards ? bounds.min.x : bounds.max.x, v.y));
    long winding = 0;
    bool on_boundary = false;
    index.segments_meeting(ray, [&](std::size_t s) {
        const Vec2 p = index.start(s), q = index.end(s);
        const int o = orient2d(p, q, v);
        if (o == 0 && std::min(p.x, q.x) <= v.x && v.x <= std::max(p.x, q.x) &&
            std::min(p.y, q.y) <= v.y && v.y <= std::max(p.y, q.y))
            on_boundary = true;
        winding += winding_contribution(seen(p), seen(q), seen(v));
    });
    if (on_boundary) return Placement::OnBoundary;
    return winding != 0 ? Placement::Inside : Placement::Outside;
}

// A contact found by the sweep over segment pairs.
struct Contact {
    std::size_t la, sa, lb, sb;
    Vec2 point;
    bool is_touch;
};

bool contact_order(const Contact& x, const Contact& y) {
    return std::tie(x.la, x.sa, x.lb, x.sb) < std::tie(y.la, y.sa, y.lb, y.sb);
}

// Representative point of a Touch: the lexicographically smallest point of the intersection,
// which is always an end of one segment lying on the other.
Vec2 touch_point(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
    auto on = [](const Vec2& x, const Vec2& a, const Vec2& b) {
        return orient2d(a, b, x) == 0 && std::min(a.x, b.x) <= x.x && x.x <= std::max(a.x, b.x) &&
               std::min(a.y, b.y) <= x.y && x.y <= std::max(a.y, b.y);
    };
    bool any = false;
    Vec2 best{0.0};
    auto consider = [&](const Vec2& x, const Vec2& a, const Vec2& b) {
        if (on(x, a, b) && (!any || lex_less(x, best))) {
            best = x;
            any = true;
        }
    };
    consider(p0, q0, q1);
    consider(p1, q0, q1);
    consider(q0, p0, p1);
    consider(q1, p0, p1);
    return best;
}

// Adjacent segments [u, v] and [v, w] that fold back onto each other: collinear, opposite
// directions. Sets `point` to the representative point of their overlap.
bool folds_back(const Vec2& u, const Vec2& v, const Vec2& w, Vec2& point) {
    if (orient2d(u, v, w) != 0) return false;
    const bool use_x = u.x != v.x;
    const double cu = use_x ? u.x : u.y, cv = use_x ? v.x : v.y, cw = use_x ? w.x : w.y;
    if ((cv > cu) == (cw > cv)) return false;
    // u and w lie on the same side of v; the nearer one ends the overlap.
    const bool u_nearer = cu > cv ? cu <= cw : cu >= cw;
    const Vec2 other = u_nearer ? u : w;
    point = lex_less(other, v) ? other : v;
    return true;
}

// Merges the listed proper contacts with the deduplicated touches, keeps the first `cap`.
std::vector<Contact> merged_list(std::vector<Contact> proper, const std::vector<Contact>& touches,
                                 std::size_t cap) {
    proper.insert(proper.end(), touches.begin(), touches.end());
    std::sort(proper.begin(), proper.end(), contact_order);
    if (proper.size() > cap) proper.resize(cap);
    return proper;
}

Crossing to_crossing(const Contact& c) {
    Crossing x;
    x.layer_a = c.la;
    x.segment_a = c.sa;
    x.layer_b = c.lb;
    x.segment_b = c.sb;
    x.point = c.point;
    x.is_touch = c.is_touch;
    return x;
}

// The contacts among the kept segments of `indices` (every layer's) for which keep(i, s)
// holds, in one grid over them (ids in (layer, segment) order), each pair once, in the order
// of its first segment's id, then its second's: touch(i, s, j, t, point) for a touch (an
// adjacent pair of one layer that folds back included) at its representative point,
// cross(i, s, j, t, p0, p1, q0, q1) for a proper crossing of segment s of layer i (p0, p1)
// with segment t of layer j (q0, q1). find_contacts() (every segment) and run_region() (the
// segments near the region) share it.
template <class Keep, class Touch, class Cross>
void scan_contacts(const std::vector<SegmentIndex>& indices, Keep&& keep, Touch&& touch,
                   Cross&& cross) {
    std::vector<std::pair<std::size_t, std::size_t>> owner;
    std::vector<Box2> boxes;
    std::vector<double> lengths;
    std::size_t total = 0;
    for (std::size_t i = 0; i < indices.size(); ++i)
        for (std::size_t s : indices[i].segments())
            if (keep(i, s)) ++total;
    owner.reserve(total);
    boxes.reserve(total);
    lengths.reserve(total);
    Box2 all;
    for (std::size_t i = 0; i < indices.size(); ++i)
        for (std::size_t s : indices[i].segments()) {
            if (!keep(i, s)) continue;
            owner.emplace_back(i, s);
            boxes.push_back(indices[i].box(s));
            all.extend(boxes.back());
            const Vec2 d = indices[i].end(s) - indices[i].start(s);
            lengths.push_back(std::sqrt(d.x * d.x + d.y * d.y));  // sizes the cells only
        }
    if (owner.empty()) return;
    std::vector<std::uint32_t> ids(owner.size());
    for (std::size_t id = 0; id < ids.size(); ++id) ids[id] = static_cast<std::uint32_t>(id);
    detail::UniformGrid<std::uint32_t> grid = segment_grid(all, median_of(lengths), owner.size());
    grid.build(ids, [&](std::uint32_t id) { return boxes[id]; });
    std::vector<std::uint32_t> hits;
    for (std::size_t id = 0; id < owner.size(); ++id) {
        const auto [i, s] = owner[id];
        const SegmentIndex& a = indices[i];
        const Vec2 p0 = a.start(s), p1 = a.end(s);
        hits.clear();
        // Each cell's later segments whose boxes meet this one's; a segment filed in several
        // of these cells comes more than once: sorted, then made unique.
        const Box2& own = boxes[id];
        grid.query(own, [&](std::uint32_t hit) {
            if (hit > id && boxes[hit].overlaps(own)) hits.push_back(hit);
        });
        std::sort(hits.begin(), hits.end());
        hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
        for (const std::uint32_t hit : hits) {
            const auto [j, t] = owner[hit];
            const SegmentIndex& b = indices[j];
            const Vec2 q0 = b.start(t), q1 = b.end(t);
            if (i == j && (a.next(s) == t || a.next(t) == s)) {
                Vec2 point;
                if ((a.next(s) == t && folds_back(p0, p1, q1, point)) ||
                    (a.next(t) == s && folds_back(q0, q1, p1, point)))
                    touch(i, s, j, t, point);
                continue;
            }
            const SegmentContact contact = segment_contact(p0, p1, q0, q1);
            if (contact == SegmentContact::None) continue;
            if (contact == SegmentContact::Touch)
                touch(i, s, j, t, touch_point(p0, p1, q0, q1));
            else
                cross(i, s, j, t, p0, p1, q0, q1);
        }
    }
}

// The partition behind RegionCheck: what may change when only vertices inside `box` move
// (and their segments stay inside it), measured on the reference scene.
struct RegionPlan {
    Box2 box;
    /// How far a change inside the box is seen: max(near distance, the largest separation
    /// threshold), scene units.
    double reach = 0.0;
    /// Per layer and vertex: the reference position lies within `reach` of the box. The
    /// separations and the nesting of the other vertices do not change.
    std::vector<std::vector<char>> near_vertex;
    /// Per layer and segment: its reference box meets the box. A contact with a segment that
    /// does not, or a touch whose point lies outside the box, does not change.
    std::vector<std::vector<char>> near_segment;
};

// What check_scene() of the reference found away from the region of a RegionPlan: the same in
// every scene that differs from it only inside the region.
struct Away {
    std::size_t crossings = 0, touches = 0, self_crossings = 0;
    std::size_t separation_violations = 0, nesting_violations = 0;
    std::vector<char> met;    // met[a * n + b], a < b: the layers meet away from the region
    std::vector<double> gap;  // gap[a * n + b], a < b: over the vertices away from the region
};

class Checker {
  public:
    Checker(const Scene& scene, const CheckParams& params) : scene_(scene), params_(params) {
        n_ = scene.size();
        indices_.reserve(n_);
        bounds_.reserve(n_);
        for (std::size_t i = 0; i < n_; ++i) {
            indices_.emplace_back(scene.layer(i));
            bounds_.push_back(scene.layer(i).bounds());
        }
        met_.assign(n_ * n_, 0);
        met_point_.assign(n_ * n_, Vec2(0.0));
        report_.near_distance =
            params.near_distance > 0.0 ? params.near_distance : automatic_near(scene);
        report_.self_crossing_count.assign(n_, 0);
    }

    CheckReport run() {
        find_contacts();
        find_outside_sides();
        find_separations();
        find_nesting_violations();
        return std::move(report_);
    }

    /// run(), also filling `away` with what lies away from plan's region (see Away).
    CheckReport run(const RegionPlan& plan, Away& away) {
        plan_ = &plan;
        away_ = &away;
        away.met.assign(n_ * n_, 0);
        away.gap.assign(n_ * n_, kInf);
        return run();
    }

    /// The counts of run() from `away` (of the reference) and the contacts, separations and
    /// nesting near plan's region, which are checked here (RegionCheck::check()).
    CheckCounts run_region(const RegionPlan& plan, const Away& away);

  private:
    // run_region(): the vertices of layer `from` near plan's region against layer `to`: their
    // smallest distance below the cutoff into `gap` (pruned as scan_pair() prunes, from
    // `met` and the reference's `away_gap`), their separation and nesting violations.
    void scan_near_region(const RegionPlan& plan, const std::vector<char>& met,
                          const std::vector<double>& away_gap, std::size_t from, std::size_t to,
                          double& gap, std::size_t& separations, std::size_t& nesting) const {
        const double near = report_.near_distance;
        const std::size_t pair = std::min(from, to) * n_ + std::max(from, to);
        const double required = scene_.required_separation(from, to);
        const double threshold = required * (1.0 - params_.separation_tolerance);
        const double cutoff = std::max(near, threshold);
        const bool scanned = bounds_[from].inflated(cutoff).overlaps(bounds_[to]);
        const bool sides = sides_by_nearest(from, to);
        const bool closed = scene_.layer(to).closed;
        if (!scanned && !sides && !closed) return;
        const Relation rel = scene_.relation(from, to);
        const std::vector<char>& near_vertex = plan.near_vertex[from];
        const std::vector<Vec2>& points = scene_.layer(from).points;
        SegmentIndex::Cursor cursor;
        for (std::size_t k = 0; k < points.size(); ++k) {
            if (!near_vertex[k]) continue;
            if (closed) {
                const Placement where = placement(indices_[to], bounds_[to], points[k]);
                if (rel == Relation::Under ? where == Placement::Outside
                                           : where == Placement::Inside)
                    ++nesting;
            }
            if (!scanned && !sides) continue;
            // As scan_pair(): only a vertex closer than the gap so far (the layers meet: 0),
            // or than required, changes the separation.
            const double so_far = met[pair] ? 0.0 : std::min(gap, away_gap[pair]);
            const double bound =
                sides || !scanned ? cutoff : std::max(threshold, std::min(cutoff, so_far));
            const Nearest nr = nearest_on(indices_[to], points[k], bound, &cursor);
            if (!nr.found()) continue;
            if (sides && nr.distance < near &&
                breaks_nesting(from, k, to, side_of(indices_[to], points[k], nr)))
                ++nesting;
            if (!scanned) continue;
            gap = std::min(gap, nr.distance);
            if (nr.distance < threshold) ++separations;
        }
    }

  public:
  private:
    void note_meeting(std::size_t a, std::size_t b, const Vec2& p) {
        if (!met_[a * n_ + b]) {
            met_[a * n_ + b] = 1;
            met_point_[a * n_ + b] = p;
        }
    }

    // A contact of the reference away from the plan's region.
    void tally_away(const Contact& c) {
        if (c.la == c.lb) {
            ++away_->self_crossings;
            return;
        }
        ++away_->crossings;
        if (c.is_touch) ++away_->touches;
        away_->met[c.la * n_ + c.lb] = 1;
    }

    void find_contacts() {
        const std::size_t cap = params_.max_listed;
        std::vector<Contact> proper_cross, proper_self, touches;
        scan_contacts(
            indices_, [](std::size_t, std::size_t) { return true; },
            [&](std::size_t i, std::size_t s, std::size_t j, std::size_t t, const Vec2& point) {
                touches.push_back({i, s, j, t, point, true});
            },
            [&](std::size_t i, std::size_t s, std::size_t j, std::size_t t, const Vec2& p0,
                const Vec2& p1, const Vec2& q0, const Vec2& q1) {
                const Contact c{i, s, j, t, crossing_point(p0, p1, q0, q1), false};
                if (away_ && !(plan_->near_segment[i][s] && plan_->near_segment[j][t]))
                    tally_away(c);
                if (i == j) {
                    ++report_.self_crossing_count[i];
                    if (proper_self.size() < cap) proper_self.push_back(c);
                } else {
                    ++report_.crossing_count;
                    note_meeting(i, j, c.point);
                    if (proper_cross.size() < cap) proper_cross.push_back(c);
                }
            });

        // One contact location counts once: touches of the same two layers at the same
        // representative point merge, keeping the lowest segment pair.
        std::sort(touches.begin(), touches.end(), [](const Contact& x, const Contact& y) {
            return std::tie(x.la, x.lb, x.point.x, x.point.y, x.sa, x.sb) <
                   std::tie(y.la, y.lb, y.point.x, y.point.y, y.sa, y.sb);
        });
        touches.erase(std::unique(touches.begin(), touches.end(),
                                  [](const Contact& x, const Contact& y) {
                                      return x.la == y.la && x.lb == y.lb && x.point == y.point;
                                  }),
                      touches.end());
        std::vector<Contact> cross_touches, self_touches;
        for (const Contact& c : touches) {
            if (away_ && !plan_->box.contains(c.point)) tally_away(c);
            if (c.la == c.lb) {
                ++report_.self_crossing_count[c.la];
                self_touches.push_back(c);
            } else {
                ++report_.crossing_count;
                ++report_.touch_count;
                note_meeting(c.la, c.lb, c.point);
                cross_touches.push_back(c);
            }
        }
        for (const Contact& c : merged_list(std::move(proper_cross), cross_touches, cap))
            report_.crossings.push_back(to_crossing(c));
        for (const Contact& c : merged_list(std::move(proper_self), self_touches, cap))
            report_.self_crossings.push_back(to_crossing(c));
    }

    // One near pair's separation scan (find_separations()).
    struct PairScan {
        std::size_t i = 0, j = 0;
        double required = 0.0;
        bool listed = false;  // a near pair: goes into the report
        PairSeparation pair;
        std::vector<SeparationViolation> violations;
        // With a region plan: the gap over the vertices away from the region (not 0 when the
        // layers meet), and the violations there.
        double away_gap = kInf;
        std::size_t away_violations = 0;
    };

    // Pairs are scanned in parallel (TBB; one thread under a max_allowed_parallelism of 1),
    // then reported in (i, j) order: the report does not depend on the threads.
    void find_separations() {
        const double near = report_.near_distance;
        std::vector<PairScan> scans;
        for (std::size_t i = 0; i < n_; ++i)
            for (std::size_t j = i + 1; j < n_; ++j) {
                const double required = scene_.required_separation(i, j);
                const double cutoff =
                    std::max(near, required * (1.0 - params_.separation_tolerance));
                if (!bounds_[i].inflated(cutoff).overlaps(bounds_[j])) continue;
                PairScan scan;
                scan.i = i;
                scan.j = j;
                scan.required = required;
                scans.push_back(std::move(scan));
            }
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, scans.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t k = range.begin(); k != range.end(); ++k)
                                  scan_pair(scans[k]);
                          });
        for (const PairScan& scan : scans) {
            if (away_) {
                away_->gap[scan.i * n_ + scan.j] = scan.away_gap;
                away_->separation_violations += scan.away_violations;
            }
            if (!scan.listed) continue;
            add_pair(scan.i, scan.j, scan.pair.gap, scan.required, scan.pair.at_a, scan.pair.at_b);
            report_.separation_violation_count += scan.violations.size();
            for (const SeparationViolation& v : scan.violations)
                if (report_.separation_violations.size() < params_.max_listed)
                    report_.separation_violations.push_back(v);
        }
    }

    void scan_pair(PairScan& scan) const {
        const std::size_t i = scan.i, j = scan.j;
        const double near = report_.near_distance;
        const double threshold = scan.required * (1.0 - params_.separation_tolerance);
        const double cutoff = std::max(near, threshold);
        PairSeparation& pair = scan.pair;
        const bool met = met_[i * n_ + j] != 0;
        pair.gap = met ? 0.0 : kInf;
        pair.at_a = pair.at_b = met_point_[i * n_ + j];
        // With a region plan the vertices away from it keep their own gap (away_gap, from
        // +inf even when the layers meet: they may not meet in a scene moved in the region).
        if (met && threshold <= 0.0 && !plan_) {
            scan.listed = true;
            return;
        }
        // Away vertices: the closest so far, and where (its order in the scan).
        PairSeparation away;
        away.gap = kInf;
        std::size_t away_order = kNone, order = 0, near_order = kNone;
        auto one_way = [&](std::size_t from, std::size_t to, bool from_is_a) {
            // Where nesting is decided by the side at the closest point, the same queries
            // (then with the whole cutoff >= near) decide it too.
            const bool sides = sides_by_nearest(from, to);
            if (sides) sides_scanned_[from * n_ + to] = 1;
            const std::vector<Vec2>& points = scene_.layer(from).points;
            const std::vector<char>* near_vertex = plan_ ? &plan_->near_vertex[from] : nullptr;
            SegmentIndex::Cursor cursor;  // the previous vertex's query
            for (std::size_t k = 0; k < points.size(); ++k, ++order) {
                const bool is_away = near_vertex && !(*near_vertex)[k];
                PairSeparation& gap = is_away ? away : pair;
                // Only a vertex closer than the pair's gap so far, or than required, changes
                // the separation: the search stops there.
                const double bound =
                    sides ? cutoff : std::max(threshold, std::min(cutoff, gap.gap));
                const Nearest nr = nearest_on(indices_[to], points[k], bound, &cursor);
                if (!nr.found()) continue;
                if (sides && nr.distance < near &&
                    breaks_nesting(from, k, to, side_of(indices_[to], points[k], nr)))
                    wrong_side_[from * n_ + to].push_back(k);
                if (nr.distance < gap.gap) {
                    gap.gap = nr.distance;
                    gap.at_a = from_is_a ? points[k] : nr.point;
                    gap.at_b = from_is_a ? nr.point : points[k];
                    (is_away ? away_order : near_order) = order;
                }
                if (nr.distance < threshold) {
                    scan.violations.push_back({from, k, to, nr.distance, scan.required});
                    if (is_away) ++scan.away_violations;
                }
            }
        };
        one_way(i, j, true);
        one_way(j, i, false);
        if (plan_) {
            scan.away_gap = away.gap;
            // The closest of both, the first in the scan on a tie: what one gap would keep.
            if (!met &&
                (away.gap < pair.gap || (away.gap == pair.gap && away_order < near_order))) {
                pair.gap = away.gap;
                pair.at_a = away.at_a;
                pair.at_b = away.at_b;
            }
        }
        scan.listed = pair.gap < near;
    }

    void add_pair(std::size_t i, std::size_t j, double gap, double required, const Vec2& at_a,
                  const Vec2& at_b) {
        PairSeparation pair;
        pair.layer_a = i;
        pair.layer_b = j;
        pair.relation = scene_.relation(i, j);
        pair.gap = gap;
        pair.required = required;
        pair.at_a = at_a;
        pair.at_b = at_b;
        if (required > 0.0)
            report_.min_separation_ratio = std::min(report_.min_separation_ratio, pair.ratio());
        report_.pairs.push_back(pair);
    }

    // Outside sides of the open layers (see outside_side()).
    void find_outside_sides() {
        outside_.assign(n_, 0);
        tbb::parallel_for(std::size_t{0}, n_, [&](std::size_t b) {
            if (!scene_.layer(b).closed)
                outside_[b] = params_.outside_sides.empty()
                                  ? open_outside(scene_, b, indices_[b], report_.near_distance)
                                  : params_.outside_sides[b];
        });
        sides_scanned_.assign(n_ * n_, 0);
        wrong_side_.assign(n_ * n_, {});
    }

    // Nesting of layer a against open layer b is decided by the side of b at each vertex's
    // closest point (within near); false where it is decided otherwise or not at all.
    bool sides_by_nearest(std::size_t a, std::size_t b) const {
        return !scene_.layer(b).closed && scene_.relation(a, b) != Relation::SideBySide &&
               bounds_[a].overlaps(bounds_[b].inflated(report_.near_distance));
    }

    // Vertex k of layer a on `side` (side_of()) of open layer b breaks their nesting: the
    // side is not the one recorded in the input (params.input_sides), or, where nothing is
    // recorded, not the one the global order asks for.
    bool breaks_nesting(std::size_t a, std::size_t k, std::size_t b, int side) const {
        if (side == 0) return false;
        int wanted = params_.input_sides ? params_.input_sides->side(a, k, b) : 0;
        if (wanted == 0) wanted = global_side(scene_.relation(a, b), outside_[b]);
        return wanted != 0 && side != wanted;
    }

    // Ordered pairs in parallel, reported in (a, b) order.
    void find_nesting_violations() {
        std::vector<std::pair<std::size_t, std::size_t>> tasks;
        for (std::size_t a = 0; a < n_; ++a)
            for (std::size_t b = 0; b < n_; ++b)
                if (a != b && !sides_scanned_[a * n_ + b] &&
                    (scene_.layer(b).closed || sides_by_nearest(a, b)))
                    tasks.emplace_back(a, b);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t k = range.begin(); k != range.end(); ++k)
                                  find_wrong_side(tasks[k].first, tasks[k].second);
                          });
        for (std::size_t a = 0; a < n_; ++a)
            for (std::size_t b = 0; b < n_; ++b) {
                if (a == b) continue;
                for (std::size_t k : wrong_side_[a * n_ + b]) {
                    if (away_ && !plan_->near_vertex[a][k]) ++away_->nesting_violations;
                    ++report_.nesting_violation_count;
                    if (report_.nesting_violations.size() < params_.max_listed)
                        report_.nesting_violations.push_back({a, k, b, scene_.relation(a, b)});
                }
            }
    }

    // The vertices of layer a on the wrong side of layer b, into wrong_side_[a * n + b].
    void find_wrong_side(std::size_t a, std::size_t b) const {
        const Relation rel = scene_.relation(a, b);
        const Layer& other = scene_.layer(b);
        const std::vector<Vec2>& points = scene_.layer(a).points;
        std::vector<std::size_t>& out = wrong_side_[a * n_ + b];
        SegmentIndex::Cursor cursor;
        for (std::size_t k = 0; k < points.size(); ++k) {
            bool broken = false;
            if (other.closed) {
                const Placement where = placement(indices_[b], bounds_[b], points[k]);
                broken = rel == Relation::Under ? where == Placement::Outside
                                                : where == Placement::Inside;
            } else {
                broken = breaks_nesting(
                    a, k, b, side_at(indices_[b], points[k], report_.near_distance, cursor));
            }
            if (broken) out.push_back(k);
        }
    }

    const Scene& scene_;
    const CheckParams& params_;
    const RegionPlan* plan_ = nullptr;  // run(plan, away): what is near the region
    Away* away_ = nullptr;              // and what run() found away from it
    std::size_t n_ = 0;
    std::vector<SegmentIndex> indices_;
    std::vector<Box2> bounds_;
    std::vector<char> met_;  // met_[a * n + b], a < b: the layers cross or touch
    std::vector<Vec2> met_point_;
    std::vector<int> outside_;  // per open layer: outside_side()
    // sides_scanned_[a * n + b]: find_separations() decided the nesting of a against b, and
    // wrong_side_[a * n + b] lists the vertices of a on the wrong side of b.
    // Written by the parallel scans, each task its own entries.
    mutable std::vector<char> sides_scanned_;
    mutable std::vector<std::vector<std::size_t>> wrong_side_;
    CheckReport report_;
};

CheckCounts Checker::run_region(const RegionPlan& plan, const Away& away) {
    plan_ = &plan;
    find_outside_sides();
    const Box2& region = plan.box;
    CheckCounts counts;
    counts.crossing_count = away.crossings;
    counts.touch_count = away.touches;
    counts.self_crossing_count = away.self_crossings;
    counts.separation_violation_count = away.separation_violations;
    counts.nesting_violation_count = away.nesting_violations;
    std::vector<char> met = away.met;
    // Contacts between the segments near the region, as find_contacts() finds them; of the
    // touches, those at a point in the region (the others do not change).
    std::vector<Contact> touches;
    scan_contacts(
        indices_, [&](std::size_t i, std::size_t s) { return plan.near_segment[i][s] != 0; },
        [&](std::size_t i, std::size_t s, std::size_t j, std::size_t t, const Vec2& point) {
            if (region.contains(point)) touches.push_back({i, s, j, t, point, true});
        },
        [&](std::size_t i, std::size_t, std::size_t j, std::size_t, const Vec2&, const Vec2&,
            const Vec2&, const Vec2&) {
            if (i == j) {
                ++counts.self_crossing_count;
            } else {
                ++counts.crossing_count;
                met[i * n_ + j] = 1;
            }
        });
    std::sort(touches.begin(), touches.end(), [](const Contact& x, const Contact& y) {
        return std::tie(x.la, x.lb, x.point.x, x.point.y) <
               std::tie(y.la, y.lb, y.point.x, y.point.y);
    });
    touches.erase(std::unique(touches.begin(), touches.end(),
                              [](const Contact& x, const Contact& y) {
                                  return x.la == y.la && x.lb == y.lb && x.point == y.point;
                              }),
                  touches.end());
    for (const Contact& c : touches) {
        if (c.la == c.lb) {
            ++counts.self_crossing_count;
        } else {
            ++counts.crossing_count;
            ++counts.touch_count;
            met[c.la * n_ + c.lb] = 1;
        }
    }
    // Separations and nesting of the vertices near the region, as find_separations() and
    // find_nesting_violations() judge them; ordered pairs of layers in parallel, each with
    // its own counts and gap, summed in order (the counts do not depend on the threads).
    const double near = report_.near_distance;
    struct Task {
        std::size_t from = 0, to = 0;
        std::size_t separations = 0, nesting = 0;
        double gap = kInf;
    };
    std::vector<Task> tasks;
    for (std::size_t from = 0; from < n_; ++from)
        for (std::size_t to = 0; to < n_; ++to)
            if (to != from) tasks.push_back({from, to});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t t = range.begin(); t != range.end(); ++t)
                              scan_near_region(plan, met, away.gap, tasks[t].from, tasks[t].to,
                                               tasks[t].gap, tasks[t].separations,
                                               tasks[t].nesting);
                      });
    std::vector<double> gap = away.gap;
    for (const Task& task : tasks) {
        const std::size_t pair = std::min(task.from, task.to) * n_ + std::max(task.from, task.to);
        gap[pair] = std::min(gap[pair], task.gap);
        counts.separation_violation_count += task.separations;
        counts.nesting_violation_count += task.nesting;
    }
    for (std::size_t i = 0; i < n_; ++i)
        for (std::size_t j = i + 1; j < n_; ++j) {
            const double required = scene_.required_separation(i, j);
            const double g = met[i * n_ + j] ? 0.0 : gap[i * n_ + j];
            if (g < near && required > 0.0)
                counts.min_separation_ratio = std::min(counts.min_separation_ratio, g / required);
        }
    return counts;
}

// max over the points of `a` of the distance to `b`, by branch and bound (see hausdorff()).
// An interval [p0, p1] of a segment of `a`, with nearest segments s0, s1 of `b` at its ends,
// is bounded above by the 1-Lipschitz bound (d0 + d1 + L) / 2 and, since the distance to one
// segment is convex along a line, by max(d(p0, s), d(p1, s)) for s = s0, s1. The second
// bound settles parallel and receding stretches without splitting them to the tolerance.
double one_sided_hausdorff(const Layer& a, const SegmentIndex& b, double tolerance) {
    struct End {
        Vec2 p;
        double d;
        std::size_t s;
    };
    struct Interval {
        double upper;
        End e0, e1;
        bool operator<(const Interval& other) const { return upper < other.upper; }
    };
    auto evaluate = [&](const Vec2& p, SegmentIndex::Cursor* cursor = nullptr) {
        const Nearest n = nearest_on(b, p, kInf, cursor);
        return End{p, n.distance, n.segment};
    };
    auto to_segment = [&](const Vec2& p, std::size_t s) {
        return point_segment_distance(p, b.start(s), b.end(s));
    };
    double lower = 0.0;
    std::vector<Interval> heap;
    auto push = [&](const End& e0, const End& e1) {
        const double length = std::hypot(e1.p.x - e0.p.x, e1.p.y - e0.p.y);
        double upper = 0.5 * (e0.d + e1.d + length);
        upper = std::min(upper, std::max(e0.d, to_segment(e1.p, e0.s)));
        upper = std::min(upper, std::max(e1.d, to_segment(e0.p, e1.s)));
        if (upper > lower + tolerance) {
            heap.push_back({upper, e0, e1});
            std::push_heap(heap.begin(), heap.end());
        }
    };
    std::vector<End> vertices;
    vertices.reserve(a.points.size());
    SegmentIndex::Cursor cursor;  // the vertices in order: each search starts at the last
    for (const Vec2& p : a.points) {
        vertices.push_back(evaluate(p, &cursor));
        lower = std::max(lower, vertices.back().d);
    }
    const std::size_t count = a.segment_count();
    for (std::size_t s = 0; s < count; ++s) push(vertices[s], vertices[(s + 1) % vertices.size()]);
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end());
        const Interval top = heap.back();
        heap.pop_back();
        if (top.upper <= lower + tolerance) break;  // every other bound is lower still
        const Vec2 mid = 0.5 * (top.e0.p + top.e1.p);
        if (mid == top.e0.p || mid == top.e1.p) continue;  // no finer split in doubles
        const End m = evaluate(mid);
        lower = std::max(lower, m.d);
        push(top.e0, m);
        push(m, top.e1);
    }
    return lower;
}

void check_hausdorff_input(const Layer& layer, const char* which) {
    if (layer.points.empty())
        throw InvalidInput(std::string("hausdorff: layer ") + which + " ('" + layer.name +
                           "') has no points");
    for (std::size_t k = 0; k < layer.points.size(); ++k) {
        const Vec2& p = layer.points[k];
        if (!std::isfinite(p.x) || !std::isfinite(p.y))
            throw InvalidInput(std::string("hausdorff: layer ") + which + " ('" + layer.name +
                               "'): point " + std::to_string(k) + " has a non-finite coordinate (" +
                               format_number(p.x) + ", " + format_number(p.y) + ")");
    }
}

// A layer as seen by the distance queries: a single point becomes one zero-length segment.
Layer as_segments(const Layer& layer) {
    Layer copy;
    copy.name = layer.name;
    copy.closed = layer.closed && layer.points.size() >= 3;
    copy.points = layer.points;
    if (copy.points.size() == 1) copy.points.push_back(copy.points.front());
    return copy;
}

}  // namespace

void validate(const CheckParams& params) {
    if (!std::isfinite(params.near_distance) || params.near_distance < 0.0)
        throw InvalidInput("check: params.near_distance must be a finite value >= 0 (got " +
                           format_number(params.near_distance) + ")");
    if (!std::isfinite(params.separation_tolerance) || params.separation_tolerance < 0.0 ||
        params.separation_tolerance >= 1.0)
        throw InvalidInput("check: params.separation_tolerance must be in [0, 1) (got " +
                           format_number(params.separation_tolerance) + ")");
}

std::size_t CheckReport::total_self_crossings() const {
    std::size_t total = 0;
    for (std::size_t c : self_crossing_count) total += c;
    return total;
}

bool CheckReport::is_collision_free() const {
    return crossing_count == 0 && total_self_crossings() == 0 && nesting_violation_count == 0;
}

double automatic_near_distance(const Scene& scene) {
    return automatic_near(scene);
}

namespace {

// validate(params), and params.outside_sides against `scene`.
void validate_outside_sides(const Scene& scene, const CheckParams& params) {
    validate(params);
    if (!params.outside_sides.empty() && params.outside_sides.size() != scene.size())
        throw InvalidInput("check: params.outside_sides has " +
                           std::to_string(params.outside_sides.size()) + " entries for " +
                           std::to_string(scene.size()) + " layers");
    for (std::size_t i = 0; i < params.outside_sides.size(); ++i)
        if (!scene.layer(i).closed && params.outside_sides[i] != 1 && params.outside_sides[i] != -1)
            throw InvalidInput("check: params.outside_sides[" + std::to_string(i) + "] (layer '" +
                               scene.layer(i).name + "') must be +1 or -1 (got " +
                               std::to_string(params.outside_sides[i]) + ")");
}

}  // namespace

CheckReport check_scene(const Scene& scene, const CheckParams& params) {
    validate_outside_sides(scene, params);
    return Checker(scene, params).run();
}

// Defined here, next to the nearest queries and the side rule that check_scene() uses, so
// that the recorded sides and the checked ones are decided by the same code.
struct InputSides::Recorded {
    static constexpr signed char kUnknown = 3;  // not found yet

    Scene scene;
    double reach = 0.0;
    std::size_t n = 0;
    // memo[a * n + b][k]: the code of vertex k of layer a against open layer b (kUnknown
    // until asked for); null where nothing is recorded (b closed, side by side, out of reach).
    std::vector<std::unique_ptr<std::atomic<signed char>[]>> memo;
    // The segment index of each open layer, built when first needed.
    mutable std::vector<std::unique_ptr<SegmentIndex>> indices;
    std::unique_ptr<std::once_flag[]> built;

    const SegmentIndex& index(std::size_t b) const {
        std::call_once(built[b],
                       [&] { indices[b] = std::make_unique<SegmentIndex>(scene.layer(b)); });
        return *indices[b];
    }

    int code(std::size_t a, std::size_t k, std::size_t b) const {
        const std::unique_ptr<std::atomic<signed char>[]>& found = memo[a * n + b];
        const std::vector<Vec2>& points = scene.layer(a).points;
        if (!found || k >= points.size()) return 0;
        signed char c = found[k].load(std::memory_order_relaxed);
        if (c != kUnknown) return c;
        // Threads that ask at once find the same value.
        const SegmentIndex& other = index(b);
        // Callers ask vertex after vertex: each thread's search starts where its last one
        // ended on the same layer (the result does not depend on where it starts).
        thread_local SegmentIndex::Cursor cursor;
        const Nearest nr = nearest_on(other, points[k], reach, &cursor);
        const int side = side_of(other, points[k], nr);
        // Found, not on b, and no side: closest to an end point of b.
        c = side == 0 && nr.found() && nr.distance > 0.0 ? InputSides::kBeyondEnd
                                                         : static_cast<signed char>(side);
        found[k].store(c, std::memory_order_relaxed);
        return c;
    }
};

InputSides record_input_sides(const Scene& scene, const InputSideParams& params) {
    validate(params);
    auto r = std::make_shared<InputSides::Recorded>();
    r->scene = scene;
    r->reach = params.reach > 0.0 ? params.reach : kSideReach * automatic_near(scene);
    const std::size_t n = scene.size();
    r->n = n;
    r->memo.resize(n * n);
    r->indices.resize(n);
    r->built = std::make_unique<std::once_flag[]>(n);
    std::vector<Box2> bounds;
    for (std::size_t i = 0; i < n; ++i) bounds.push_back(scene.layer(i).bounds());
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b) {
            const Relation rel = a == b ? Relation::Same : scene.relation(a, b);
            if (scene.layer(b).closed || (rel != Relation::Under && rel != Relation::Over) ||
                !bounds[a].overlaps(bounds[b].inflated(r->reach)))
                continue;
            const std::size_t count = scene.layer(a).points.size();
            auto& found = r->memo[a * n + b];
            found = std::make_unique<std::atomic<signed char>[]>(count);
            for (std::size_t k = 0; k < count; ++k)
                found[k].store(InputSides::Recorded::kUnknown, std::memory_order_relaxed);
        }
    InputSides out;
    out.n_ = n;
    out.recorded_ = std::move(r);
    return out;
}

InputSides InputSides::from_codes(const Scene& scene, std::vector<std::vector<signed char>> codes) {
    auto r = std::make_shared<InputSides::Recorded>();
    r->scene = scene;
    const std::size_t n = scene.size();
    r->n = n;
    r->memo.resize(n * n);
    r->indices.resize(n);
    r->built = std::make_unique<std::once_flag[]>(n);
    for (std::size_t p = 0; p < n * n && p < codes.size(); ++p) {
        const std::vector<signed char>& from = codes[p];
        if (from.empty()) continue;
        // Every code known: no query is ever made.
        const std::size_t count = scene.layer(p / n).points.size();
        auto& found = r->memo[p];
        found = std::make_unique<std::atomic<signed char>[]>(count);
        for (std::size_t k = 0; k < count; ++k)
            found[k].store(k < from.size() ? from[k] : 0, std::memory_order_relaxed);
    }
    InputSides out;
    out.n_ = n;
    out.recorded_ = std::move(r);
    return out;
}

int InputSides::code(std::size_t a, std::size_t k, std::size_t b) const {
    if (a >= n_ || b >= n_ || !recorded_) return 0;
    if (!origin_.empty()) {
        if (k >= origin_[a].size()) return 0;
        k = origin_[a][k];
    }
    if (!layer_.empty()) {
        a = layer_[a];
        b = layer_[b];
        if (a == kNoLayer || b == kNoLayer) return 0;
    }
    return recorded_->code(a, k, b);
}

std::size_t InputSides::vertex_count(std::size_t a) const {
    if (a >= n_ || !recorded_) return 0;
    if (!origin_.empty()) return origin_[a].size();
    const std::size_t r = layer_.empty() ? a : layer_[a];
    return r == kNoLayer ? 0 : recorded_->scene.layer(r).points.size();
}

namespace {

// InputSides::matched()'s reordering of the matches `match` of `points` (open layer) onto
// the reference layer `ref`: see there. `exact`: the vertex is its matched reference vertex.
void match_in_order(const std::vector<Vec2>& points, const std::vector<Vec2>& ref,
                    const std::vector<char>& exact, std::vector<std::size_t>& match) {
    const std::size_t n = points.size();
    std::size_t j = 0;
    std::size_t lo = 0;  // the reference index of the last unmoved vertex (0: none yet)
    while (j < n) {
        if (exact[j]) {
            lo = match[j];
            ++j;
            continue;
        }
        std::size_t e = j;
        while (e < n && !exact[e]) ++e;
        const std::size_t hi = e < n ? match[e] : ref.size() - 1;
        bool ordered = lo <= hi;
        for (std::size_t k = j; k < e && ordered; ++k)
            ordered = match[k] >= lo && match[k] <= hi && (k == j || match[k - 1] <= match[k]);
        if (!ordered && lo <= hi &&
            static_cast<double>(hi - lo + 1) * static_cast<double>(e - j) <= 4e6) {
            // Candidates per vertex, by reference index; Viterbi over non-decreasing indices.
            struct Cand {
                std::size_t k;
                double d, cost;
                std::size_t from;
            };
            std::vector<std::vector<Cand>> cands(e - j);
            for (std::size_t v = j; v < e; ++v) {
                double nearest = kInf;
                for (std::size_t k = lo; k <= hi; ++k)
                    nearest = std::min(nearest, std::hypot(points[v].x - ref[k].x, points[v].y - ref[k].y));
                std::vector<Cand>& c = cands[v - j];
                for (std::size_t k = lo; k <= hi; ++k) {
                    const double d = std::hypot(points[v].x - ref[k].x, points[v].y - ref[k].y);
                    if (d <= 3.0 * nearest) c.push_back({k, d, kInf, kNone});
                }
                if (c.size() > 16) {
                    std::nth_element(c.begin(), c.begin() + 16, c.end(),
                                     [](const Cand& x, const Cand& y) { return x.d < y.d; });
                    c.resize(16);
                    std::sort(c.begin(), c.end(),
                              [](const Cand& x, const Cand& y) { return x.k < y.k; });
                }
            }
            for (Cand& c : cands[0]) c.cost = c.d;
            for (std::size_t r = 1; r < cands.size(); ++r)
                for (Cand& c : cands[r])
                    for (std::size_t q = 0; q < cands[r - 1].size(); ++q) {
                        const Cand& p = cands[r - 1][q];
                        if (p.k <= c.k && p.cost + c.d < c.cost) {
                            c.cost = p.cost + c.d;
                            c.from = q;
                        }
                    }
            std::size_t best = kNone;
            for (std::size_t q = 0; q < cands.back().size(); ++q)
                if (cands.back()[q].cost < kInf &&
                    (best == kNone || cands.back()[q].cost < cands.back()[best].cost))
                    best = q;
            for (std::size_t r = cands.size(); best != kNone && r-- > 0;) {
                match[j + r] = cands[r][best].k;
                best = cands[r][best].from;
            }
        }
        j = e;
    }
}

}  // namespace

InputSides InputSides::matched(const InputSides& recorded, const Scene& reference,
                               const Scene& scene) {
    InputSides out;
    if (recorded.empty()) return out;
    const std::size_t n = scene.size();
    out.n_ = n;
    out.recorded_ = recorded.recorded_;
    out.layer_.assign(n, kNoLayer);
    out.origin_.assign(n, {});
    for (std::size_t a = 0; a < n; ++a) {
        const std::optional<std::size_t> namesake = reference.find(scene.layer(a).name);
        if (!namesake || *namesake >= recorded.n_) continue;
        const std::size_t ra = *namesake;
        out.layer_[a] = recorded.layer_.empty() ? ra : recorded.layer_[ra];
        if (out.layer_[a] == kNoLayer) continue;
        const Layer& ref_layer = reference.layer(ra);
        const SegmentIndex index(ref_layer);
        const std::vector<Vec2>& ref = ref_layer.points;
        const std::vector<Vec2>& points = scene.layer(a).points;
        // The reference vertex of each vertex of layer a: the nearer end of its closest segment.
        std::vector<std::size_t> match(points.size(), 0);
        std::vector<char> exact(points.size(), 0);  // the vertex is that reference vertex
        for (std::size_t j = 0; j < points.size(); ++j) {
            const Nearest nr = nearest_on(index, points[j]);
            if (!nr.found()) continue;
            const Vec2 s0 = index.start(nr.segment), s1 = index.end(nr.segment);
            const bool first = std::hypot(nr.point.x - s0.x, nr.point.y - s0.y) <=
                               std::hypot(nr.point.x - s1.x, nr.point.y - s1.y);
            match[j] = first ? nr.segment : (nr.segment + 1) % ref.size();
            exact[j] = points[j] == ref[match[j]];
        }
        // A simplification keeps its vertices in their order. Where the matches of a run of
        // vertices that moved (untangled) between two that did not are out of that order (a
        // vertex closest to another sheet of a roll, nearer than it moved), the run takes the
        // reference vertices in order, between those of its unmoved ends, that are nearest in
        // all (each vertex choosing among the reference vertices within 3 times its nearest
        // one's distance; runs whose stretch times length exceeds 4e6 keep their matches).
        if (!ref_layer.closed) match_in_order(points, ref, exact, match);
        std::vector<std::size_t>& origin = out.origin_[a];
        for (std::size_t k : match) {
            if (!recorded.origin_.empty())
                k = k < recorded.origin_[ra].size() ? recorded.origin_[ra][k] : kNoLayer;
            origin.push_back(k);
        }
    }
    return out;
}

int outside_side(const Scene& scene, std::size_t i, double near_distance) {
    const Layer& layer = scene.layer(i);
    if (layer.closed) return closed_outside(layer);
    if (!std::isfinite(near_distance) || near_distance < 0.0)
        throw InvalidInput("outside_side: near_distance must be a finite value >= 0 (got " +
                           format_number(near_distance) + ")");
    const double near = near_distance > 0.0 ? near_distance : automatic_near(scene);
    return open_outside(scene, i, SegmentIndex(layer), near);
}

int outside_side(const Scene& scene, std::size_t i) {
    return outside_side(scene, i, 0.0);
}

std::vector<int> outside_sides(const Scene& scene, double near_distance) {
    std::vector<int> sides;
    sides.reserve(scene.size());
    for (std::size_t l = 0; l < scene.size(); ++l)
        sides.push_back(outside_side(scene, l, near_distance));
    return sides;
}

HausdorffDistance hausdorff(const Layer& a, const Layer& b, double tolerance) {
    if (!std::isfinite(tolerance) || tolerance <= 0.0)
        throw InvalidInput("hausdorff: tolerance must be a finite value > 0 (got " +
                           format_number(tolerance) + ")");
    check_hausdorff_input(a, "a");
    check_hausdorff_input(b, "b");
    const Layer sa = as_segments(a), sb = as_segments(b);
    const SegmentIndex ia(sa), ib(sb);
    HausdorffDistance result;
    result.a_to_b = one_sided_hausdorff(sa, ib, tolerance);
    result.b_to_a = one_sided_hausdorff(sb, ia, tolerance);
    return result;
}

CheckCounts counts_of(const CheckReport& report) {
    CheckCounts counts;
    counts.crossing_count = report.crossing_count;
    counts.touch_count = report.touch_count;
    counts.self_crossing_count = report.total_self_crossings();
    counts.separation_violation_count = report.separation_violation_count;
    counts.nesting_violation_count = report.nesting_violation_count;
    counts.min_separation_ratio = report.min_separation_ratio;
    return counts;
}

struct RegionCheck::State {
    const Scene* reference = nullptr;
    CheckParams params;
    bool is_enabled = false;  // else every check() checks the whole scene
    RegionPlan plan;
    Away away;
    CheckReport report;
    CheckCounts counts;  // of `report`
    std::atomic<std::size_t> whole_checks{0};  // check() may be called from several threads
};

RegionCheck::RegionCheck(const Scene& reference, const CheckParams& params, const Box2& region)
    : state_(std::make_unique<State>()) {
    State& st = *state_;
    st.reference = &reference;
    st.params = params;
    st.is_enabled = !region.is_empty() && !params.outside_sides.empty();
    if (!st.is_enabled) {
        st.report = check_scene(reference, params);
        st.counts = counts_of(st.report);
        return;
    }
    validate_outside_sides(reference, params);
    RegionPlan& plan = st.plan;
    plan.box = region;
    const double near =
        params.near_distance > 0.0 ? params.near_distance : automatic_near(reference);
    double largest = 0.0;
    for (std::size_t a = 0; a < reference.size(); ++a)
        for (std::size_t b = a + 1; b < reference.size(); ++b)
            largest = std::max(largest, reference.required_separation(a, b));
    plan.reach = std::max(near, largest * (1.0 - params.separation_tolerance));
    for (const Layer& layer : reference.layers()) {
        plan.near_vertex.emplace_back(layer.points.size(), 0);
        plan.near_segment.emplace_back(layer.segment_count(), 0);
        for (std::size_t k = 0; k < layer.points.size(); ++k) {
            const Vec2& p = layer.points[k];
            const double dx = std::max({region.min.x - p.x, p.x - region.max.x, 0.0});
            const double dy = std::max({region.min.y - p.y, p.y - region.max.y, 0.0});
            plan.near_vertex.back()[k] = dx * dx + dy * dy <= plan.reach * plan.reach;
        }
        for (std::size_t s = 0; s < layer.segment_count(); ++s) {
            Box2 b;
            b.extend(layer.segment_start(s));
            b.extend(layer.segment_end(s));
            plan.near_segment.back()[s] = b.overlaps(region);
        }
    }
    st.report = Checker(reference, st.params).run(plan, st.away);
    st.counts = counts_of(st.report);
}

RegionCheck::~RegionCheck() = default;
RegionCheck::RegionCheck(RegionCheck&&) noexcept = default;
RegionCheck& RegionCheck::operator=(RegionCheck&&) noexcept = default;

const CheckReport& RegionCheck::reference_report() const {
    return state_->report;
}

std::size_t RegionCheck::whole_checks() const {
    return state_->whole_checks;
}

CheckCounts RegionCheck::check(const Scene& scene) const {
    State& st = *state_;
    const Scene& reference = *st.reference;
    if (scene.size() != reference.size())
        throw InvalidInput("RegionCheck::check: the scene has " + std::to_string(scene.size()) +
                           " layers, the reference " + std::to_string(reference.size()));
    for (std::size_t l = 0; l < scene.size(); ++l)
        if (scene.layer(l).points.size() != reference.layer(l).points.size() ||
            scene.layer(l).closed != reference.layer(l).closed)
            throw InvalidInput("RegionCheck::check: layer " + std::to_string(l) +
                               " differs from the reference's in vertex count or closedness");
    auto whole = [&] {
        ++st.whole_checks;
        return counts_of(check_scene(scene, st.params));
    };
    if (!st.is_enabled) return whole();
    // Every moved vertex, its neighbours and the segments between them (before and after)
    // inside the region, none of those segments of zero length (which would change which
    // segments are adjacent): else the whole scene is checked.
    const Box2& region = st.plan.box;
    bool moved_any = false;
    for (std::size_t l = 0; l < scene.size(); ++l) {
        const std::vector<Vec2>& now = scene.layer(l).points;
        const std::vector<Vec2>& then = reference.layer(l).points;
        const std::size_t n = now.size();
        const bool closed = scene.layer(l).closed;
        for (std::size_t v = 0; v < n; ++v) {
            if (now[v] == then[v]) continue;
            moved_any = true;
            if (n < 3) return whole();
            if (!region.contains(now[v]) || !region.contains(then[v])) return whole();
            const bool has_previous = closed || v > 0, has_next = closed || v + 1 < n;
            for (const std::size_t w : {(v + n - 1) % n, (v + 1) % n}) {
                if (w == (v + n - 1) % n ? !has_previous : !has_next) continue;
                if (!region.contains(now[w]) || !region.contains(then[w])) return whole();
                if (now[w] == now[v] || then[w] == then[v]) return whole();
            }
        }
    }
    if (!moved_any) return st.counts;
    if (st.params.near_distance == 0.0 && automatic_near(scene) != st.report.near_distance)
        return whole();
    return Checker(scene, st.params).run_region(st.plan, st.away);
}

}  // namespace strata
