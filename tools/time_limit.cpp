#include "time_limit.h"

#include "strata/core/format.h"

#include <cmath>
#include <exception>
#include <utility>

namespace strata::cli {

TimeLimit::TimeLimit(double seconds)
    : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}

ProgressFn TimeLimit::around(ProgressFn inner) const {
    if (!(seconds_ > 0.0)) return inner;
    return [limit = *this, inner = std::move(inner)](std::string_view stage, double fraction) {
        if (limit.is_past()) return false;
        return inner ? inner(stage, fraction) : true;
    };
}

bool TimeLimit::is_past() const {
    // Compared in double seconds: a huge limit (1e300) never overflows a clock duration.
    return seconds_ > 0.0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() >=
               seconds_;
}

std::string TimeLimit::message(const std::string& input) const {
    return input + ": not done within the time limit of " + format_number(seconds_) +
           " s (--time-limit); nothing written";
}

void add_time_limit_option(CLI::App& cmd, double& seconds, const std::string& what) {
    const CLI::Validator non_negative(
        [](std::string& value) -> std::string {
            std::size_t used = 0;
            double v = -1.0;
            try {
                v = std::stod(value, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (value.empty() || used != value.size() || !std::isfinite(v) || v < 0.0)
                return "must be a number of seconds >= 0 (got " + value + ")";
            return std::string();
        },
        "SECONDS>=0");
    cmd.add_option("--time-limit", seconds,
                   "Seconds " + what +
                       " may take (0: no limit); past it, it stops with exit 1 and writes nothing")
        ->check(non_negative)
        ->capture_default_str();
}

}  // namespace strata::cli
