#pragma once
/// @file Formatting for messages and reports: numbers as the shortest text that reads back
/// exactly, and text from input files shown safely.

#include <cstddef>
#include <string>
#include <string_view>

namespace strata {

/// `value` as the shortest decimal text that parses back to the same double ("nan", "inf"
/// for non-finite values).
std::string format_number(double value);

/// `text` (a name or an excerpt of an input file) as a one-line message shows it: printable
/// ASCII and well-formed UTF-8 characters as they are; every other byte (controls, DEL, C1
/// controls, bytes of no valid sequence) as \xNN and a backslash as \\, so that a control or
/// binary byte can neither cut, colour nor garble the message. At most `max_chars` characters
/// of `text` are shown, followed by "..." when there are more.
std::string shown_text(std::string_view text, std::size_t max_chars = 40);

}  // namespace strata
