#include "strata/io/atomic_file.h"

#include "strata/core/error.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

namespace strata {

namespace fs = std::filesystem;

std::string read_text_file(const fs::path& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw IoError(path.string() + ": is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw IoError(path.string() + ": cannot open for reading (" + std::strerror(errno) + ")");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw IoError(path.string() + ": read failed");
    return buffer.str();
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
