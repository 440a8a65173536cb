#pragma once
/// @file One local untangling of the simplification driver (a Job: the runs of live vertices
/// it may move, its work scene and its result); the JobSlots that say which job's runs a live
/// vertex is in; and the Overlay through which the exact checks read positions: the live
/// ones, or over a job's runs those of its work scene. Private to src/simplify.

#include "simplify/detail/live_polylines.h"
#include "untangle/detail/engine.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace strata::detail {

/// A run of alive vertices of one layer, in order, standing for one work layer.
struct Run {
    std::size_t layer = 0;
    std::vector<std::size_t> ids;
    bool whole_loop = false;
};

/// One local untangling: prepared from the live polylines, run without writing to them (so
/// that untanglings whose footprints keep apart run side by side), then committed.
struct Job {
    std::size_t l = 0, a = 0, v = 0, b = 0;  ///< Removal of v between a and b, layer l.
    Vec2 removed{};                          ///< Where v was.
    std::uint32_t stamp = 0;                 ///< JobSlots::mark of the runs' vertices.
    std::vector<Run> runs;
    std::vector<Piece> pieces;   ///< Per run: its free vertices.
    std::vector<SegRef> moving;  ///< Segments with a free end.
    std::optional<Scene> work;   ///< The work scene: one layer per run.
    RelationSource relations;    ///< Work layer -> its layer.
    EngineSettings settings;     ///< Per work layer.
    Box2 footprint;              ///< The runs' vertices before, and the removed one.
    EngineResult result;
    double seconds_prepare = 0.0;
    bool rolled = false;   ///< Some vertex of the job takes an open layer Flipped (a roll).
    bool shifted = false;  ///< Kept by shifting its chord (JobRunner::shift_chord()), no pass.
    /// Its untangling succeeded but left the shape farther from the input than allowed
    /// (JobRunner::execute()): refused.
    bool shape_refused = false;
};

/// The job for removing vertex v of layer l, still linked.
inline Job job_for(const LivePolylines& live, std::size_t l, std::size_t v) {
    const WorkLayer& w = live.layer(l);
    Job job;
    job.l = l;
    job.a = w.prev[v];
    job.v = v;
    job.b = w.next[v];
    job.removed = w.pos[v];
    return job;
}

/// The box of the job's vertices before and after (it has run), and of the removed vertex.
inline Box2 span_of(const Job& job) {
    Box2 box = job.footprint;
    for (std::size_t r = 0; r < job.runs.size(); ++r)
        for (const Vec2& p : job.work->layer(r).points) box.extend(p);
    return box;
}

/// Whether `box` meets the footprint of one of `jobs`.
inline bool meets_any(const std::vector<Job>& jobs, const Box2& box) {
    for (const Job& job : jobs)
        if (job.footprint.overlaps(box)) return true;
    return false;
}

/// Where each live vertex is in a job's runs. Stamp style, never cleared: vertex x of layer k
/// is in the runs of the job whose stamp is mark[k][x] (0: none yet), as vertex index[k][x]
/// of its run run[k][x].
struct JobSlots {
    std::vector<std::vector<std::uint32_t>> mark, run, index;

    bool is_free(std::size_t k, std::size_t x, const Job& job) const {
        return x != kNone && mark[k][x] == job.stamp && job.pieces[run[k][x]].is_free[index[k][x]];
    }
};

/// Where the checks read positions: the live polylines, or over a job's runs its work scene.
class Overlay {
  public:
    /// The live positions.
    explicit Overlay(const LivePolylines& live) : live_(&live) {}
    /// Over `job`'s runs, the positions of `work` (its work scene while it runs); `moving`:
    /// the job's moving segments where they are in `work` (filed with their boxes there).
    /// Writes nothing the live polylines share: the jobs of a batch run side by side.
    Overlay(const LivePolylines& live, const JobSlots& slots, const Job& job, const Scene& work,
            const SegmentGrid& moving)
        : live_(&live), slots_(&slots), job_(&job), work_(&work), moving_(&moving) {}

    /// The job read through, if any.
    const Job* job() const { return job_; }

    Vec2 pos(std::size_t k, std::size_t x) const {
        if (job_ && slots_->mark[k][x] == job_->stamp)
            return work_->layer(slots_->run[k][x]).points[slots_->index[k][x]];
        return live_->layer(k).pos[x];
    }

    /// Calls f(layer, start) once per segment whose box meets `box`, at these positions.
    template <class F>
    void near(const Box2& box, F&& f) const {
        if (!job_) {
            live_->segments_near(box, f);
            return;
        }
        // The live grid holds the moving segments where they were: they come from `moving`.
        live_->live_segments_near(box, [&](const LiveSegment& s) {
            if (!slots_->is_free(s.layer, s.start, *job_) &&
                !slots_->is_free(s.layer, s.end, *job_))
                f(static_cast<std::size_t>(s.layer), static_cast<std::size_t>(s.start));
        });
        moving_->query_once(
            box,
            [&](SegRef s) {
                Box2 b;
                b.extend(pos(s.layer, s.start));
                b.extend(pos(s.layer, live_->layer(s.layer).next[s.start]));
                return b;
            },
            [&](SegRef s) {
                f(static_cast<std::size_t>(s.layer), static_cast<std::size_t>(s.start));
            });
    }

  private:
    const LivePolylines* live_;
    const JobSlots* slots_ = nullptr;
    const Job* job_ = nullptr;
    const Scene* work_ = nullptr;
    const SegmentGrid* moving_ = nullptr;
};

}  // namespace strata::detail
