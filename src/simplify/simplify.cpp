#include "strata/simplify/simplify.h"

#include "simplify/detail/segment_grid.h"
#include "simplify/detail/work_layer.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_gaps.h"
#include "strata/geometry/predicates.h"
#include "strata/simplify/decimator.h"
#include "untangle/detail/engine.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <queue>
#include <unordered_map>
#include <utility>

namespace strata {

namespace {

using Clock = std::chrono::steady_clock;
using detail::kNone;
using detail::SegmentGrid;
using detail::SegRef;
using detail::WorkLayer;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Candidate {
    double cost;
    std::uint32_t layer, vertex, version;
    bool operator>(const Candidate& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (layer != o.layer) return layer > o.layer;
        return vertex > o.vertex;
    }
};

bool point_in_closed_triangle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& p) {
    const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

double segment_distance(const Vec2& p0, const Vec2& p1, const Vec2& q0, const Vec2& q1) {
    return std::min(
        std::min(point_segment_distance(p0, q0, q1), point_segment_distance(p1, q0, q1)),
        std::min(point_segment_distance(q0, p0, p1), point_segment_distance(q1, p0, p1)));
}

class Driver {
  public:
    Driver(const Scene& scene, const SimplifyParams& params)
        : input_(scene),
          params_(params),
          decimator_(make_decimator(params.decimator, params.seed)),
          grid_(1.0) {
        const std::size_t n = scene.size();
        layers_.resize(n);
        std::vector<double> lengths;
        for (std::size_t l = 0; l < n; ++l) {
            const Layer& in = scene.layer(l);
            WorkLayer& w = layers_[l];
            const std::size_t m = in.points.size();
            w.closed = in.closed;
            w.original = w.pos = in.points;
            w.prev.resize(m);
            w.next.resize(m);
            for (std::size_t i = 0; i < m; ++i) {
                w.prev[i] = i > 0 ? i - 1 : (in.closed ? m - 1 : kNone);
                w.next[i] = i + 1 < m ? i + 1 : (in.closed ? 0 : kNone);
            }
            w.alive.assign(m, 1);
            w.locked.assign(m, 0);
            w.alive_count = m;
            const std::size_t floor_count = in.closed ? 3 : 2;
            std::size_t target = params.keep > 0 ? params.keep
                                                 : m - static_cast<std::size_t>(std::floor(
                                                           params.remove * static_cast<double>(m)));
            w.target = std::max(std::min(target, m), floor_count);
            for (std::size_t i = 0; i < in.segment_count(); ++i)
                lengths.push_back(glm::distance(in.segment_start(i), in.segment_end(i)));
        }
        std::nth_element(lengths.begin(),
                         lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2),
                         lengths.end());
        const double median = lengths.empty() ? 1.0 : lengths[lengths.size() / 2];
        std::size_t segments = 0;
        for (std::size_t l = 0; l < n; ++l) segments += scene.layer(l).segment_count();
        grid_ = SegmentGrid(std::max(4.0 * median, std::numeric_limits<double>::min()),
                            scene.bounds(), segments);
        for (std::size_t l = 0; l < n; ++l)
            for (std::size_t i = 0; i < layers_[l].alive.size(); ++i)
                if (has_segment(l, i)) grid_.insert(ref(l, i), seg_box(l, i));

        // Separation each layer needs from every other, with the tolerance applied.
        need_.assign(n, std::vector<double>(n, 0.0));
        reach_.assign(n, 0.0);
        nest_thickness_.assign(n, 0.0);
        for (std::size_t a = 0; a < n; ++a)
            for (std::size_t b = 0; b < n; ++b) {
                if (a == b) continue;
                need_[a][b] = scene.required_separation(a, b) *
                              (1.0 - params.untangling.separation_tolerance);
                reach_[a] = std::max(reach_[a], need_[a][b]);
                if (scene.relation(a, b) != Relation::SideBySide)
                    nest_thickness_[a] += scene.layer(b).thickness;
            }
        for (std::size_t a = 0; a < n; ++a) nest_thickness_[a] += scene.layer(a).thickness;
        stamp_.resize(n);
        for (std::size_t l = 0; l < n; ++l) stamp_[l].assign(layers_[l].alive.size(), 0);
        mark_ = stamp_;
        slot_run_ = stamp_;
        slot_index_ = stamp_;
        for (double r : reach_) max_reach_ = std::max(max_reach_, r);
        version_.resize(n);
        for (std::size_t l = 0; l < n; ++l) version_[l].assign(layers_[l].alive.size(), 0);
        if (params.untangle) settings_ = detail::resolve_settings(scene, params.untangling);
        report_.layers.resize(n);
    }

    SimplifyReport run(const ProgressFn& progress) {
        const auto start_all = Clock::now();
        std::size_t to_remove = 0;
        for (const WorkLayer& w : layers_) to_remove += w.alive_count - w.target;
        for (std::size_t l = 0; l < layers_.size(); ++l)
            for (std::size_t v = 0; v < layers_[l].alive.size(); ++v) push(l, v);
        std::size_t last_reported = 0;
        // Deferred schedule: a first sweep removes what needs no untangling; a second one
        // untangles, over the layers still above their target only.
        defer_ = params_.untangle && params_.schedule == UntangleSchedule::Deferred;
        for (int sweep = 0; sweep < (defer_ ? 2 : 1); ++sweep) {
            if (sweep == 1) {
                defer_ = false;
                for (std::size_t l = 0; l < layers_.size(); ++l)
                    if (layers_[l].alive_count > layers_[l].target)
                        for (std::size_t v = 0; v < layers_[l].alive.size(); ++v) push(l, v);
            }
            for (;;) {
                if (queue_.empty()) {
                    flush();  // its commits may bring new candidates
                    if (queue_.empty()) break;
                }
                const Candidate c = queue_.top();
                queue_.pop();
                const std::size_t l = c.layer, v = c.vertex;
                WorkLayer& w = layers_[l];
                if (c.version != version_[l][v] || !removable(l, v) || w.alive_count <= w.target)
                    continue;
                const std::size_t a = w.prev[v], b = w.next[v];
                if (params_.max_error > 0.0 && span_error(view(l), a, b) > params_.max_error) {
                    w.locked[v] = 1;
                    continue;
                }
                if (batching())
                    remove_batched(c);
                else
                    count(try_remove(l, v), l, v);
                if (progress && (done_ - last_reported) * 100 >= to_remove) {
                    last_reported = done_;
                    if (!progress("simplify", to_remove ? static_cast<double>(done_) /
                                                              static_cast<double>(to_remove)
                                                        : 1.0))
                        throw Cancelled();
                }
            }
        }
        if (progress && !progress("simplify", 1.0)) throw Cancelled();
        report_.seconds_total = seconds_since(start_all);
        return report_;
    }

    Scene result() const {
        std::vector<Layer> layers = input_.layers();
        for (std::size_t l = 0; l < layers.size(); ++l) {
            const WorkLayer& w = layers_[l];
            std::vector<Vec2> points;
            const std::size_t start = w.first();
            std::size_t i = start;
            do {
                points.push_back(w.pos[i]);
                i = w.next[i];
            } while (i != kNone && i != start);
            layers[l].points = std::move(points);
        }
        Scene out(std::move(layers), input_.units());
        out.metadata = input_.metadata;
        return out;
    }

    SimplifyReport& report() { return report_; }
    /// outside_side() of every input layer (already resolved for the untangling, if any).
    std::vector<int> outside_sides() const {
        if (!settings_.outside_signs.empty()) return settings_.outside_signs;
        std::vector<int> sides;
        for (std::size_t l = 0; l < input_.size(); ++l) sides.push_back(outside_side(input_, l));
        return sides;
    }
    std::size_t target(std::size_t l) const { return layers_[l].target; }
    /// Largest distance of a kept vertex of layer l from its input position.
    double max_displacement(std::size_t l) const {
        const WorkLayer& w = layers_[l];
        double d = 0.0;
        for (std::size_t i = 0; i < w.alive.size(); ++i)
            if (w.alive[i]) d = std::max(d, glm::distance(w.pos[i], w.original[i]));
        return d;
    }

  private:
    static SegRef ref(std::size_t l, std::size_t i) {
        return {static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(i)};
    }
    bool has_segment(std::size_t l, std::size_t i) const {
        return layers_[l].alive[i] && layers_[l].next[i] != kNone;
    }
    Box2 seg_box(std::size_t l, std::size_t i) const {
        Box2 box;
        box.extend(layers_[l].pos[i]);
        box.extend(layers_[l].pos[layers_[l].next[i]]);
        return box;
    }
    DecimationView view(std::size_t l) const {
        return DecimationView{layers_[l].original, layers_[l].pos, layers_[l].closed};
    }
    bool removable(std::size_t l, std::size_t v) const {
        const WorkLayer& w = layers_[l];
        if (!w.alive[v] || w.locked[v]) return false;
        if (!w.closed && (w.prev[v] == kNone || w.next[v] == kNone)) return false;  // ends stay
        return w.alive_count > (w.closed ? 3 : 2);
    }
    void push(std::size_t l, std::size_t v) {
        if (!removable(l, v)) return;
        const WorkLayer& w = layers_[l];
        const auto start = Clock::now();
        const double cost = decimator_->cost(l, view(l), w.prev[v], v, w.next[v]);
        report_.seconds_decimate += seconds_since(start);
        queue_.push(
            {cost, static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(v), ++version_[l][v]});
    }

    // Calls f(layer, start) once per segment whose box meets `box` (driver's positions).
    template <class F>
    void segments_near(const Box2& box, F&& f) {
        ++stamp_counter_;
        grid_.query(box, [&](SegRef s) {
            std::uint32_t& mark = stamp_[s.layer][s.start];
            if (mark == stamp_counter_) return;
            mark = stamp_counter_;
            f(static_cast<std::size_t>(s.layer), static_cast<std::size_t>(s.start));
        });
    }

    // A run of alive vertices of one layer, in order, standing for one work layer.
    struct Run {
        std::size_t layer = 0;
        std::vector<std::size_t> ids;
        bool whole_loop = false;
    };

    // One local untangling: prepared from the driver's state, run without writing to it (so
    // that untanglings whose footprints keep apart run side by side), then committed.
    struct Job {
        std::size_t l = 0, a = 0, v = 0, b = 0;  // removal of v between a and b, layer l
        Vec2 removed{};
        std::uint32_t stamp = 0;  // mark_ value of the runs' vertices
        std::vector<Run> runs;
        std::vector<Piece> pieces;
        std::vector<SegRef> moving;  // segments with a free end
        std::optional<Scene> work;
        detail::RelationSource relations;
        detail::EngineSettings settings;
        Box2 footprint;  // the runs' vertices before, and the removed one
        detail::EngineResult result;
        double seconds_prepare = 0.0;
    };

    // Where the checks read positions: the driver's, or over a job's runs its work scene.
    struct Overlay {
        const Job* job = nullptr;
        const Scene* work = nullptr;
        const SegmentGrid* moving = nullptr;   // the job's moving segments where they are now
        std::vector<SegRef>* found = nullptr;  // the job's scratch for near()
    };

    Vec2 pos(std::size_t k, std::size_t x, const Overlay& ov) const {
        if (ov.job && mark_[k][x] == ov.job->stamp)
            return ov.work->layer(slot_run_[k][x]).points[slot_index_[k][x]];
        return layers_[k].pos[x];
    }
    bool is_free(std::size_t k, std::size_t x, const Job& job) const {
        return x != kNone && mark_[k][x] == job.stamp &&
               job.pieces[slot_run_[k][x]].is_free[slot_index_[k][x]];
    }

    // Calls f(layer, start) once per segment whose box meets `box`, at the overlay's
    // positions. With a job, writes nothing the driver shares (jobs run side by side).
    template <class F>
    void near(const Box2& box, const Overlay& ov, F&& f) {
        if (!ov.job) {
            segments_near(box, f);
            return;
        }
        std::vector<SegRef>& found = *ov.found;
        found.clear();
        grid_.query(box, [&](SegRef s) {  // the grid holds the moving ones where they were
            if (!is_free(s.layer, s.start, *ov.job) &&
                !is_free(s.layer, layers_[s.layer].next[s.start], *ov.job))
                found.push_back(s);
        });
        ov.moving->query(box, [&](SegRef s) { found.push_back(s); });
        auto key = [](const SegRef& s) {
            return (static_cast<std::uint64_t>(s.layer) << 32) | s.start;
        };
        std::sort(found.begin(), found.end(),
                  [&](const SegRef& x, const SegRef& y) { return key(x) < key(y); });
        found.erase(std::unique(found.begin(), found.end(),
                                [&](const SegRef& x, const SegRef& y) { return key(x) == key(y); }),
                    found.end());
        for (const SegRef& s : found)
            f(static_cast<std::size_t>(s.layer), static_cast<std::size_t>(s.start));
    }

    // Segment (a, b) of layer l meets no other segment and keeps its separations.
    bool segment_clear(std::size_t l, std::size_t a, std::size_t b, const Overlay& ov) {
        const Vec2 p = pos(l, a, ov), q = pos(l, b, ov);
        Box2 box;
        box.extend(p);
        box.extend(q);
        bool ok = true;
        near(box.inflated(reach_[l]), ov, [&](std::size_t k, std::size_t u) {
            if (!ok) return;
            const std::size_t u2 = layers_[k].next[u];
            if (k == l && (u == a || u == b || u2 == a || u2 == b)) return;
            const Vec2 s0 = pos(k, u, ov), s1 = pos(k, u2, ov);
            if (segment_contact(p, q, s0, s1) != SegmentContact::None) {
                ok = false;
                return;
            }
            if (k != l && need_[l][k] > 0.0 && segment_distance(p, q, s0, s1) < need_[l][k])
                ok = false;
        });
        return ok;
    }

    // Whether w (of layer k) lies strictly on the side of segment (pa, pb) of layer l that
    // the nesting asks for: inside l when k is under l, outside when over (false for
    // side-by-side layers, where the side of an open layer is not said).
    bool on_wanted_side(std::size_t k, std::size_t l, const Vec2& pa, const Vec2& pb,
                        const Vec2& w) const {
        const Relation r = input_.relation(k, l);
        if (r != Relation::Under && r != Relation::Over) return false;
        const int outside = settings_.outside_signs[l];  // +1: outside on the right
        const int wanted = r == Relation::Under ? outside : -outside;
        return orient2d(pa, pb, w) == wanted;
    }

    // No vertex but a, b of any layer lies in the closed triangle (a, removed, b). With a
    // job (after its untangling), a vertex of another layer on its own side of the chord
    // (a, b) is allowed there.
    bool triangle_empty(std::size_t l, std::size_t a, const Vec2& removed, std::size_t b,
                        const Overlay& ov) {
        const Vec2 pa = pos(l, a, ov), pb = pos(l, b, ov);
        Box2 box;
        box.extend(pa);
        box.extend(pb);
        box.extend(removed);
        bool ok = true;
        near(box, ov, [&](std::size_t k, std::size_t u) {
            if (!ok) return;
            for (std::size_t x : {u, layers_[k].next[u]}) {
                if (k == l && (x == a || x == b)) continue;
                if (point_in_closed_triangle(pa, removed, pb, pos(k, x, ov))) {
                    // After an untangling the triangle is no longer swept: a vertex of
                    // another layer may have moved into it from the side it belongs on.
                    if (ov.job && k != l && on_wanted_side(k, l, pa, pb, pos(k, x, ov))) continue;
                    ok = false;
                    return;
                }
            }
        });
        return ok;
    }

    // The segments of closed layer k that the job changes, as (start, end) pairs: their old
    // versions (driver's positions) in `olds`, their new ones (the overlay's) in `news`. Those
    // are the segments next to the job's free vertices of k, and on the removal's own layer
    // the chord (a, b), whose old version is (a, v) and (v, b).
    void changed_segments(std::size_t k, const Overlay& ov, std::vector<Vec2>& olds,
                          std::vector<Vec2>& news) const {
        const Job& job = *ov.job;
        const WorkLayer& w = layers_[k];
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
            news.push_back(pos(k, s, ov));
            news.push_back(pos(k, t, ov));
            if (k == job.l && s == job.a) {
                olds.insert(olds.end(), {w.pos[s], job.removed, job.removed, w.pos[t]});
            } else {
                olds.insert(olds.end(), {w.pos[s], w.pos[t]});
            }
        }
    }

    // Every vertex of `ids` (layer l) stays on its side of every closed layer: moving
    // vertices could carry a whole small loop out of another without any crossing left at
    // the end. Tested locally and exactly, so that the cost does not grow with the layers:
    // the change of the winding number of closed layer k around a vertex that moves from p0
    // to p1 is the change at p0 caused by the segments of k the job changed, plus the
    // crossings of the path p0 -> p1 with k where it is now (winding_contribution(),
    // winding_change_across()). Any change, or a path that touches k, fails. The driver's
    // state before the job is collision-free, so an unchanged side is the right one.
    bool nesting_kept(std::size_t l, const std::vector<std::size_t>& ids, const Overlay& ov) {
        std::vector<Vec2> olds, news;
        for (std::size_t k = 0; k < layers_.size(); ++k) {
            if (k == l || !layers_[k].closed) continue;
            changed_segments(k, ov, olds, news);
            for (std::size_t id : ids) {
                const Vec2 p0 = layers_[l].pos[id], p1 = pos(l, id, ov);
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
                    near(path, ov, [&](std::size_t j, std::size_t u) {
                        if (j != k || touches) return;
                        const std::optional<int> across = winding_change_across(
                            p0, p1, pos(k, u, ov), pos(k, layers_[k].next[u], ov));
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

    bool closed_valid(std::size_t l, const Overlay& ov) const {
        const WorkLayer& w = layers_[l];
        if (!w.closed || w.alive_count > 3) return true;
        const std::size_t i = w.first(), j = w.next[i], k = w.next[j];
        return orient2d(pos(l, i, ov), pos(l, j, ov), pos(l, k, ov)) != 0;
    }

    void unlink(std::size_t l, std::size_t v) {
        WorkLayer& w = layers_[l];
        const std::size_t a = w.prev[v], b = w.next[v];
        grid_.erase(ref(l, a), seg_box(l, a));
        grid_.erase(ref(l, v), seg_box(l, v));
        w.alive[v] = 0;
        w.next[a] = b;
        w.prev[b] = a;
        --w.alive_count;
        grid_.insert(ref(l, a), seg_box(l, a));
    }

    void relink(std::size_t l, std::size_t v) {
        WorkLayer& w = layers_[l];
        const std::size_t a = w.prev[v], b = w.next[v];
        grid_.erase(ref(l, a), seg_box(l, a));
        w.alive[v] = 1;
        w.next[a] = v;
        w.prev[b] = v;
        ++w.alive_count;
        grid_.insert(ref(l, a), seg_box(l, a));
        grid_.insert(ref(l, v), seg_box(l, v));
    }

    // Moves vertex v of layer l, keeping the grid in step.
    void move(std::size_t l, std::size_t v, const Vec2& to) {
        WorkLayer& w = layers_[l];
        if (w.pos[v] == to) return;
        const std::size_t a = w.prev[v];
        if (a != kNone) grid_.erase(ref(l, a), seg_box(l, a));
        if (w.next[v] != kNone) grid_.erase(ref(l, v), seg_box(l, v));
        w.pos[v] = to;
        if (a != kNone) grid_.insert(ref(l, a), seg_box(l, a));
        if (w.next[v] != kNone) grid_.insert(ref(l, v), seg_box(l, v));
    }

    enum class Outcome { Removed, Deferred, Refused };

    void count(Outcome outcome, std::size_t l, std::size_t v) {
        switch (outcome) {
            case Outcome::Removed:
                ++report_.removed;
                ++done_;
                break;
            case Outcome::Deferred:
                ++report_.deferred;
                break;
            case Outcome::Refused:
                layers_[l].locked[v] = 1;
                ++report_.refused;
                ++report_.layers[l].refused;
                break;
        }
    }

    // The exact local test of removing the vertex at `removed` between a and b (unlinked):
    // layer l stays valid, the closed triangle (a, removed, b) holds no other vertex, and the
    // chord (a, b) meets nothing and keeps its separations.
    bool removal_clear(std::size_t l, std::size_t a, const Vec2& removed, std::size_t b,
                       const Overlay& ov) {
        return closed_valid(l, ov) && triangle_empty(l, a, removed, b, ov) &&
               segment_clear(l, a, b, ov);
    }

    // Unlinks v; true when that alone keeps its region collision-free.
    bool remove_if_clear(std::size_t l, std::size_t v) {
        WorkLayer& w = layers_[l];
        const std::size_t a = w.prev[v], b = w.next[v];
        const Vec2 removed = w.pos[v];
        const auto start = Clock::now();
        unlink(l, v);
        const bool clear = !params_.untangle || removal_clear(l, a, removed, b, Overlay{});
        report_.seconds_check += seconds_since(start);
        if (clear) {
            push(l, a);
            push(l, b);
        }
        return clear;
    }

    // One removal at a time (no batch): the paper's order.
    Outcome try_remove(std::size_t l, std::size_t v) {
        if (remove_if_clear(l, v)) return Outcome::Removed;
        if (!defer_ && untangle_now(l, v)) return Outcome::Removed;
        relink(l, v);
        return defer_ ? Outcome::Deferred : Outcome::Refused;
    }

    // Marks vertex v of layer k for the job being prepared (stamp style, no clearing); a
    // vertex of a job waiting in the batch is left alone and flags a conflict.
    void mark(std::size_t k, std::size_t v, std::vector<std::size_t>& marked) {
        const std::uint32_t m = mark_[k][v];
        if (m == mark_counter_) return;
        if (m != 0 && is_pending_stamp(m)) {
            conflict_ = true;
            return;
        }
        mark_[k][v] = mark_counter_;
        marked.push_back(v);
    }
    bool is_marked(std::size_t k, std::size_t v) const {
        return v != kNone && mark_[k][v] == mark_counter_;
    }
    bool is_pending_stamp(std::uint32_t m) const {
        for (const Job& job : pending_)
            if (job.stamp == m) return true;
        return false;
    }

    // Runs of layer k through its `marked` vertices, extended by n_out on both sides, in the
    // order of their first input id. Costs O(marked * n_out), whatever the layer's size.
    void runs_of(std::size_t k, std::vector<std::size_t>& marked, std::vector<Run>& out) {
        const WorkLayer& w = layers_[k];
        const std::size_t seeds = marked.size();
        for (std::size_t s = 0; s < seeds; ++s) {
            std::size_t i = marked[s], j = marked[s];
            for (std::size_t c = 0; c < params_.n_out; ++c) {
                if (w.prev[i] != kNone) i = w.prev[i];
                if (w.next[j] != kNone) j = w.next[j];
                mark(k, i, marked);
                mark(k, j, marked);
            }
        }
        if (w.closed && marked.size() >= w.alive_count) {  // every vertex: the whole loop
            Run run{k, {}, true};
            const std::size_t start = *std::min_element(marked.begin(), marked.end());
            std::size_t x = start;
            do {
                run.ids.push_back(x);
                x = w.next[x];
            } while (x != start);
            out.push_back(std::move(run));
            return;
        }
        std::vector<std::size_t> starts;
        for (std::size_t v : marked)
            if (!is_marked(k, w.prev[v])) starts.push_back(v);
        std::sort(starts.begin(), starts.end());
        for (std::size_t v : starts) {
            Run run{k, {}, false};
            for (std::size_t x = v; is_marked(k, x); x = w.next[x]) run.ids.push_back(x);
            out.push_back(std::move(run));
        }
    }

    bool meets_pending(const Box2& box) const {
        for (const Job& job : pending_)
            if (job.footprint.overlaps(box)) return true;
        return false;
    }

    enum class Prepared { Ready, Conflict, Refused };

    // The work scene of the untangling after removing job.v (already unlinked): runs of every
    // layer through the segments near the removal, their vertices in the region free.
    // Conflict: it would share vertices or come within reach of a job waiting in the batch.
    Prepared prepare(Job& job) {
        const auto start = Clock::now();
        const WorkLayer& w = layers_[job.l];
        Box2 box;
        box.extend(w.pos[job.a]);
        box.extend(w.pos[job.b]);
        box.extend(job.removed);
        const double chord = glm::distance(w.pos[job.a], w.pos[job.b]);
        const Box2 region = box.inflated(std::max(2.0 * nest_thickness_[job.l], 0.5 * chord));
        const Box2 around = region.inflated(std::max(2.0 * nest_thickness_[job.l], chord));
        // Work layers: runs through the vertices of the segments near the region.
        std::vector<std::vector<std::size_t>> marked(layers_.size());
        job.stamp = ++mark_counter_;
        conflict_ = false;
        if (params_.global) {
            for (std::size_t k = 0; k < layers_.size(); ++k)
                for (std::size_t v = 0; v < layers_[k].alive.size(); ++v)
                    if (layers_[k].alive[v]) mark(k, v, marked[k]);
        } else {
            segments_near(around, [&](std::size_t k, std::size_t u) {
                mark(k, u, marked[k]);
                mark(k, layers_[k].next[u], marked[k]);
            });
        }
        job.runs.clear();
        for (std::size_t k = 0; k < layers_.size() && !conflict_; ++k)
            if (!marked[k].empty()) runs_of(k, marked[k], job.runs);
        if (conflict_) return Prepared::Conflict;
        job.footprint = Box2{};
        job.footprint.extend(job.removed);
        for (const Run& run : job.runs)
            for (std::size_t id : run.ids) job.footprint.extend(layers_[run.layer].pos[id]);
        if (meets_pending(job.footprint.inflated(max_reach_))) return Prepared::Conflict;

        std::vector<Layer> work_layers;
        job.pieces.clear();
        job.relations = detail::RelationSource{};
        job.relations.scene = &input_;
        job.settings = settings_;
        job.settings.outside_signs.clear();
        job.settings.check_every_step = !params_.global;
        job.settings.rest_at_start = true;  // passes of one round: match toward the start
        for (std::size_t r = 0; r < job.runs.size(); ++r) {
            const Run& run = job.runs[r];
            const Layer& parent = input_.layer(run.layer);
            const WorkLayer& parent_work = layers_[run.layer];
            Layer layer;
            layer.name = parent.name + "#" + std::to_string(r);
            layer.closed = run.whole_loop;
            layer.thickness = parent.thickness;
            layer.weight = parent.weight;
            layer.alpha = parent.alpha;
            layer.beta = parent.beta;
            Piece piece;
            piece.layer = r;
            piece.is_whole_loop = run.whole_loop;
            for (std::size_t k = 0; k < run.ids.size(); ++k) {
                const std::size_t id = run.ids[k];
                const Vec2 p = parent_work.pos[id];
                if (!layer.points.empty() && layer.points.back() == p)
                    return Prepared::Refused;  // would be merged
                layer.points.push_back(p);
                piece.vertices.push_back(k);
                // Open layers keep their end vertices where they are.
                const bool is_end = !parent_work.closed && (parent_work.prev[id] == kNone ||
                                                            parent_work.next[id] == kNone);
                piece.is_free.push_back(!is_end && (params_.global || region.contains(p)) ? 1 : 0);
                slot_run_[run.layer][id] = static_cast<std::uint32_t>(r);
                slot_index_[run.layer][id] = static_cast<std::uint32_t>(k);
            }
            if (layer.closed && layer.points.front() == layer.points.back())
                return Prepared::Refused;
            work_layers.push_back(std::move(layer));
            job.pieces.push_back(std::move(piece));
            job.relations.parent.push_back(run.layer);
            job.settings.outside_signs.push_back(settings_.outside_signs[run.layer]);
        }
        job.work.emplace(std::move(work_layers));
        job.moving.clear();
        for (const Run& run : job.runs) {
            const WorkLayer& o = layers_[run.layer];
            for (std::size_t id : run.ids)
                if (o.next[id] != kNone &&
                    (is_free(run.layer, id, job) || is_free(run.layer, o.next[id], job)))
                    job.moving.push_back(ref(run.layer, id));
        }
        job.seconds_prepare = seconds_since(start);
        return Prepared::Ready;
    }

    // Runs the job's untangling, checking its region exactly after every projection step.
    // Reads the driver's state and writes only to `job`: jobs of one batch run side by side.
    void execute(Job& job) {
        SegmentGrid moving(grid_.cell());
        std::vector<SegRef> found;
        auto is_ok = [&](const Scene& s) {
            const Overlay ov{&job, &s, &moving, &found};
            moving.clear();
            for (const SegRef& seg : job.moving) {
                Box2 box;
                box.extend(pos(seg.layer, seg.start, ov));
                box.extend(pos(seg.layer, layers_[seg.layer].next[seg.start], ov));
                moving.insert(seg, box);
            }
            if (!removal_clear(job.l, job.a, job.removed, job.b, ov)) return false;
            for (std::size_t r = 0; r < job.runs.size(); ++r) {
                const Run& run = job.runs[r];
                const WorkLayer& o = layers_[run.layer];
                for (std::size_t k = 0; k < run.ids.size(); ++k) {
                    if (!job.pieces[r].is_free[k]) continue;
                    const std::size_t id = run.ids[k];
                    if (o.prev[id] != kNone && !segment_clear(run.layer, o.prev[id], id, ov))
                        return false;
                    if (o.next[id] != kNone && !segment_clear(run.layer, id, o.next[id], ov))
                        return false;
                }
                if (!closed_valid(run.layer, ov)) return false;
            }
            // Nesting of the region's vertices against every closed layer near it.
            for (const Run& run : job.runs)
                if (!nesting_kept(run.layer, run.ids, ov)) return false;
            return true;
        };
        job.result = detail::run_engine(*job.work, job.pieces, params_.untangling, job.relations,
                                        job.settings, is_ok, {});
    }

    // The box of the job's vertices before and after, and of the removed vertex.
    Box2 span_of(const Job& job) const {
        Box2 box = job.footprint;
        for (std::size_t r = 0; r < job.runs.size(); ++r)
            for (const Vec2& p : job.work->layer(r).points) box.extend(p);
        return box;
    }

    // One untangling of a removal on layer l, in the report.
    void count_call(std::size_t l) {
        ++report_.untangle_calls;
        ++report_.layers[l].untangled;
    }

    // The removal of v (unlinked) is kept, or rolled back and its vertex locked.
    void conclude(std::size_t l, std::size_t v, bool kept) {
        if (kept) {
            count(Outcome::Removed, l, v);
            return;
        }
        relink(l, v);
        count(Outcome::Refused, l, v);
    }

    // Applies a successful job's moves; true if it succeeded.
    bool commit(const Job& job) {
        count_call(job.l);
        report_.rounds += job.result.rounds;
        report_.seconds_check += job.seconds_prepare;
        report_.seconds_fields += job.result.seconds_fields;
        report_.seconds_untangle += job.result.seconds_untangle;
        report_.seconds_finish += job.result.seconds_finish;
        report_.seconds_check += job.result.seconds_check;
        if (job.result.gave_up) ++report_.gave_up;
        if (!job.result.ok) return false;
        for (std::size_t r = 0; r < job.runs.size(); ++r) {
            const Run& run = job.runs[r];
            for (std::size_t k = 0; k < run.ids.size(); ++k)
                if (job.pieces[r].is_free[k])
                    move(run.layer, run.ids[k], job.work->layer(r).points[k]);
        }
        // New costs around the removal and the moved vertices.
        push(job.l, job.a);
        push(job.l, job.b);
        for (std::size_t r = 0; r < job.runs.size(); ++r) {
            const Run& run = job.runs[r];
            const WorkLayer& o = layers_[run.layer];
            for (std::size_t k = 0; k < run.ids.size(); ++k)
                if (job.pieces[r].is_free[k]) {
                    const std::size_t id = run.ids[k];
                    push(run.layer, id);
                    if (o.prev[id] != kNone) push(run.layer, o.prev[id]);
                    if (o.next[id] != kNone) push(run.layer, o.next[id]);
                }
        }
        return true;
    }

    static Job job_for(const WorkLayer& w, std::size_t l, std::size_t v) {
        Job job;
        job.l = l;
        job.a = w.prev[v];
        job.v = v;
        job.b = w.next[v];
        job.removed = w.pos[v];
        return job;
    }

    // Untangles after removing v (unlinked) right away; true if kept.
    bool untangle_now(std::size_t l, std::size_t v) {
        ++report_.batches;  // a batch of one
        Job job = job_for(layers_[l], l, v);
        if (prepare(job) != Prepared::Ready) {  // no job waits: never a conflict
            count_call(l);
            return false;
        }
        execute(job);
        return commit(job);
    }

    // Batched removal of candidate v (immediate untangling): a removal that needs untangling
    // waits in the batch; the batch runs when full, when a removal comes within reach of one
    // of its jobs, or when the queue is empty.
    void remove_batched(const Candidate& c) {
        const std::size_t l = c.layer, v = c.vertex;
        WorkLayer& w = layers_[l];
        Box2 touch;
        touch.extend(w.pos[w.prev[v]]);
        touch.extend(w.pos[v]);
        touch.extend(w.pos[w.next[v]]);
        // Near a waiting job (or on a closed layer down to a few vertices, whose validity
        // reads the whole layer): set aside until the batch has run.
        if (!pending_.empty() &&
            (meets_pending(touch.inflated(max_reach_)) || (w.closed && w.alive_count <= 4))) {
            postpone(c);
            return;
        }
        if (remove_if_clear(l, v)) {
            if (!pending_.empty()) touched_.push_back({touch, pending_.size()});
            count(Outcome::Removed, l, v);
            return;
        }
        Job job = job_for(w, l, v);
        const Prepared prepared = prepare(job);
        if (prepared == Prepared::Conflict) {  // its region meets a waiting job's
            relink(l, v);
            postpone(c);
            return;
        }
        if (prepared == Prepared::Refused) {
            count_call(l);
            conclude(l, v, false);
            return;
        }
        pending_.push_back(std::move(job));
        if (pending_.size() >= params_.batch || (w.closed && w.alive_count <= 3)) flush();
    }

    // Sets candidate c aside until the batch has run; runs it when too many wait.
    void postpone(const Candidate& c) {
        postponed_.push_back(c);
        if (postponed_.size() >= 4 * params_.batch) flush();
    }

    // Runs the waiting jobs side by side (TBB), then commits them in the order they came. A
    // job whose vertices, before or after, came within reach of another's (or of a removal
    // made while it waited) is run again alone afterwards, so the outcome is the same at any
    // thread count.
    void flush() {
        if (pending_.empty()) {
            for (const Candidate& c : postponed_) queue_.push(c);
            postponed_.clear();
            return;
        }
        ++report_.batches;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pending_.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t i = range.begin(); i != range.end(); ++i)
                                  execute(pending_[i]);
                          });
        std::vector<Job> jobs = std::move(pending_);
        pending_.clear();
        std::vector<Box2> reached(jobs.size());
        for (std::size_t i = 0; i < jobs.size(); ++i) reached[i] = span_of(jobs[i]);
        std::vector<std::size_t> again;
        for (std::size_t i = 0; i < jobs.size(); ++i) {
            const Box2 mine = reached[i].inflated(max_reach_);
            bool independent = true;
            for (std::size_t j = 0; j < jobs.size() && independent; ++j)
                if (j != i && mine.overlaps(reached[j])) independent = false;
            for (const Touched& t : touched_)
                if (i < t.jobs_before && mine.overlaps(t.box)) independent = false;
            if (!independent) {
                again.push_back(i);
                continue;
            }
            conclude(jobs[i].l, jobs[i].v, commit(jobs[i]));
        }
        touched_.clear();
        for (const Candidate& c : postponed_) queue_.push(c);
        postponed_.clear();
        for (std::size_t i : again) {
            const Job& job = jobs[i];
            report_.seconds_fields += job.result.seconds_fields;  // the first run's time
            report_.seconds_untangle += job.result.seconds_untangle;
            report_.seconds_finish += job.result.seconds_finish;
            report_.seconds_finish += job.result.seconds_finish;
            report_.seconds_check += job.result.seconds_check + job.seconds_prepare;
            ++report_.batch_reruns;
            conclude(job.l, job.v, untangle_now(job.l, job.v));
        }
    }

    bool batching() const { return params_.untangle && !defer_ && !params_.global; }

    const Scene& input_;
    const SimplifyParams& params_;
    std::unique_ptr<Decimator> decimator_;
    std::vector<WorkLayer> layers_;
    SegmentGrid grid_;
    std::vector<std::vector<double>> need_;
    std::vector<double> reach_, nest_thickness_;
    std::vector<std::vector<std::uint32_t>> stamp_, version_;
    std::uint32_t stamp_counter_ = 0;
    std::vector<std::vector<std::uint32_t>> mark_;  // a job's runs: the job's stamp
    std::uint32_t mark_counter_ = 0;
    std::vector<std::vector<std::uint32_t>> slot_run_, slot_index_;  // where in its job's runs
    bool conflict_ = false;                                          // prepare() met a waiting job
    double max_reach_ = 0.0;  // largest separation needed between two layers
    struct Touched {
        Box2 box;                     // a removal made while jobs waited
        std::size_t jobs_before = 0;  // jobs waiting then
    };
    std::vector<Job> pending_;  // the batch
    std::vector<Touched> touched_;
    std::vector<Candidate> postponed_;  // set aside until the batch has run
    std::size_t done_ = 0;
    bool defer_ = false;  // this sweep sets conflicting removals aside
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> queue_;
    detail::EngineSettings settings_;
    SimplifyReport report_;
};

}  // namespace

void validate(const SimplifyParams& params) {
    if (!(params.remove >= 0.0 && params.remove <= 1.0))
        throw InvalidInput("simplify: params.remove must be in [0, 1] (got " +
                           format_number(params.remove) + ")");
    if (!(params.max_error >= 0.0) || !std::isfinite(params.max_error))
        throw InvalidInput("simplify: params.max_error must be >= 0 and finite (got " +
                           format_number(params.max_error) + ")");
    if (params.batch < 1) throw InvalidInput("simplify: params.batch must be >= 1 (got 0)");
    if (!(params.keep_input_gaps >= 0.0 && params.keep_input_gaps <= 1.0))
        throw InvalidInput("simplify: params.keep_input_gaps must be in [0, 1] (got " +
                           format_number(params.keep_input_gaps) + ")");
    make_decimator(params.decimator, params.seed);
    validate(params.untangling);
}

SimplifyReport simplify(Scene& scene, const SimplifyParams& params, const ProgressFn& progress) {
    validate(params);
    // The gap rule raises required separations on a copy: `scene` stays unchanged on throw.
    Scene input = scene;
    std::size_t raised = 0;
    if (params.untangle && params.keep_input_gaps > 0.0) {
        InputGapParams gap_params;
        // Gaps pass at required x (1 - separation_tolerance): ask for enough that the kept
        // share is keep_input_gaps, at most the whole gap.
        gap_params.fraction =
            std::min(1.0, params.keep_input_gaps / (1.0 - params.untangling.separation_tolerance));
        raised = keep_input_gaps(input, gap_params).raised;
    }
    Driver driver(input, params);
    SimplifyReport report = driver.run(progress);
    report.raised_separations = raised;
    Scene out = driver.result();
    for (const Scene::RaisedSeparation& r : input.raised_separations())
        out.raise_required_separation(r.a, r.b, r.value);

    auto start = Clock::now();
    CheckParams check_params;
    check_params.separation_tolerance = params.untangling.separation_tolerance;
    // The input's open-layer sides: vertex order is kept, and the vote of outside_side() is
    // unreliable on layers simplified to a few vertices.
    check_params.outside_sides = driver.outside_sides();
    const CheckReport check = check_scene(out, check_params);
    report.crossings = check.crossing_count;
    report.self_crossings = check.total_self_crossings();
    report.nesting_violations = check.nesting_violation_count;
    report.min_separation_ratio = check.min_separation_ratio;
    report.collision_free = check.is_collision_free() && check.separations_hold();
    const Vec2 size = scene.bounds().size();
    const double tolerance = 1e-6 * std::max(std::hypot(size.x, size.y), 1e-300);
    for (std::size_t l = 0; l < scene.size(); ++l) {
        LayerSimplifyReport& r = report.layers[l];
        const Layer& before = scene.layer(l);
        const Layer& after = out.layer(l);
        r.name = before.name;
        r.before = before.points.size();
        r.after = after.points.size();
        r.target = driver.target(l);
        r.max_displacement = driver.max_displacement(l);
        if (r.after > r.target) report.targets_met = false;
        r.hausdorff = hausdorff(after, before, tolerance).symmetric();
    }
    report.seconds_check += seconds_since(start);
    scene = std::move(out);
    return report;
}

}  // namespace strata
