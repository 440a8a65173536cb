#include "strata/core/format.h"

#include "geometry/detail/utf8.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
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

namespace {

// The length of the well-formed UTF-8 sequence of a printable character at the start of `text`
// (detail::utf8_char(), not a C1 control); 0 when there is none.
std::size_t printable_utf8_length(std::string_view text) {
    const detail::Utf8Char c = detail::utf8_char(text);
    return c.code < 0xa0 ? 0 : c.length;  // C1 controls
}

}  // namespace

std::string shown_text(std::string_view text, std::size_t max_chars) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    std::size_t i = 0, shown = 0;
    for (; i < text.size() && shown < max_chars; ++shown) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '\\') {
            out += "\\\\";
            ++i;
        } else if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
            ++i;
        } else if (const std::size_t n = printable_utf8_length(text.substr(i)); n > 0) {
            out.append(text.substr(i, n));
            i += n;
        } else {
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15u];
            ++i;
        }
    }
    if (i < text.size()) out += "...";
    return out;
}

}  // namespace strata
