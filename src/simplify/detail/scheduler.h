#pragma once
/// @file The order of the simplification driver's removals: a priority queue of candidate
/// vertices by decimation cost; each removal kept when the local check clears it, otherwise
/// untangled (one at a time, or in batches whose untanglings run side by side) or set aside,
/// by the schedule (SimplifyParams::schedule, batch); the counts and times of the report.
/// Private to src/simplify.

#include "simplify/detail/job_runner.h"
#include "simplify/detail/live_polylines.h"
#include "simplify/detail/local_check.h"
#include "simplify/detail/separations.h"
#include "simplify/detail/untangle_job.h"
#include "strata/core/progress.h"
#include "strata/simplify/decimator.h"
#include "strata/simplify/simplify.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <queue>
#include <vector>

namespace strata::detail {

/// A vertex to try removing, at its decimation cost when queued (version: of that cost).
struct Candidate {
    double cost;
    std::uint32_t layer, vertex, version;
    bool operator>(const Candidate& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (layer != o.layer) return layer > o.layer;
        return vertex > o.vertex;
    }
};

class Scheduler {
  public:
    /// Keeps references to every argument.
    Scheduler(const SimplifyParams& params, LivePolylines& live, const Separations& separations,
              const LocalCheck& check, JobRunner& jobs);

    /// Removes vertices until every layer is at its target or nothing more can go. The report
    /// holds the removal counts and times (not the final check of the output).
    /// @throws Cancelled when `progress` returns false.
    SimplifyReport run(const ProgressFn& progress);

  private:
    enum class Outcome { Removed, Deferred, Refused };

    DecimationView view(std::size_t l) const;
    bool removable(std::size_t l, std::size_t v) const;
    void push(std::size_t l, std::size_t v);
    void push_untimed(std::size_t l, std::size_t v);
    void count(Outcome outcome, std::size_t l, std::size_t v);
    void count_call(std::size_t l);
    void conclude(std::size_t l, std::size_t v, bool kept);
    bool remove_if_clear(std::size_t l, std::size_t v);
    Outcome try_remove(std::size_t l, std::size_t v);
    bool untangle_now(std::size_t l, std::size_t v);
    bool commit(const Job& job);
    void remove_batched(const Candidate& c);
    bool waits_on(std::size_t l) const;
    void postpone(const Candidate& c);
    void requeue_set_aside();
    void flush();
    bool batching() const { return params_.untangle && !defer_ && !params_.global; }

    const SimplifyParams& params_;
    LivePolylines& live_;
    const Separations& separations_;
    const LocalCheck& check_;
    JobRunner& jobs_;
    std::unique_ptr<Decimator> decimator_;
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> queue_;
    std::vector<std::vector<std::uint32_t>> version_;  // per vertex: of its latest candidate
    bool defer_ = false;        // this sweep sets removals that need untangling aside
    std::vector<Job> pending_;  // the batch
    struct Touched {
        Box2 box;                     // a removal made while jobs waited
        std::size_t jobs_before = 0;  // jobs waiting then
    };
    std::vector<Touched> touched_;
    std::vector<Candidate> postponed_;  // set aside until the batch has run
    // Candidates of layers that looked done while a removal on them waited in the batch (it
    // may be refused): queued again after the batch, without counting towards its size.
    std::vector<Candidate> held_;
    std::size_t done_ = 0;              // removals kept
    SimplifyReport report_;
};

}  // namespace strata::detail
