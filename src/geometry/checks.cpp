#include "strata/geometry/checks.h"

#include "geometry/detail/parallel.h"
#include "geometry/detail/region_check.h"
#include "geometry/detail/segment_index.h"
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
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

namespace strata {

namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr double kInf = std::numeric_limits<double>::infinity();

using detail::automatic_near;
using detail::kSideReach;
using detail::median_of;
using detail::Nearest;
using detail::nearest_on;
using detail::parallel_for_each_index;
using detail::segment_grid;
using detail::SegmentIndex;
using detail::side_at;
using detail::side_of;

bool lex_less(const Vec2& a, const Vec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
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
        // The layers' indices side by side: a region check (RegionCheck::check()) builds them
        // for whole layers, at every check.
        indices_.resize(n_);
        bounds_.resize(n_);
        parallel_for_each_index(n_, [&](std::size_t i) {
            indices_[i] = SegmentIndex(scene.layer(i));
            bounds_[i] = scene.layer(i).bounds();
        });
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
                               shown_text(scene.layer(i).name) + "') must be +1 or -1 (got " +
                               std::to_string(params.outside_sides[i]) + ")");
}

}  // namespace

CheckReport check_scene(const Scene& scene, const CheckParams& params) {
    validate_outside_sides(scene, params);
    return Checker(scene, params).run();
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
    CheckCounts counts;                        // of `report`
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
