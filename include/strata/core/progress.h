#pragma once
/// @file Progress reporting: one callback, polled by long-running library calls.

#include <functional>
#include <string_view>

namespace strata {

/// Called with the current stage name and its completed fraction in [0, 1].
/// Returning false cancels the operation, which then throws strata::Cancelled.
using ProgressFn = std::function<bool(std::string_view stage, double fraction)>;

}  // namespace strata
