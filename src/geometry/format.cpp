#include "strata/core/format.h"

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
// (no overlong form, no surrogate, at most U+10FFFF, not a C1 control); 0 when there is none.
std::size_t printable_utf8_length(std::string_view text) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
    const unsigned char lead = byte(0);
    std::size_t length = 0;
    char32_t code = 0;
    if (lead >= 0xc2 && lead <= 0xdf) {
        length = 2;
        code = lead & 0x1fu;
    } else if (lead >= 0xe0 && lead <= 0xef) {
        length = 3;
        code = lead & 0x0fu;
    } else if (lead >= 0xf0 && lead <= 0xf4) {
        length = 4;
        code = lead & 0x07u;
    } else {
        return 0;
    }
    if (text.size() < length) return 0;
    for (std::size_t i = 1; i < length; ++i) {
        if ((byte(i) & 0xc0u) != 0x80u) return 0;
        code = (code << 6) | (byte(i) & 0x3fu);
    }
    const char32_t smallest = length == 2 ? 0x80 : length == 3 ? 0x800 : 0x10000;
    if (code < smallest || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return 0;
    if (code < 0xa0) return 0;  // C1 controls
    return length;
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
