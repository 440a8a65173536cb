#include "strata/io/atomic_file.h"

#include "strata/core/error.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <system_error>

namespace strata {

namespace fs = std::filesystem;

std::string read_text_file(const fs::path& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw IoError(path.string() + ": is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw IoError(path.string() + ": cannot open for reading (" + std::strerror(errno) + ")");
    // Sized from the file when it has a size, then read in chunks to its end. (Streaming into an
    // ostringstream copied the text twice, and swallowed an out-of-memory error, leaving a
    // truncated text.)
    std::string text;
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    const auto size = fs::file_size(path, ec);
    if (!ec) text.reserve(static_cast<std::size_t>(size) + kChunk);  // room for the last read
    for (;;) {
        const std::size_t at = text.size();
        text.resize(at + kChunk);
        in.read(&text[at], static_cast<std::streamsize>(kChunk));
        text.resize(at + static_cast<std::size_t>(in.gcount()));
        if (!in) break;
    }
    if (in.bad()) throw IoError(path.string() + ": read failed");
    return text;
}

void write_file_atomic(const fs::path& path, std::string_view content) {
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw IoError(path.string() + ": cannot write, folder '" + dir.string() +
                      "' does not exist");
    std::random_device entropy;
    const fs::path temp =
        dir / ("." + path.filename().string() + ".tmp" + std::to_string(entropy()));
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out)
            throw IoError(path.string() + ": cannot create temporary file '" + temp.string() +
                          "' (" + std::strerror(errno) + ")");
        out.write(content.data(), static_cast<std::streamsize>(content.size()));
        out.flush();
        if (!out) {
            out.close();
            fs::remove(temp, ec);
            throw IoError(path.string() + ": write failed (" + std::strerror(errno) + ")");
        }
    }
    fs::rename(temp, path, ec);
    if (ec) {
        std::error_code ignored;
        fs::remove(temp, ignored);
        throw IoError(path.string() + ": cannot rename the temporary file into place (" +
                      ec.message() + ")");
    }
}

void ensure_not_an_input(const fs::path& output, const std::vector<fs::path>& inputs) {
    for (const fs::path& input : inputs) {
        std::error_code ec;
        if (fs::exists(output, ec) && fs::equivalent(output, input, ec))
            throw InvalidInput(output.string() + ": refusing to overwrite the input file '" +
                               input.string() + "'");
    }
}

}  // namespace strata
