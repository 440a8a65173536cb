#include "simplify/detail/job_runner.h"

#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace strata::detail {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

bool is_waiting_stamp(const std::vector<Job>& waiting, std::uint32_t m) {
    for (const Job& job : waiting)
        if (job.stamp == m) return true;
    return false;
}

// The alive vertex `steps` links before (step -1) or after (+1) x, or the last one there is.
std::size_t walk(const WorkLayer& w, std::size_t x, int steps) {
    for (int i = 0; i < std::abs(steps); ++i) {
        const std::size_t y = steps < 0 ? w.prev[x] : w.next[x];
        if (y == kNone) break;
        x = y;
    }
    return x;
}

// The input vertices of w from id `from` to id `to` (wrapping on a closed layer), in order.
template <typename F>
void for_input_ids(const WorkLayer& w, std::size_t from, std::size_t to, F&& f) {
    const std::size_t n = w.original.size();
    for (std::size_t i = from;; i = (i + 1) % n) {
        f(i);
        if (i == to) break;
    }
}

}  // namespace

// The shape error around x (alive vertex of layer k), with the positions `at` gives: the
// larger of the distance from x to the input polyline between the alive vertices two links
// before and after it, and the distance from the input vertices between x's alive neighbours
// to the simplified polyline's four segments around x (so a vertex that slides along its own
// layer by less than a segment's length adds nothing). A local symmetric Hausdorff distance.
template <typename At>
double JobRunner::shape_error(std::size_t k, std::size_t x, At&& at) const {
    const WorkLayer& w = live_.layer(k);
    const std::size_t p = walk(w, x, -1), n = walk(w, x, 1);
    const std::size_t p2 = walk(w, x, -2), n2 = walk(w, x, 2);
    double out = std::numeric_limits<double>::infinity();
    if (p2 == n2) {
        out = glm::distance(at(k, x), w.original[x]);
    } else {
        for_input_ids(w, p2, n2, [&](std::size_t i) {
            if (i != n2)
                out =
                    std::min(out, point_segment_distance(at(k, x), w.original[i],
                                                         w.original[(i + 1) % w.original.size()]));
        });
    }
    double in = 0.0;
    if (p != n) {
        const Vec2 q[5] = {at(k, p2), at(k, p), at(k, x), at(k, n), at(k, n2)};
        for_input_ids(w, p, n, [&](std::size_t i) {
            double d = std::numeric_limits<double>::infinity();
            for (int s = 0; s < 4; ++s)
                d = std::min(d, point_segment_distance(w.original[i], q[s], q[s + 1]));
            in = std::max(in, d);
        });
    }
    return std::max(out, in);
}

// The largest shape_error() over every alive vertex of the layers the job's runs are in, at
// their live positions (before the job): what the simplification has left so far.
double JobRunner::layers_shape_error(const Job& job) const {
    auto at = [&](std::size_t k, std::size_t id) { return live_.layer(k).pos[id]; };
    std::vector<char> seen(live_.size(), 0);
    double worst = 0.0;
    for (const Run& run : job.runs) {
        if (seen[run.layer]) continue;
        seen[run.layer] = 1;
        const WorkLayer& w = live_.layer(run.layer);
        const std::size_t first = w.first();
        if (first == kNone) continue;
        std::size_t x = first;
        while (w.prev[x] != kNone && w.prev[x] != first) x = w.prev[x];  // an open layer's start
        const std::size_t start = x;
        do {
            worst = std::max(worst, shape_error(run.layer, x, at));
            x = w.next[x];
        } while (x != kNone && x != start);
    }
    return worst;
}

// The largest shape_error() over the job's free vertices: before it ran (live positions), or
// with the work scene's.
double JobRunner::job_shape_error(const Job& job, bool after) const {
    auto at = [&](std::size_t k, std::size_t id) {
        if (after && slots_.mark[k][id] == job.stamp)
            return job.work->layer(slots_.run[k][id]).points[slots_.index[k][id]];
        return live_.layer(k).pos[id];
    };
    double worst = 0.0;
    for (std::size_t r = 0; r < job.runs.size(); ++r)
        for (std::size_t k = 0; k < job.runs[r].ids.size(); ++k)
            if (job.pieces[r].is_free[k])
                worst = std::max(worst, shape_error(job.runs[r].layer, job.runs[r].ids[k], at));
    return worst;
}

JobRunner::JobRunner(const Scene& input, const SimplifyParams& params,
                     const EngineSettings& settings, LivePolylines& live,
                     const Separations& separations, const LocalCheck& check,
                     const InputSides& sides)
    : input_(input),
      params_(params),
      settings_(settings),
      live_(live),
      separations_(separations),
      check_(check),
      sides_(sides) {
    slots_.mark.resize(live.size());
    for (std::size_t l = 0; l < live.size(); ++l)
        slots_.mark[l].assign(live.layer(l).alive.size(), 0);
    slots_.run = slots_.mark;
    slots_.index = slots_.mark;
}

// Marks vertex v of layer k for the job being prepared; a vertex of a waiting job is left
// alone and flags a conflict.
void JobRunner::mark(std::size_t k, std::size_t v, std::vector<std::size_t>& marked,
                     const std::vector<Job>& waiting) {
    const std::uint32_t m = slots_.mark[k][v];
    if (m == mark_counter_) return;
    if (m != 0 && is_waiting_stamp(waiting, m)) {
        conflict_ = true;
        return;
    }
    slots_.mark[k][v] = mark_counter_;
    marked.push_back(v);
}

// Runs of layer k through its `marked` vertices, extended by n_out on both sides, in the
// order of their first input id. Costs O(marked * n_out), whatever the layer's size.
void JobRunner::runs_of(std::size_t k, std::vector<std::size_t>& marked,
                        const std::vector<Job>& waiting, std::vector<Run>& out) {
    const WorkLayer& w = live_.layer(k);
    const std::size_t seeds = marked.size();
    for (std::size_t s = 0; s < seeds; ++s) {
        std::size_t i = marked[s], j = marked[s];
        for (std::size_t c = 0; c < params_.n_out; ++c) {
            if (w.prev[i] != kNone) i = w.prev[i];
            if (w.next[j] != kNone) j = w.next[j];
            mark(k, i, marked, waiting);
            mark(k, j, marked, waiting);
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

JobRunner::Prepared JobRunner::prepare(Job& job, const std::vector<Job>& waiting) {
    const auto start = Clock::now();
    const WorkLayer& w = live_.layer(job.l);
    Box2 box;
    box.extend(w.pos[job.a]);
    box.extend(w.pos[job.b]);
    box.extend(job.removed);
    const double chord = glm::distance(w.pos[job.a], w.pos[job.b]);
    const double nest = separations_.nest_thickness[job.l];
    const Box2 region = box.inflated(std::max(2.0 * nest, 0.5 * chord));
    const Box2 around = region.inflated(std::max(2.0 * nest, chord));
    // Work layers: runs through the vertices of the segments near the region.
    std::vector<std::vector<std::size_t>> marked(live_.size());
    job.stamp = ++mark_counter_;
    conflict_ = false;
    if (params_.global) {
        for (std::size_t k = 0; k < live_.size(); ++k)
            for (std::size_t v = 0; v < live_.layer(k).alive.size(); ++v)
                if (live_.layer(k).alive[v]) mark(k, v, marked[k], waiting);
    } else {
        // The segments filed in the cells of the input's grid that `around` touches (those
        // the live grid gave before it was built again for longer segments): the region is
        // the same at any later cell size.
        const LivePolylines::CellRange cells = live_.input_cells(around);
        live_.segments_near(around.inflated(2.0 * live_.input_cell()),
                            [&](std::size_t k, std::size_t u) {
                                if (!cells.meets(live_.input_cells(live_.seg_box(k, u)))) return;
                                mark(k, u, marked[k], waiting);
                                mark(k, live_.layer(k).next[u], marked[k], waiting);
                            });
    }
    job.runs.clear();
    for (std::size_t k = 0; k < live_.size() && !conflict_; ++k)
        if (!marked[k].empty()) runs_of(k, marked[k], waiting, job.runs);
    if (conflict_) return Prepared::Conflict;
    job.footprint = Box2{};
    job.footprint.extend(job.removed);
    for (const Run& run : job.runs)
        for (std::size_t id : run.ids) job.footprint.extend(live_.layer(run.layer).pos[id]);
    if (meets_any(waiting, job.footprint.inflated(separations_.max_reach)))
        return Prepared::Conflict;

    std::vector<Layer> work_layers;
    job.pieces.clear();
    job.relations = RelationSource{};
    job.relations.scene = &input_;
    job.settings = settings_;
    job.settings.outside_signs.clear();
    job.settings.check_every_step = !params_.global;
    job.settings.rest_at_start = true;  // passes of one round: match toward the start
    for (std::size_t r = 0; r < job.runs.size(); ++r) {
        const Run& run = job.runs[r];
        const Layer& parent = input_.layer(run.layer);
        const WorkLayer& parent_work = live_.layer(run.layer);
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
            const bool is_end = !parent_work.closed &&
                                (parent_work.prev[id] == kNone || parent_work.next[id] == kNone);
            piece.is_free.push_back(!is_end && (params_.global || region.contains(p)) ? 1 : 0);
            slots_.run[run.layer][id] = static_cast<std::uint32_t>(r);
            slots_.index[run.layer][id] = static_cast<std::uint32_t>(k);
        }
        if (layer.closed && layer.points.front() == layer.points.back()) return Prepared::Refused;
        work_layers.push_back(std::move(layer));
        job.pieces.push_back(std::move(piece));
        job.relations.parent.push_back(run.layer);
        job.settings.outside_signs.push_back(settings_.outside_signs[run.layer]);
    }
    job.work.emplace(std::move(work_layers));
    local_sides(job);
    job.moving.clear();
    for (const Run& run : job.runs) {
        const WorkLayer& o = live_.layer(run.layer);
        for (std::size_t id : run.ids)
            if (o.next[id] != kNone &&
                (slots_.is_free(run.layer, id, job) || slots_.is_free(run.layer, o.next[id], job)))
                job.moving.push_back(LivePolylines::ref(run.layer, id));
    }
    job.seconds_prepare = seconds_since(start);
    return Prepared::Ready;
}

// The local sides of the job's vertices (RelationSource::local_sides, take_input_sides()):
// vertex k of run r is input vertex run.ids[k] of layer run.layer. Nothing is set when the
// job has no such vertex.
//
// A job that holds a rolled vertex (a Flipped side) gives up when stalled with a close vertex
// still on the wrong side (EngineSettings::give_up_when_stalled, from its fifth pass), and its
// finishing stage stops pushing after a sweep that leaves as many close vertices on the wrong
// side as it found (EngineSettings::finish_stop_when_wrong_stays): there four layers can stack
// (a shirt rolled over a jacket's end on a body: body, shirt, jacket, roll), and the
// untanglings that fail ran all 16 passes at 2-3x the cost of a pass of the unrolled scene,
// most of it in sweeps that pushed the same vertices back and forth (docs/untangle.md,
// *Rolled families, measured*). Jobs without one run as before, so scenes without rolls keep
// their outputs.
void JobRunner::local_sides(Job& job) const {
    take_input_sides(job.relations, *job.work, sides_, settings_.outside_signs,
                     [&job](std::size_t r, std::size_t k) { return job.runs[r].ids[k]; });
    for (const auto& layer : job.relations.local_sides)
        for (const auto& vertex : layer)
            for (const RelationSource::LocalSide& x : vertex)
                if (x.side == RelationSource::Side::Flipped) {
                    job.rolled = true;
                    job.settings.give_up_when_stalled = true;
                    job.settings.finish_stop_when_wrong_stays = 1;
                }
}

void JobRunner::execute(Job& job) const {
    SegmentGrid moving = make_segment_grid(live_.grid().cell());
    // A result that carries a vertex out of the job's neighbourhood is no local fix: refused
    // (filing its segments would also touch an unbounded number of grid cells).
    const Vec2 size = job.footprint.size();
    const Box2 bound =
        job.footprint.inflated(2.0 * std::max(std::hypot(size.x, size.y), separations_.max_reach));
    auto is_ok = [&](const Scene& s) {
        const Overlay ov(live_, slots_, job, s, moving);
        moving.clear();
        for (const SegRef& seg : job.moving) {
            const Vec2 a = ov.pos(seg.layer, seg.start);
            const Vec2 b = ov.pos(seg.layer, live_.layer(seg.layer).next[seg.start]);
            if (!bound.contains(a) || !bound.contains(b)) return false;
            Box2 box;
            box.extend(a);
            box.extend(b);
            moving.insert(seg, box);
        }
        if (!check_.removal_clear(job.l, job.a, job.removed, job.b, ov)) return false;
        // The segments with a moved end: two segments that both stay where they are live were
        // clear there (the chord (a, b) aside, which removal_clear() reads).
        for (std::size_t r = 0; r < job.runs.size(); ++r) {
            const Run& run = job.runs[r];
            const WorkLayer& o = live_.layer(run.layer);
            auto moved = [&](std::size_t id) { return ov.pos(run.layer, id) != o.pos[id]; };
            for (std::size_t k = 0; k < run.ids.size(); ++k) {
                if (!job.pieces[r].is_free[k]) continue;
                const std::size_t id = run.ids[k];
                const bool here = moved(id);
                if (o.prev[id] != kNone && (here || moved(o.prev[id])) &&
                    !check_.segment_clear(run.layer, o.prev[id], id, ov))
                    return false;
                if (o.next[id] != kNone && (here || moved(o.next[id])) &&
                    !check_.segment_clear(run.layer, id, o.next[id], ov))
                    return false;
            }
            if (!check_.closed_valid(run.layer, ov)) return false;
        }
        // Nesting of the region's vertices against every closed layer near it.
        for (const Run& run : job.runs)
            if (!check_.nesting_kept(run.layer, run.ids, ov)) return false;
        // Sides of the open layers, as the input gives them (a rolled part stays rolled).
        return check_.sides_kept(ov);
    };
    // A rolled job's result (a shifted chord or an untangling) may leave the shape around its
    // free vertices (shape_error()) farther from the input than the removal alone would by at
    // most the removal's layer's separation (what an untangling must move a layer by), or
    // else no farther than the shape error its layers already have elsewhere (so it does not
    // raise their Hausdorff distance). Beyond both it is refused. Jobs without a rolled vertex
    // are not bounded, so scenes without rolls keep their outputs.
    const double error_bound =
        job.rolled ? job_shape_error(job, false) + separations_.reach[job.l] : 0.0;
    double layers_error = -1.0;  // the job's layers' largest shape error, when first needed
    auto within_bound = [&] {
        const double error = job_shape_error(job, true);
        if (error <= error_bound) return true;
        if (layers_error < 0.0) layers_error = layers_shape_error(job);
        return error <= layers_error;
    };
    job.shifted = job.rolled && shift_chord(job, is_ok, within_bound);
    if (job.shifted) {
        job.result = EngineResult{};
        job.result.ok = true;
        return;
    }
    job.result = run_engine(*job.work, job.pieces, params_.untangling, job.relations, job.settings,
                            is_ok, {});
    if (job.rolled && job.result.ok && !within_bound()) {
        job.result.ok = false;
        job.shape_refused = true;
    }
}

// A removal whose chord (a, b) crosses nothing but comes closer than their separation to other
// layers, all of them on the far side of it from the removed vertex (the chord of a bend cuts
// into what lies inside the bend): moving a and b together toward the removed vertex, along
// the chord's normal, gives the room back where the layer was. Shifts tried: to the required
// separation, to the checked one (need), twice those; never beyond the removed vertex's
// distance to the chord. One is kept when no vertex lies in the area that (before a, a),
// (a, b) and (b, after b) sweep (so nothing tunnels: that area's old sides are live segments
// and the crossing-free chord), `is_ok` (the job's exact check) passes and the shape error
// stays within bounds (`within_bound`, execute()); the work scene is left as it was otherwise.
// Tried for rolled jobs only (Job::rolled), before the untangling: there the untangling of such a
// removal moved the whole fold and gave up (collar_wrap, docs/simplify.md); other jobs run as
// before, so scenes without rolls keep their outputs.
bool JobRunner::shift_chord(Job& job, const std::function<bool(const Scene&)>& is_ok,
                            const std::function<bool()>& within_bound) const {
    const std::size_t l = job.l, a = job.a, b = job.b;
    const WorkLayer& w = live_.layer(l);
    if (!slots_.is_free(l, a, job) || !slots_.is_free(l, b, job)) return false;
    const std::size_t before_a = w.prev[a], after_b = w.next[b];
    if (before_a == kNone || after_b == kNone) return false;
    const Vec2 pa = w.pos[a], pb = w.pos[b], v = job.removed;
    const int side = orient2d(pa, pb, v);
    const double length = glm::distance(pa, pb);
    if (side == 0 || !(length > 0.0)) return false;
    Vec2 normal(pb.y - pa.y, pa.x - pb.x);  // right of a -> b
    normal /= length;
    if (glm::dot(normal, v - pa) < 0.0) normal = -normal;  // toward the removed vertex
    const double height = glm::dot(normal, v - pa);
    Box2 chord;
    chord.extend(pa);
    chord.extend(pb);
    // The check passes a gap at need (the required separation less the tolerance); the shift
    // aims at the required separation itself, as the finishing stage does.
    const double full = 1.0 / (1.0 - params_.untangling.separation_tolerance);
    double shortfall = 0.0, least = 0.0;  // to the required separation, to need
    bool blocked = false;
    live_.live_segments_near(
        chord.inflated(full * separations_.reach[l]), [&](const LiveSegment& s) {
            if (blocked || s.layer == l) return;
            const double need = separations_.need[l][s.layer];
            if (!(need > 0.0)) return;
            if (segment_contact(pa, pb, s.p, s.q) != SegmentContact::None) {
                blocked = true;
                return;
            }
            const double d = std::min(
                std::min(point_segment_distance(s.p, pa, pb), point_segment_distance(s.q, pa, pb)),
                std::min(point_segment_distance(pa, s.p, s.q),
                         point_segment_distance(pb, s.p, s.q)));
            if (!(d < full * need)) return;
            if (orient2d(pa, pb, s.p) == side || orient2d(pa, pb, s.q) == side) {
                blocked = true;  // on the removed vertex's side: moving toward it cannot help
                return;
            }
            shortfall = std::max(shortfall, full * need - d);
            least = std::max(least, need - d);
        });
    if (blocked || !(shortfall > 0.0)) return false;
    const std::size_t ra = slots_.run[l][a], ka = slots_.index[l][a];
    const std::size_t rb = slots_.run[l][b], kb = slots_.index[l][b];
    Scene& work = *job.work;
    const Vec2 before = w.pos[before_a], after = w.pos[after_b];
    // The shift to the required separation first, then to need, then twice those (a shift
    // also moves the neighbouring segments): the first that the check passes.
    for (const double by : {shortfall, least, 2.0 * least, 2.0 * shortfall}) {
        if (!(by > 0.0) || by > height) continue;
        const Vec2 qa = pa + by * normal, qb = pb + by * normal;
        // Nothing in the area swept by (before, a), (a, b) and (b, after).
        Box2 swept;
        for (const Vec2& p : {before, pa, pb, after, qa, qb}) swept.extend(p);
        bool clear = true;
        auto in = [](const Vec2& x, const Vec2& p, const Vec2& q, const Vec2& r) {
            Box2 box;
            box.extend(p);
            box.extend(q);
            box.extend(r);
            return point_in_closed_triangle(box, p, q, r, x);
        };
        live_.live_segments_near(swept, [&](const LiveSegment& s) {
            if (!clear) return;
            for (const std::size_t x : {std::size_t{s.start}, std::size_t{s.end}}) {
                if (s.layer == l && (x == before_a || x == a || x == b || x == after_b)) continue;
                const Vec2 p = x == s.start ? s.p : s.q;
                if (in(p, before, pa, qa) || in(p, pa, qa, qb) || in(p, pa, qb, pb) ||
                    in(p, pb, qb, after))
                    clear = false;
            }
        });
        if (!clear) continue;
        auto set = [&](std::size_t r, std::size_t k, const Vec2& to) {
            std::vector<Vec2> points = work.layer(r).points;
            points[k] = to;
            work.set_points(r, std::move(points));
        };
        set(ra, ka, qa);
        set(rb, kb, qb);
        if (is_ok(work) && within_bound()) return true;
        set(ra, ka, pa);
        set(rb, kb, pb);
    }
    return false;
}

void JobRunner::apply(const Job& job) {
    for (std::size_t r = 0; r < job.runs.size(); ++r) {
        const Run& run = job.runs[r];
        for (std::size_t k = 0; k < run.ids.size(); ++k)
            if (job.pieces[r].is_free[k])
                live_.move(run.layer, run.ids[k], job.work->layer(r).points[k]);
    }
}

}  // namespace strata::detail
