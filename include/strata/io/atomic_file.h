#pragma once
/// @file Whole-file reading and atomic writing.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace strata {

/// Reads a whole file. @throws IoError naming the file and the reason.
std::string read_text_file(const std::filesystem::path& path);

/// Writes `content` to a temporary file beside `path`, then renames it over `path`, so that
/// `path` is either untouched or complete. @throws IoError naming the file and the reason
/// (the temporary file is removed then).
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

/// @throws InvalidInput when `output` names the same file as one of `inputs` (so that an
/// input is never overwritten).
void ensure_not_an_input(const std::filesystem::path& output,
                         const std::vector<std::filesystem::path>& inputs);

}  // namespace strata
