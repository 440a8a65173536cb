#include "strata/core/format.h"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <limits>
#include <string>

using namespace strata;

TEST_CASE("format_number gives the shortest text that reads back exactly", "[format]") {
    for (const double v :
         {0.1, 1.0 / 3.0, -2.5e-300, 6.02214076e23, 0.3, 1e21, 123456789.0,
          std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max()}) {
        const std::string text = format_number(v);
        CHECK(std::strtod(text.c_str(), nullptr) == v);
    }
    CHECK(format_number(0.1) == "0.1");
    CHECK(format_number(std::numeric_limits<double>::quiet_NaN()) == "nan");
    CHECK(format_number(-std::numeric_limits<double>::infinity()) == "-inf");
}

TEST_CASE("shown_text keeps printable text and shows every other byte as \\xNN", "[format]") {
    CHECK(shown_text("sleeve_2") == "sleeve_2");
    CHECK(shown_text("\xc3\xa4rmel \xe2\x86\x92 \xf0\x9f\xa7\xa5") ==
          "\xc3\xa4rmel \xe2\x86\x92 \xf0\x9f\xa7\xa5");  // ärmel → 🧥: well-formed UTF-8
    // A terminal colour escape, a NUL, DEL and a tab.
    CHECK(shown_text(std::string("a\x1b[31mb\0c\x7f\t", 11)) == "a\\x1b[31mb\\x00c\\x7f\\x09");
    // Bytes of no valid UTF-8 sequence: a lone continuation byte, a truncated sequence, an
    // overlong '/', a surrogate, a C1 control (U+009B, the byte a fuzzed SVG id held).
    CHECK(shown_text("\x9b") == "\\x9b");
    CHECK(shown_text("x\xe2\x86") == "x\\xe2\\x86");
    CHECK(shown_text("\xc0\xaf") == "\\xc0\\xaf");
    CHECK(shown_text("\xed\xa0\x80") == "\\xed\\xa0\\x80");
    CHECK(shown_text("\xc2\x9b") == "\\xc2\\x9b");
    // A backslash is doubled, so a shown \xNN always stands for one byte.
    CHECK(shown_text("a\\x41") == "a\\\\x41");
    // At most max_chars characters (a UTF-8 character counts once), then "...".
    CHECK(shown_text("abcdef", 3) == "abc...");
    CHECK(shown_text("abc", 3) == "abc");
    CHECK(shown_text("\xc3\xa4\xc3\xa4\xc3\xa4", 2) == "\xc3\xa4\xc3\xa4...");
    CHECK(shown_text("") == "");
}
