#pragma once
/// @file Number formatting for messages and reports (shortest text that reads back exactly).

#include <string>

namespace strata {

/// `value` as the shortest decimal text that parses back to the same double ("nan", "inf"
/// for non-finite values).
std::string format_number(double value);

}  // namespace strata
