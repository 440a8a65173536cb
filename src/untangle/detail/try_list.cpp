#include "untangle/detail/try_list.h"

#include "strata/core/error.h"

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace strata::detail {

namespace {

constexpr std::size_t none = static_cast<std::size_t>(-1);

// What the calling thread and the worker share while a list runs. Tries are claimed in order.
// Every try queues its progress calls; the calling thread passes them on to the caller's
// progress in the order of the tries, a try's after the earlier tries' (so the caller sees the
// calls of one try at a time, as when they run one at a time), and takes the results in that
// order. `last_` is the last try the list may still need: the first clean one (with
// until_clean) or the first that threw; a try after it stops at its next progress call, and
// neither its calls nor its result are passed on.
class TryList {
  public:
    TryList(std::size_t count, bool until_clean, const RunTry& run, const TakeTry& take,
            const ProgressFn& progress)
        : slots_(count),
          until_clean_(until_clean),
          run_(run),
          take_(take),
          progress_(progress),
          last_(count - 1) {}

    // The next try to run, or `none` when no try is left that the list may need. `worker`:
    // claimed by the worker, which the calling thread then waits for before it returns.
    std::size_t claim(bool worker) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!claimable()) return none;
        if (worker) worker_busy_ = true;
        return next_++;
    }

    bool has_unclaimed() {
        std::lock_guard<std::mutex> lock(mutex_);
        return claimable();
    }

    // The worker's loop: claims and runs tries until none is left.
    void work() {
        for (std::size_t i = claim(true); i != none; i = claim(true)) {
            run(i, [this, i](std::string_view stage, double fraction) {
                queue(i, stage, fraction);
                return wanted(i);
            });
            {
                std::lock_guard<std::mutex> lock(mutex_);
                worker_busy_ = false;
            }
            changed_.notify_one();
        }
    }

    // Try i on the calling thread; its progress calls pass on the queued ones as far as they go.
    void run_here(std::size_t i) {
        tbb::this_task_arena::isolate([&] {  // not the worker's loop while waiting in here
            run(i, [this, i](std::string_view stage, double fraction) {
                queue(i, stage, fraction);
                pass_on();
                return wanted(i);
            });
        });
    }

    // Until the worker is done with its try: passes on its progress calls and takes the results
    // as they come.
    void wait_for_worker() {
        for (;;) {
            pass_on();
            take_done();
            std::unique_lock<std::mutex> lock(mutex_);
            if (!worker_busy_) break;
            changed_.wait_for(lock, std::chrono::milliseconds(50));
        }
        pass_on();
        take_done();
    }

    // Passes the queued progress calls on to the caller's progress, in the order of the tries;
    // when it returns false, every try stops (cancelled()).
    void pass_on() {
        for (;;) {
            std::string stage;
            double fraction = 0.0;
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (cancelled_ || passing_ >= slots_.size() || passing_ > last_) return;
                Slot& slot = slots_[passing_];
                if (slot.passed == slot.calls.size()) {
                    if (!slot.done) return;
                    ++passing_;
                    continue;
                }
                stage = slot.calls[slot.passed].first;
                fraction = slot.calls[slot.passed].second;
                ++slot.passed;
            }
            if (progress_ && !progress_(stage, fraction)) {
                cancelled_ = true;
                stop_ = true;
                return;
            }
        }
    }

    // Hands the results whose progress calls have all been passed on to take, in order (none
    // once cancelled); rethrows the exception of a try it reaches.
    void take_done() {
        for (;;) {
            TryResult result;
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (cancelled_ || taken_ >= passing_ || taken_ > last_) return;
                Slot& slot = slots_[taken_];
                if (slot.error) std::rethrow_exception(slot.error);
                result = std::move(*slot.result);
                slot.result.reset();
            }
            take_(taken_++, std::move(result));
        }
    }

    // Every try stops at its next progress call.
    void stop() { stop_ = true; }

    bool cancelled() const { return cancelled_; }
    std::size_t taken() const { return taken_; }

  private:
    struct Slot {
        std::vector<std::pair<std::string, double>> calls;  // the try's progress calls
        std::size_t passed = 0;                             // of calls, passed on
        std::optional<TryResult> result;
        std::exception_ptr error;
        bool done = false;
    };

    bool wanted(std::size_t i) const { return !stop_ && i <= last_; }

    // Whether try next_ is left to run and may be needed (under mutex_).
    bool claimable() const { return next_ < slots_.size() && wanted(next_); }

    void queue(std::size_t i, std::string_view stage, double fraction) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            slots_[i].calls.emplace_back(std::string(stage), fraction);
        }
        changed_.notify_one();
    }

    // Runs try i and keeps its outcome; a try stopped because the list no longer needs it is
    // dropped.
    void run(std::size_t i, const ProgressFn& progress) {
        std::optional<TryResult> result;
        std::exception_ptr error;
        try {
            result = run_(i, progress);
        } catch (...) {
            error = std::current_exception();
        }
        std::lock_guard<std::mutex> lock(mutex_);
        if (stop_ || i > last_) return;
        Slot& slot = slots_[i];
        if (error || (until_clean_ && result->report.collision_free)) last_ = i;
        slot.result = std::move(result);
        slot.error = error;
        slot.done = true;
    }

    std::vector<Slot> slots_;
    const bool until_clean_;
    const RunTry& run_;
    const TakeTry& take_;
    const ProgressFn& progress_;
    std::mutex mutex_;  // guards slots_, next_, passing_, worker_busy_
    std::condition_variable changed_;
    std::size_t next_ = 0;           // the next try to claim
    std::size_t passing_ = 0;        // the try whose progress calls are passed on
    std::atomic<std::size_t> last_;  // written under mutex_
    std::atomic<bool> stop_{false}, cancelled_{false};
    bool worker_busy_ = false;
    std::size_t taken_ = 0;  // the calling thread's
};

}  // namespace

std::size_t run_try_list(std::size_t count, bool until_clean, bool ahead, const RunTry& run,
                         const TakeTry& take, const ProgressFn& progress) {
    if (count == 0) return 0;
    TryList list(count, until_clean, run, take, progress);
    tbb::task_group group;
    bool spawned = false;
    // On every way out, a throw included, the worker's try stops and is waited for.
    struct Join {
        TryList& list;
        tbb::task_group& group;
        const bool& spawned;
        ~Join() {
            if (!spawned) return;
            list.stop();
            group.wait();
        }
    } join{list, group, spawned};
    for (;;) {
        list.pass_on();
        list.take_done();
        const std::size_t i = list.claim(false);
        if (i == none) break;
        if (!spawned && (ahead || list.taken() > 0) && list.has_unclaimed()) {
            group.run([&list] { list.work(); });
            spawned = true;
        }
        list.run_here(i);
    }
    if (spawned) {
        list.wait_for_worker();
        group.wait();  // the worker's loop ends: nothing is left to claim
    }
    list.pass_on();
    list.take_done();
    if (list.cancelled()) throw Cancelled();
    return list.taken();
}

}  // namespace strata::detail
