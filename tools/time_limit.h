#pragma once
/// @file `--time-limit`: how long `strata untangle` may take, or `strata simplify` on one input
/// (each slice of a batch on its own clock).

#include "strata/core/error.h"
#include "strata/core/progress.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <stdexcept>
#include <string>

namespace strata::cli {

/// A run stopped at its time limit; main() prints it and exits 1 (nothing is written).
class TimeLimitReached : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// A time limit of `seconds` (0: none) from construction.
class TimeLimit {
  public:
    explicit TimeLimit(double seconds);

    /// `inner` (possibly empty), but false once the limit is past: the library then stops at
    /// its next progress call (an untangling round, each percent of a simplification's
    /// removals) and throws Cancelled, its input unchanged.
    ProgressFn around(ProgressFn inner) const;

    /// True when a limit is set and past.
    bool is_past() const;

    /// "IN: not done within the time limit of S s (--time-limit); nothing written".
    std::string message(const std::string& input) const;

    /// run(), whose Cancelled, once the limit is past, becomes TimeLimitReached(message(input)).
    template <class F>
    auto guard(const std::string& input, F&& run) const -> decltype(run()) {
        try {
            return run();
        } catch (const Cancelled&) {
            if (is_past()) throw TimeLimitReached(message(input));
            throw;
        }
    }

  private:
    double seconds_ = 0.0;
    std::chrono::steady_clock::time_point start_;
};

/// Adds `--time-limit SECONDS` (a finite number >= 0; 0, the default: none) bound to `seconds`.
void add_time_limit_option(CLI::App& cmd, double& seconds, const std::string& what);

}  // namespace strata::cli
