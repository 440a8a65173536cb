#pragma once
/// @file What `strata simplify` does to one scene and to each slice of a batch, and the batch
/// summary table, shared by the CLI (tools/cmd_simplify.cpp) and the Python package's
/// strata.batch (python/src/module.cpp): both print the same table.

#include "strata/core/progress.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace strata::cli {

/// What to do with an input that already crosses (or breaks its nesting).
enum class InputCrossings { Untangle, Skip, Fail };

/// Everything `strata simplify` was asked on its command line.
struct SimplifyOptions {
    std::vector<std::string> inputs;
    std::string output, svg, report;
    double thickness = 0.0;
    int threads = 0;
    bool no_shape_matching = false;
    bool no_finish = false;
    bool naive = false;
    bool compare_naive = false;  ///< Also run the naive decimation, for the numbers.
    /// Seconds one input may take (`--time-limit`; 0: none): past it, its untangling or
    /// simplification stops (TimeLimitReached; a slice of a batch fails, the others go on).
    double time_limit = 0.0;
    InputCrossings input_crossings = InputCrossings::Untangle;
    SimplifyParams params;
};

/// What was done to an input that already crossed before it was simplified.
struct InputUntangling {
    std::size_t crossings = 0, nesting_violations = 0;  ///< Of the input.
    /// untangle_inferring_sides()'s (report.inferred_sides: the input's rolled regions kept).
    UntangleReport report;
};

/// The outcome of one scene (one slice of a batch).
struct Outcome {
    std::string input, output;
    std::optional<SimplifyReport> report, naive;
    std::optional<InputUntangling> untangled;  ///< The input crossed and was untangled first.
    bool skipped = false;                      ///< The input crossed (--input-crossings skip).
    std::string error;                         ///< Non-empty: failed, nothing written.
};

/// `v`, or null when not finite.
nlohmann::json finite_or_null(double v);
/// The JSON report of one simplification (`--report`).
nlohmann::json report_json(const SimplifyReport& r, const SimplifyReport* naive);
nlohmann::json untangling_json(const InputUntangling& u);
/// Peak resident memory of this process so far, MiB (getrusage).
double peak_memory_mib();
/// Largest per-layer Hausdorff distance of `r`.
double max_hausdorff(const SimplifyReport& r);

/// One line on what is wrong with `check` (an input's), naming the first culprit.
std::string tangle_summary(const Scene& scene, const CheckReport& check);

/// Simplification keeps a collision-free scene so. An input that already crosses is untangled
/// first (InputCrossings::Untangle: the global untangling, which cannot mend a layer that
/// crosses itself; `progress` false cancels it: Cancelled), or refused (Fail: InvalidInput;
/// Skip: std::nullopt).
std::optional<Scene> prepare_input(const Scene& input, const std::string& name, InputCrossings mode,
                                   const SimplifyParams& params,
                                   std::optional<InputUntangling>& untangled,
                                   const ProgressFn& progress = {});

/// Simplifies one scene; the naive run (no untangling) is made beside it when asked for.
Outcome run_one(const Scene& input, const SimplifyOptions& opt, const ProgressFn& progress,
                Scene& result, Scene* naive_result);

/// The files of `inputs`: a folder stands for its .json and .svg files, sorted by name.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs);

/// Where a batch writes `input`: FOLDER/<stem>.json.
std::string batch_output(const std::string& folder, const std::string& input);

/// One slice of a batch: reads `input` (with opt.thickness), prepares it (opt.input_crossings),
/// simplifies it and writes `output` atomically, within opt.time_limit from its start. Never
/// throws: a failure is Outcome::error.
Outcome simplify_slice(const std::string& input, const std::string& output,
                       const SimplifyOptions& opt);

/// Counts over the slices of a batch.
struct BatchTotals {
    std::size_t slices = 0, failed = 0, skipped = 0, untangled = 0, tangled = 0;
    void add(const Outcome& o);
    /// 0 when every slice was simplified collision-free, else 1.
    int exit_code() const { return failed == 0 && tangled == 0 && skipped == 0 ? 0 : 1; }
};

/// The batch table: its header line, one line per slice and the closing line (each with
/// its '\n').
std::string batch_header();
std::string batch_row(const Outcome& o);
std::string batch_footer(const BatchTotals& totals, double peak_memory_mib);
/// The `--report` entry of one slice of a batch.
nlohmann::json batch_entry(const Outcome& o);

}  // namespace strata::cli
