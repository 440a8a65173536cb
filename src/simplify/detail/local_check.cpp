#include "simplify/detail/local_check.h"

#include "strata/geometry/checks.h"
#include "strata/geometry/predicates.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace strata::detail {

namespace {

double segment_distance(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
    return std::min(
        std::min(point_segment_distance(p0, q0, q1), point_segment_distance(p1, q0, q1)),
        std::min(point_segment_distance(q0, p0, p1), point_segment_distance(q1, p0, p1)));
}

// The boxes are more than `d` apart along x or y, by a margin far above the rounding of the
// subtraction: then no point of one is within d of a point of the other.
bool apart_by_more(const Box2& a, const Box2& b, double d) {
    const double gap =
        std::max({a.min.x - b.max.x, b.min.x - a.max.x, a.min.y - b.max.y, b.min.y - a.max.y});
    const double scale =
        std::max({std::abs(a.min.x), std::abs(a.max.x), std::abs(a.min.y), std::abs(a.max.y),
                  std::abs(b.min.x), std::abs(b.max.x), std::abs(b.min.y), std::abs(b.max.y)});
    return gap > d + 1e-12 * scale;
}

}  // namespace

LocalCheck::LocalCheck(const Scene& input, const LivePolylines& live,
                       const Separations& separations, const std::vector<int>& outside_signs,
                       const InputSides& sides)
    : input_(input),
      live_(live),
      separations_(separations),
      outside_signs_(outside_signs),
      sides_(sides),
      reach_(automatic_near_distance(input)),
      open_under_over_(input.size(), 0),
      under_or_over_open_(input.size(), 0) {
    for (std::size_t k = 0; k < input.size(); ++k)
        for (std::size_t j = 0; j < input.size() && !input.layer(k).closed; ++j) {
            const Relation r = input.relation(j, k);
            if (j != k && (r == Relation::Under || r == Relation::Over)) {
                open_under_over_[k] = 1;
                under_or_over_open_[j] = 1;
                open_nesting_ = true;
            }
        }
}

// One query serves both tests: the box of the triangle and the chord's inflated by its
// reach (two queries, the triangle's and the chord's, read the same cells twice).
bool LocalCheck::removal_clear(std::size_t l, std::size_t a, const Vec2& removed, std::size_t b,
                               const Overlay& ov) const {
    if (!closed_valid(l, ov)) return false;
    const Chord chord = chord_of(l, a, b, ov);
    Triangle triangle{l, a, b, chord.p, removed, chord.q, chord.box};
    triangle.box.extend(removed);
    Box2 query = chord.box.inflated(separations_.reach[l]);
    query.extend(triangle.box);
    bool ok = true;
    if (!ov.job()) {  // live positions: what the checks read is in the grid's records
        live_.live_segments_near(query, [&](const LiveSegment& s) {
            ok = ok &&
                 triangle_clear_of(triangle, s.layer, s.start, s.end, s.end_is_last, s.p, s.q) &&
                 chord_clear_of(chord, s.layer, s.start, s.end, s.p, s.q);
        });
        return ok;
    }
    ov.near(query, [&](std::size_t k, std::size_t u) {
        ok = ok && clear_of_triangle(triangle, k, u, ov) && clear_of_chord(chord, k, u, ov);
    });
    return ok;
}

bool LocalCheck::segment_clear(std::size_t l, std::size_t a, std::size_t b,
                               const Overlay& ov) const {
    const Chord chord = chord_of(l, a, b, ov);
    bool ok = true;
    ov.near(chord.box.inflated(separations_.reach[l]),
            [&](std::size_t k, std::size_t u) { ok = ok && clear_of_chord(chord, k, u, ov); });
    return ok;
}

LocalCheck::Chord LocalCheck::chord_of(std::size_t l, std::size_t a, std::size_t b,
                                       const Overlay& ov) const {
    Chord c{l, a, b, ov.pos(l, a), ov.pos(l, b), Box2{}};
    c.box.extend(c.p);
    c.box.extend(c.q);
    return c;
}

bool LocalCheck::clear_of_chord(const Chord& c, std::size_t k, std::size_t u,
                                const Overlay& ov) const {
    const std::size_t u2 = live_.layer(k).next[u];
    if (k == c.l && (u == c.a || u == c.b || u2 == c.a || u2 == c.b)) return true;
    return chord_clear_of(c, k, u, u2, ov.pos(k, u), ov.pos(k, u2));
}

bool LocalCheck::chord_clear_of(const Chord& c, std::size_t k, std::size_t u, std::size_t u2,
                                const Vec2& s0, const Vec2& s1) const {
    if (k == c.l && (u == c.a || u == c.b || u2 == c.a || u2 == c.b)) return true;
    Box2 other;
    other.extend(s0);
    other.extend(s1);
    // Segments meet only where their boxes do (exact comparisons).
    if (other.overlaps(c.box) && segment_contact(c.p, c.q, s0, s1) != SegmentContact::None)
        return false;
    const double need = separations_.need[c.l][k];
    if (k == c.l || !(need > 0.0) || apart_by_more(c.box, other, need)) return true;
    return !(segment_distance(c.p, c.q, s0, s1) < need);
}

bool LocalCheck::closed_valid(std::size_t l, const Overlay& ov) const {
    const WorkLayer& w = live_.layer(l);
    if (!w.closed || w.alive_count > 3) return true;
    const std::size_t i = w.first(), j = w.next[i], k = w.next[j];
    return orient2d(ov.pos(l, i), ov.pos(l, j), ov.pos(l, k)) != 0;
}

// Whether w (of layer k) lies strictly on the side of segment (pa, pb) of layer l that the
// nesting asks for: inside l when k is under l, outside when over (false for side-by-side
// layers, where the side of an open layer is not said).
bool LocalCheck::on_wanted_side(std::size_t k, std::size_t l, const Vec2& pa, const Vec2& pb,
                                const Vec2& w) const {
    const Relation r = input_.relation(k, l);
    if (r != Relation::Under && r != Relation::Over) return false;
    const int outside = outside_signs_[l];  // +1: outside on the right
    const int wanted = r == Relation::Under ? outside : -outside;
    return orient2d(pa, pb, w) == wanted;
}

// No vertex of segment (k, u) but a, b lies in the closed triangle. Each vertex is tested
// once over a query that holds the triangle's box: as the start of its segment (which meets
// the box when the vertex is in it), the last one of an open layer as an end. Over a job
// (after its untangling), a vertex of another layer on its own side of the chord (a, b) is
// allowed there.
bool LocalCheck::clear_of_triangle(const Triangle& t, std::size_t k, std::size_t u,
                                   const Overlay& ov) const {
    const std::vector<std::size_t>& next = live_.layer(k).next;
    const std::size_t u2 = next[u];
    return triangle_clear_of(t, k, u, u2, next[u2] == kNone, ov.pos(k, u), ov.pos(k, u2), &ov);
}

bool LocalCheck::triangle_clear_of(const Triangle& t, std::size_t k, std::size_t u, std::size_t u2,
                                   bool u2_is_last, const Vec2& s0, const Vec2& s1,
                                   const Overlay* ov) const {
    for (const std::size_t x : {u, u2}) {
        if (x != u && !u2_is_last) continue;
        if (k == t.l && (x == t.a || x == t.b)) continue;
        const Vec2& w = x == u ? s0 : s1;
        if (point_in_closed_triangle(t.box, t.pa, t.removed, t.pb, w)) {
            // After an untangling the triangle is no longer swept: a vertex of another layer
            // may have moved into it from the side it belongs on.
            if (ov && ov->job() && k != t.l && on_wanted_side(k, t.l, t.pa, t.pb, w)) continue;
            return false;
        }
    }
    return true;
}

// The segments of closed layer k that the overlay's job changes, as (start, end) pairs: their
// old versions (live positions) in `olds`, their new ones (the overlay's) in `news`. Those
// are the segments next to the job's free vertices of k, and on the removal's own layer the
// chord (a, b), whose old version is (a, v) and (v, b).
void LocalCheck::changed_segments(std::size_t k, const Overlay& ov, std::vector<Vec2>& olds,
                                  std::vector<Vec2>& news) const {
    const Job& job = *ov.job();
    const WorkLayer& w = live_.layer(k);
    std::vector<std::size_t> starts;
    for (std::size_t r = 0; r < job.runs.size(); ++r) {
        if (job.runs[r].layer != k) continue;
        const std::vector<std::size_t>& ids = job.runs[r].ids;
        for (std::size_t i = 0; i < ids.size(); ++i) {
            if (!job.pieces[r].is_free[i]) continue;
            if (w.prev[ids[i]] != kNone) starts.push_back(w.prev[ids[i]]);
            if (w.next[ids[i]] != kNone) starts.push_back(ids[i]);
        }
    }
    if (k == job.l) starts.push_back(job.a);
    std::sort(starts.begin(), starts.end());
    starts.erase(std::unique(starts.begin(), starts.end()), starts.end());
    olds.clear();
    news.clear();
    for (std::size_t s : starts) {
        const std::size_t t = w.next[s];
        news.push_back(ov.pos(k, s));
        news.push_back(ov.pos(k, t));
        if (k == job.l && s == job.a) {
            olds.insert(olds.end(), {w.pos[s], job.removed, job.removed, w.pos[t]});
        } else {
            olds.insert(olds.end(), {w.pos[s], w.pos[t]});
        }
    }
}

// Moving vertices could carry a whole small loop out of another without any crossing left at
// the end. Tested locally and exactly, so that the cost does not grow with the layers: the
// change of the winding number of closed layer k around a vertex that moves from p0 to p1 is
// the change at p0 caused by the segments of k the job changed, plus the crossings of the
// path p0 -> p1 with k where it is now (winding_contribution(), winding_change_across()). Any
// change, or a path that touches k, fails. The live polylines are collision-free before the
// job, so an unchanged side is the right one.
bool LocalCheck::nesting_kept(std::size_t l, const std::vector<std::size_t>& ids,
                              const Overlay& ov) const {
    std::vector<Vec2> olds, news;
    for (std::size_t k = 0; k < live_.size(); ++k) {
        if (k == l || !live_.layer(k).closed) continue;
        changed_segments(k, ov, olds, news);
        for (std::size_t id : ids) {
            const Vec2 p0 = live_.layer(l).pos[id], p1 = ov.pos(l, id);
            int change = 0;
            for (std::size_t i = 0; i < news.size(); i += 2)
                change += winding_contribution(news[i], news[i + 1], p0);
            for (std::size_t i = 0; i < olds.size(); i += 2)
                change -= winding_contribution(olds[i], olds[i + 1], p0);
            if (p1 != p0) {
                Box2 path;
                path.extend(p0);
                path.extend(p1);
                bool touches = false;
                ov.near(path, [&](std::size_t j, std::size_t u) {
                    if (j != k || touches) return;
                    const std::optional<int> across = winding_change_across(
                        p0, p1, ov.pos(k, u), ov.pos(k, live_.layer(k).next[u]));
                    if (across) {
                        change += *across;
                    } else {
                        touches = true;
                    }
                });
                if (touches) return false;
            }
            if (change != 0) return false;
        }
    }
    return true;
}

// One box query for the whole job: every segment of an open layer within reach_ of one of the
// points tested is in it. The closest segment of a layer to a point is then the smallest
// (distance, index) among its segments closer than reach_, as check_scene() finds it; boxes
// growing from the largest separation, one query per size and per point, found the same
// segments (measured: 3.1 queries per point at 8 x 10k, 98%, 10% of the process).
void LocalCheck::segments_near(const Box2& box, const Overlay& ov,
                               std::vector<std::vector<NearSegment>>& near) const {
    near.assign(live_.size(), {});
    ov.near(box, [&](std::size_t k, std::size_t u) {
        if (live_.layer(k).closed || !open_under_over_[k]) return;
        const Vec2 a = ov.pos(k, u), b = ov.pos(k, live_.layer(k).next[u]);
        if (a == b) return;  // zero length: its point is an end of its neighbours
        NearSegment s{u, a, b, Box2{}};
        s.box.extend(a);
        s.box.extend(b);
        near[k].push_back(s);
    });
}

LocalCheck::Closest LocalCheck::closest_of(const Vec2& p,
                                           const std::vector<NearSegment>& segments) const {
    Box2 box;
    box.extend(p);
    const Box2 reach = box.inflated(reach_);
    Closest c;
    c.best = reach_;
    for (const NearSegment& s : segments) {
        if (!s.box.overlaps(reach)) continue;
        Vec2 q;
        const double d = point_segment_distance(p, s.a, s.b, &q);
        // check_scene(): the segment of smallest index among equally close ones (input ids
        // run in layer order on an open layer).
        if (d < c.best || (d == c.best && c.seg != kNone && s.start < c.seg)) {
            c.best = d;
            c.seg = s.start;
            c.point = q;
        }
    }
    return c;
}

int LocalCheck::side_of_closest(std::size_t k, const Vec2& p, const Closest& c,
                                const Overlay& ov) const {
    if (c.seg == kNone || c.best == 0.0) return 0;
    const WorkLayer& w = live_.layer(k);
    const std::size_t e = w.next[c.seg];
    const Vec2 a = ov.pos(k, c.seg), b = ov.pos(k, e);
    if (c.point == a) {
        if (w.prev[c.seg] == kNone) return 0;  // an end of the open layer
        return corner_side(ov.pos(k, w.prev[c.seg]), a, b, p);
    }
    if (c.point == b) {
        if (w.next[e] == kNone) return 0;
        return corner_side(a, b, ov.pos(k, w.next[e]), p);
    }
    return segment_side(a, b, p);
}

bool LocalCheck::keeps_sides(std::size_t j, std::size_t x, const Overlay& ov,
                             const std::vector<std::vector<NearSegment>>& near) const {
    const Vec2 p = ov.pos(j, x);
    for (std::size_t k = 0; k < live_.size(); ++k) {
        if (k == j || live_.layer(k).closed) continue;
        const Relation r = input_.relation(j, k);
        if (r != Relation::Under && r != Relation::Over) continue;
        int wanted = sides_.side(j, x, k);
        if (wanted == 0) wanted = global_side(r, outside_signs_[k]);
        const int side = side_of_closest(k, p, closest_of(p, near[k]), ov);
        if (side != 0 && side != wanted) return false;
    }
    return true;
}

bool LocalCheck::sides_kept(const Overlay& ov) const {
    if (!open_nesting_) return true;
    const Job& job = *ov.job();
    // The points tested: the free vertices, and the ends of the open layers near the job,
    // moved or not: at a high removal a rolled part is often down to the end of its layer,
    // whose side changes when the layer it lies over is moved under it (the one unmoved case
    // tested here; see the header).
    std::vector<SegRef> points;
    Box2 box;
    for (std::size_t r = 0; r < job.runs.size(); ++r) {
        const Run& run = job.runs[r];
        for (std::size_t i = 0; i < run.ids.size(); ++i)
            if (job.pieces[r].is_free[i] && under_or_over_open_[run.layer]) {
                points.push_back(LivePolylines::ref(run.layer, run.ids[i]));
                box.extend(ov.pos(run.layer, run.ids[i]));
            }
    }
    const Box2 span = span_of(job).inflated(reach_);
    for (std::size_t j = 0; j < live_.size(); ++j) {
        const WorkLayer& w = live_.layer(j);
        if (w.closed || w.pos.empty()) continue;
        for (const std::size_t end : {std::size_t{0}, w.pos.size() - 1})
            if (under_or_over_open_[j] && span.contains(ov.pos(j, end))) {
                points.push_back(LivePolylines::ref(j, end));
                box.extend(ov.pos(j, end));
            }
    }
    if (points.empty()) return true;
    std::vector<std::vector<NearSegment>> near;
    segments_near(box.inflated(reach_), ov, near);
    for (const SegRef& x : points)
        if (!keeps_sides(x.layer, x.start, ov, near)) return false;
    return true;
}

}  // namespace strata::detail
