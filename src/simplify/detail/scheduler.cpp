#include "simplify/detail/scheduler.h"

#include "strata/core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <utility>

namespace strata::detail {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Scheduler::Scheduler(const SimplifyParams& params, LivePolylines& live,
                     const Separations& separations, const LocalCheck& check, JobRunner& jobs)
    : params_(params),
      live_(live),
      separations_(separations),
      check_(check),
      jobs_(jobs),
      decimator_(make_decimator(params.decimator, params.seed)) {
    version_.resize(live.size());
    for (std::size_t l = 0; l < live.size(); ++l) version_[l].assign(live.layer(l).alive.size(), 0);
    report_.layers.resize(live.size());
}

SimplifyReport Scheduler::run(const ProgressFn& progress) {
    const auto start_all = Clock::now();
    std::size_t to_remove = 0;
    for (std::size_t l = 0; l < live_.size(); ++l)
        to_remove += live_.layer(l).alive_count - live_.layer(l).target;
    auto push_all = [&](bool above_target_only) {
        const auto start = Clock::now();
        for (std::size_t l = 0; l < live_.size(); ++l)
            if (!above_target_only || live_.layer(l).alive_count > live_.layer(l).target)
                for (std::size_t v = 0; v < live_.layer(l).alive.size(); ++v) push_untimed(l, v);
        report_.seconds_decimate += seconds_since(start);
    };
    push_all(false);
    std::size_t last_reported = 0;
    // Deferred schedule: a first sweep removes what needs no untangling; a second one
    // untangles, over the layers still above their target only.
    defer_ = params_.untangle && params_.schedule == UntangleSchedule::Deferred;
    for (int sweep = 0; sweep < (defer_ ? 2 : 1); ++sweep) {
        if (sweep == 1) {
            defer_ = false;
            push_all(true);
        }
        for (;;) {
            if (queue_.empty()) {
                flush();  // its commits may bring new candidates
                if (queue_.empty()) break;
            }
            const Candidate c = queue_.top();
            queue_.pop();
            const std::size_t l = c.layer, v = c.vertex;
            const WorkLayer& w = live_.layer(l);
            if (c.version != version_[l][v]) continue;
            if (!removable(l, v) || w.alive_count <= w.target) {
                // A waiting job's removal on this layer may yet be refused and give its vertex
                // back: keep the candidate until the batch has run.
                if (w.alive[v] && !w.locked[v] && waits_on(l)) held_.push_back(c);
                continue;
            }
            const std::size_t a = w.prev[v], b = w.next[v];
            if (params_.max_error > 0.0 && span_error(view(l), a, b) > params_.max_error) {
                live_.lock(l, v);
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

DecimationView Scheduler::view(std::size_t l) const {
    const WorkLayer& w = live_.layer(l);
    return DecimationView{w.original, w.pos, w.closed};
}

bool Scheduler::removable(std::size_t l, std::size_t v) const {
    const WorkLayer& w = live_.layer(l);
    if (!w.alive[v] || w.locked[v]) return false;
    if (!w.closed && (w.prev[v] == kNone || w.next[v] == kNone)) return false;  // ends stay
    return w.alive_count > (w.closed ? 3 : 2);
}

// Queues v at its current cost; its earlier candidates are out of date.
void Scheduler::push(std::size_t l, std::size_t v) {
    const auto start = Clock::now();
    push_untimed(l, v);
    report_.seconds_decimate += seconds_since(start);
}

// push() without its timer, for callers that time it with their own work.
void Scheduler::push_untimed(std::size_t l, std::size_t v) {
    if (!removable(l, v)) return;
    const WorkLayer& w = live_.layer(l);
    const double cost = decimator_->cost(l, view(l), w.prev[v], v, w.next[v]);
    queue_.push(
        {cost, static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(v), ++version_[l][v]});
}

void Scheduler::count(Outcome outcome, std::size_t l, std::size_t v) {
    switch (outcome) {
        case Outcome::Removed:
            ++report_.removed;
            ++done_;
            break;
        case Outcome::Deferred:
            ++report_.deferred;
            break;
        case Outcome::Refused:
            live_.lock(l, v);
            ++report_.refused;
            ++report_.layers[l].refused;
            break;
    }
}

// One untangling of a removal on layer l, in the report.
void Scheduler::count_call(std::size_t l) {
    ++report_.untangle_calls;
    ++report_.layers[l].untangled;
}

// The removal of v (unlinked) is kept, or rolled back and its vertex locked.
void Scheduler::conclude(std::size_t l, std::size_t v, bool kept) {
    if (kept) {
        count(Outcome::Removed, l, v);
        return;
    }
    live_.relink(l, v);
    count(Outcome::Refused, l, v);
}

// Unlinks v; true when that alone keeps its region collision-free.
bool Scheduler::remove_if_clear(std::size_t l, std::size_t v) {
    const WorkLayer& w = live_.layer(l);
    const std::size_t a = w.prev[v], b = w.next[v];
    const Vec2 removed = w.pos[v];
    // Three clock readings for the check and the two new costs (a reading costs ~20 ns, a
    // removal ~5 us: timing each push on its own took 3% of a run).
    const auto start = Clock::now();
    live_.unlink(l, v);
    const bool clear = !params_.untangle || check_.removal_clear(l, a, removed, b, Overlay(live_));
    const auto checked = Clock::now();
    report_.seconds_check += std::chrono::duration<double>(checked - start).count();
    if (clear) {
        push_untimed(l, a);
        push_untimed(l, b);
        report_.seconds_decimate += seconds_since(checked);
    }
    return clear;
}

// One removal at a time (no batch): the paper's order.
Scheduler::Outcome Scheduler::try_remove(std::size_t l, std::size_t v) {
    if (remove_if_clear(l, v)) return Outcome::Removed;
    if (!defer_ && untangle_now(l, v)) return Outcome::Removed;
    live_.relink(l, v);
    return defer_ ? Outcome::Deferred : Outcome::Refused;
}

// Untangles after removing v (unlinked) right away; true if kept.
bool Scheduler::untangle_now(std::size_t l, std::size_t v) {
    ++report_.batches;  // a batch of one
    Job job = job_for(live_, l, v);
    if (jobs_.prepare(job, pending_) != JobRunner::Prepared::Ready) {  // never a conflict here
        count_call(l);
        return false;
    }
    jobs_.execute(job);
    return commit(job);
}

// Applies a successful job's moves; true if it succeeded.
bool Scheduler::commit(const Job& job) {
    count_call(job.l);
    report_.rounds += job.result.rounds;
    report_.seconds_check += job.seconds_prepare;
    report_.seconds_fields += job.result.seconds_fields;
    report_.seconds_untangle += job.result.seconds_untangle;
    report_.seconds_finish += job.result.seconds_finish;
    report_.seconds_check += job.result.seconds_check;
    if (job.result.gave_up) ++report_.gave_up;
    if (job.shifted) ++report_.chord_shifts;
    if (job.shape_refused) ++report_.shape_refused;
    if (!job.result.ok) return false;
    jobs_.apply(job);
    // New costs around the removal and the moved vertices.
    push(job.l, job.a);
    push(job.l, job.b);
    for (std::size_t r = 0; r < job.runs.size(); ++r) {
        const Run& run = job.runs[r];
        const WorkLayer& o = live_.layer(run.layer);
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

// Batched removal of candidate c (immediate untangling): a removal that needs untangling
// waits in the batch; the batch runs when full, when a removal comes within reach of one of
// its jobs, or when the queue is empty.
void Scheduler::remove_batched(const Candidate& c) {
    const std::size_t l = c.layer, v = c.vertex;
    const WorkLayer& w = live_.layer(l);
    const double max_reach = separations_.max_reach;
    Box2 touch;
    touch.extend(w.pos[w.prev[v]]);
    touch.extend(w.pos[v]);
    touch.extend(w.pos[w.next[v]]);
    // Near a waiting job (or on a closed layer down to a few vertices, whose validity reads
    // the whole layer): set aside until the batch has run.
    if (!pending_.empty() &&
        (meets_any(pending_, touch.inflated(max_reach)) || (w.closed && w.alive_count <= 4))) {
        postpone(c);
        return;
    }
    if (remove_if_clear(l, v)) {
        if (!pending_.empty()) touched_.push_back({touch, pending_.size()});
        count(Outcome::Removed, l, v);
        return;
    }
    Job job = job_for(live_, l, v);
    const JobRunner::Prepared prepared = jobs_.prepare(job, pending_);
    if (prepared == JobRunner::Prepared::Conflict) {  // its region meets a waiting job's
        live_.relink(l, v);
        postpone(c);
        return;
    }
    if (prepared == JobRunner::Prepared::Refused) {
        count_call(l);
        conclude(l, v, false);
        return;
    }
    pending_.push_back(std::move(job));
    if (pending_.size() >= params_.batch || (w.closed && w.alive_count <= 3)) flush();
}

// A job of the batch removes a vertex of layer l.
bool Scheduler::waits_on(std::size_t l) const {
    for (const Job& job : pending_)
        if (job.l == l) return true;
    return false;
}

// The candidates set aside while the batch waited (postponed and held) go back to the queue.
void Scheduler::requeue_set_aside() {
    for (const Candidate& c : postponed_) queue_.push(c);
    postponed_.clear();
    for (const Candidate& c : held_) queue_.push(c);
    held_.clear();
}

// Sets candidate c aside until the batch has run; runs it when too many wait.
void Scheduler::postpone(const Candidate& c) {
    postponed_.push_back(c);
    if (postponed_.size() >= 4 * params_.batch) flush();
}

// Runs the waiting jobs side by side (TBB), then commits them in the order they came. A job
// whose vertices, before or after, came within reach of another's (or of a removal made while
// it waited) is run again alone afterwards, so the outcome is the same at any thread count.
void Scheduler::flush() {
    if (pending_.empty()) {
        requeue_set_aside();
        return;
    }
    ++report_.batches;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pending_.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i)
                              jobs_.execute(pending_[i]);
                      });
    std::vector<Job> jobs = std::move(pending_);
    pending_.clear();
    const double max_reach = separations_.max_reach;
    std::vector<Box2> reached(jobs.size());
    for (std::size_t i = 0; i < jobs.size(); ++i) reached[i] = span_of(jobs[i]);
    std::vector<std::size_t> again;
    for (std::size_t i = 0; i < jobs.size(); ++i) {
        const Box2 mine = reached[i].inflated(max_reach);
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
    requeue_set_aside();
    for (std::size_t i : again) {
        const Job& job = jobs[i];
        report_.seconds_fields += job.result.seconds_fields;  // the first run's time
        report_.seconds_untangle += job.result.seconds_untangle;
        report_.seconds_finish += job.result.seconds_finish;
        report_.seconds_check += job.result.seconds_check + job.seconds_prepare;
        ++report_.batch_reruns;
        conclude(job.l, job.v, untangle_now(job.l, job.v));
    }
}

}  // namespace strata::detail
