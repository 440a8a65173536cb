#pragma once
// One UTF-8 character decoded from the start of a text: the one decoder of shown_text()
// (format.cpp) and of the SVG writer's test for what XML can hold (svg_io.cpp). Internal.

#include <cstddef>
#include <string_view>

namespace strata::detail {

/// A character decoded by utf8_char(): its code point and its length in bytes (0: the text
/// does not start with a well-formed multi-byte sequence).
struct Utf8Char {
    char32_t code = 0;
    std::size_t length = 0;
};

/// The well-formed multi-byte UTF-8 sequence at the start of `text` (no overlong form, no
/// surrogate, at most U+10FFFF); length 0 when there is none, or when the first byte is ASCII.
inline Utf8Char utf8_char(std::string_view text) {
    if (text.empty()) return {};
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
        return {};
    }
    if (text.size() < length) return {};
    for (std::size_t i = 1; i < length; ++i) {
        if ((byte(i) & 0xc0u) != 0x80u) return {};
        code = (code << 6) | (byte(i) & 0x3fu);
    }
    const char32_t smallest = length == 2 ? 0x80 : length == 3 ? 0x800 : 0x10000;
    if (code < smallest || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return {};
    return {code, length};
}

}  // namespace strata::detail
