#pragma once
/// @file The untangling jobs of the simplification driver: prepare() cuts the region around a
/// removal out of the live polylines into a work scene (runs of every layer near it, their
/// vertices in the region free), execute() runs the untangling engine on it with the exact
/// local check, apply() moves the live vertices to where a successful job put them. Jobs of
/// one batch are prepared and applied one after another and executed side by side. Private to
/// src/simplify.

#include "simplify/detail/live_polylines.h"
#include "simplify/detail/local_check.h"
#include "simplify/detail/separations.h"
#include "simplify/detail/untangle_job.h"
#include "strata/geometry/input_sides.h"
#include "strata/simplify/simplify.h"
#include "untangle/detail/engine.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace strata::detail {

class JobRunner {
  public:
    /// `settings`: resolved for `input` (resolve_settings()); `sides`: the input's sides
    /// (record_input_sides(input)), which each job's untangling keeps. Keeps references to
    /// every argument.
    JobRunner(const Scene& input, const SimplifyParams& params, const EngineSettings& settings,
              LivePolylines& live, const Separations& separations, const LocalCheck& check,
              const InputSides& sides);

    enum class Prepared { Ready, Conflict, Refused };

    /// The work scene of the untangling after removing job.v (already unlinked): runs of every
    /// layer through the segments near the removal, their vertices in the region free.
    /// Conflict: it would share vertices with, or come within reach of, one of `waiting`
    /// (jobs prepared and not yet applied). Refused: the work scene would merge vertices.
    Prepared prepare(Job& job, const std::vector<Job>& waiting);
    /// Runs the job's untangling, checking its region exactly after every projection step.
    /// Reads the live polylines and writes only to `job`: jobs run side by side.
    void execute(Job& job) const;
    /// Moves the job's free vertices to where its untangling put them.
    void apply(const Job& job);

  private:
    void local_sides(Job& job) const;
    /// Keeps the removal of a rolled job by moving its chord's two ends toward the removed
    /// vertex, out of the layers the chord came too close to, when `is_ok` passes and the shape
    /// error stays within bounds (`within_bound`, execute()): true, the work scene moved; false, it
    /// is as it was.
    bool shift_chord(Job& job, const std::function<bool(const Scene&)>& is_ok,
                     const std::function<bool()>& within_bound) const;
    /// Local symmetric Hausdorff distance of layer k around its alive vertex x to the input
    /// (positions by `at(layer, id)`), scene units.
    template <typename At>
    double shape_error(std::size_t k, std::size_t x, At&& at) const;
    /// The largest shape_error() over the job's free vertices, before it ran or after.
    double job_shape_error(const Job& job, bool after) const;
    /// The largest shape_error() over the alive vertices of the job's layers, live positions.
    double layers_shape_error(const Job& job) const;
    void mark(std::size_t k, std::size_t v, std::vector<std::size_t>& marked,
              const std::vector<Job>& waiting);
    bool is_marked(std::size_t k, std::size_t v) const {
        return v != kNone && slots_.mark[k][v] == mark_counter_;
    }
    void runs_of(std::size_t k, std::vector<std::size_t>& marked, const std::vector<Job>& waiting,
                 std::vector<Run>& out);

    const Scene& input_;
    const SimplifyParams& params_;
    const EngineSettings& settings_;
    LivePolylines& live_;
    const Separations& separations_;
    const LocalCheck& check_;
    const InputSides& sides_;
    JobSlots slots_;
    std::uint32_t mark_counter_ = 0;  // stamp of the job being prepared
    bool conflict_ = false;           // prepare() met a waiting job
};

}  // namespace strata::detail
