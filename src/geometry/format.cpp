#include "strata/core/format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace strata {

// The shortest "%.<p>g" with p >= 6 that reads back as `value`. The shortest round-trip
// digits (std::to_chars) give p: the correctly rounded value at that many digits (or more)
// reads back too, and at fewer none does. (Trying p = 6, 7, ... 17 with snprintf and strtod
// took up to twelve of each a number, most of a large scene's write time.)
std::string format_number(double value) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char shortest[32];
    const auto [end, error] =
        std::to_chars(shortest, shortest + sizeof shortest, value, std::chars_format::scientific);
    int digits = 17;
    if (error == std::errc()) {
        // "-d.ddde+XX": the digits before the exponent.
        digits = 0;
        for (const char* c = shortest; c != end && *c != 'e'; ++c)
            if (*c >= '0' && *c <= '9') ++digits;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 6, 17), value);
    return buf;
}

}  // namespace strata
