// Reading and checking mesh text before OpenMesh sees it (see mesh_text.h).
#include "io/detail/mesh_text.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <locale>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace strata::detail {

namespace {

struct TextToken {
    std::string text;
    std::size_t line = 0, column = 0;
};

// Whitespace-separated tokens of one line, with their 1-based columns.
std::vector<TextToken> line_tokens(const std::string& line, std::size_t line_number) {
    std::vector<TextToken> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        const std::size_t start = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i > start) out.push_back({line.substr(start, i - start), line_number, start + 1});
    }
    return out;
}

[[noreturn]] void mesh_text_error(const std::filesystem::path& path, const TextToken& at,
                                  const std::string& what) {
    throw InvalidInput(path.string() + ":" + std::to_string(at.line) + ":" +
                       std::to_string(at.column) + ": " + what);
}

// A finite coordinate, or an error naming the token.
double check_coordinate(const std::filesystem::path& path, const TextToken& t) {
    const char* begin = t.text.c_str();
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    // The whole token: an embedded NUL would end the C string early.
    if (end == begin || end != begin + t.text.size())
        mesh_text_error(path, t, "expected a number (got '" + shown_text(t.text) + "')");
    if (!std::isfinite(v))
        mesh_text_error(path, t, "coordinate is not finite (got '" + shown_text(t.text) + "')");
    return v;
}

// An integer token, or an error naming it.
long long integer_token(const std::filesystem::path& path, const TextToken& t,
                        const std::string& text, const char* what) {
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(begin, &end, 10);
    if (end == begin || end != begin + text.size() || errno == ERANGE)
        mesh_text_error(path, t,
                        std::string("expected ") + what + " (got '" + shown_text(t.text) + "')");
    return v;
}

void validate_obj_text(const std::filesystem::path& path, std::istream& in) {
    std::vector<std::vector<TextToken>> faces;
    long long vertices = 0;
    std::string line;
    for (std::size_t n = 1; std::getline(in, line); ++n) {
        auto tokens = line_tokens(line.substr(0, line.find('#')), n);
        if (tokens.empty()) continue;
        if (tokens[0].text == "v") {
            if (tokens.size() < 4) {
                TextToken at = tokens.back();
                at.column += at.text.size();
                mesh_text_error(
                    path, at,
                    "a vertex needs 3 coordinates (got " + std::to_string(tokens.size() - 1) + ")");
            }
            for (std::size_t k = 1; k < 4; ++k) check_coordinate(path, tokens[k]);
            ++vertices;
        } else if (tokens[0].text == "f") {
            tokens.push_back({std::to_string(vertices), n, 0});  // vertices defined so far
            faces.push_back(std::move(tokens));
        }
    }
    for (const auto& face : faces) {
        const long long before = std::stoll(face.back().text);
        for (std::size_t k = 1; k + 1 < face.size(); ++k) {
            const TextToken& t = face[k];
            const long long i =
                integer_token(path, t, t.text.substr(0, t.text.find('/')), "a vertex index");
            const long long resolved = i < 0 ? before + i + 1 : i;
            if (i == 0 || resolved < 1 || resolved > vertices)
                mesh_text_error(path, t,
                                "face names vertex " + std::to_string(i) +
                                    ", which does not exist (" + std::to_string(vertices) +
                                    " vertices)");
        }
    }
}

void validate_stl_text(const std::filesystem::path& path, std::istream& in) {
    std::string line;
    for (std::size_t n = 1; std::getline(in, line); ++n) {
        const auto tokens = line_tokens(line, n);
        if (n == 1 && (tokens.empty() || tokens[0].text != "solid")) return;  // binary STL
        if (tokens.empty() || tokens[0].text != "vertex") continue;
        if (tokens.size() < 4) mesh_text_error(path, tokens[0], "a vertex needs 3 coordinates");
        for (std::size_t k = 1; k < 4; ++k) check_coordinate(path, tokens[k]);
    }
}

// A PLY file's layout as its header declares it.
struct PlyProperty {
    std::string name;
    bool list = false;
    std::string count_type;  // lists only
    std::string type;        // a scalar's type, or a list's item type
};
struct PlyElement {
    std::string name;
    long long count = 0;
    std::vector<PlyProperty> properties;
};
struct PlyLayout {
    bool ascii = true, big_endian = false;
    std::size_t header_lines = 0;
    std::vector<PlyElement> elements;
};

// Bytes of a PLY scalar type (a type the header check accepted).
std::size_t ply_type_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "double" || type == "float64") return 8;
    return 4;
}

// The PLY header, checked line by line before OpenMesh sees it: OpenMesh 9 loops forever on
// some malformed headers (a format line whose version is not a number, found by fuzz_mesh).
// Leaves `in` at the first byte after the end_header line.
PlyLayout validate_ply_header(const std::filesystem::path& path, std::istream& in) {
    static const std::set<std::string> types = {
        "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
        "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
    std::error_code ec;
    const auto file_size = static_cast<long long>(std::filesystem::file_size(path, ec));
    auto check_type = [&](const TextToken& t) {
        if (types.count(t.text) == 0)
            mesh_text_error(path, t, "unknown PLY property type '" + shown_text(t.text) + "'");
    };
    auto expect_count = [&](const std::vector<TextToken>& tokens, std::size_t count,
                            const char* form) {
        if (tokens.size() != count) {
            TextToken at = tokens.back();
            at.column += at.text.size();
            mesh_text_error(path, at, std::string("expected '") + form + "'");
        }
    };
    PlyLayout layout;
    std::string line;
    std::size_t n = 0;
    bool format = false, element = false;
    while (std::getline(in, line)) {
        ++n;
        const auto tokens = line_tokens(line, n);
        if (n == 1) {
            if (tokens.size() != 1 || tokens[0].text != "ply")
                mesh_text_error(path, {tokens.empty() ? "" : tokens[0].text, 1, 1},
                                "not a PLY file: the first line must be 'ply'");
            continue;
        }
        if (tokens.empty()) continue;
        const std::string& key = tokens[0].text;
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            if (!format) mesh_text_error(path, tokens[0], "the PLY header has no format line");
            layout.header_lines = n;
            return layout;
        }
        if (key == "format") {
            expect_count(tokens, 3, "format ascii|binary_little_endian|binary_big_endian 1.0");
            if (tokens[1].text != "ascii" && tokens[1].text != "binary_little_endian" &&
                tokens[1].text != "binary_big_endian")
                mesh_text_error(path, tokens[1],
                                "unknown PLY format '" + shown_text(tokens[1].text) + "'");
            // The only PLY version (OpenMesh allocated 2 GB on "ascii 333...1").
            if (check_coordinate(path, tokens[2]) != 1.0)
                mesh_text_error(
                    path, tokens[2],
                    "unsupported PLY version '" + shown_text(tokens[2].text) + "' (expected 1.0)");
            format = true;
            layout.ascii = tokens[1].text == "ascii";
            layout.big_endian = tokens[1].text == "binary_big_endian";
        } else if (key == "element") {
            expect_count(tokens, 3, "element NAME COUNT");
            element = true;
            const long long count =
                integer_token(path, tokens[2], tokens[2].text, "an element count");
            if (count < 0)
                mesh_text_error(path, tokens[2],
                                "count is negative (got '" + tokens[2].text + "')");
            // Every element takes at least one byte (binary) or one token (ASCII).
            if (count > file_size)
                mesh_text_error(path, tokens[2],
                                "count " + tokens[2].text + " is more than the file holds (" +
                                    std::to_string(file_size) + " bytes)");
            layout.elements.push_back({tokens[1].text, count, {}});
        } else if (key == "property") {
            // OpenMesh dereferences the current element (found by fuzz_mesh: a SEGV).
            if (!element) mesh_text_error(path, tokens[0], "a property before any element line");
            if (tokens.size() >= 2 && tokens[1].text == "list") {
                expect_count(tokens, 5, "property list COUNT_TYPE TYPE NAME");
                check_type(tokens[2]);
                check_type(tokens[3]);
                if (tokens[2].text.find("float") != std::string::npos || tokens[2].text == "double")
                    mesh_text_error(path, tokens[2],
                                    "a list's length type must be an integer type (got '" +
                                        tokens[2].text + "')");
                layout.elements.back().properties.push_back(
                    {tokens[4].text, true, tokens[2].text, tokens[3].text});
            } else {
                expect_count(tokens, 3, "property TYPE NAME");
                check_type(tokens[1]);
                layout.elements.back().properties.push_back(
                    {tokens[2].text, false, "", tokens[1].text});
            }
        } else {
            mesh_text_error(path, tokens[0], "unknown PLY header line '" + shown_text(key) + "'");
        }
    }
    mesh_text_error(path, {"", n, 1}, "the PLY header has no end_header line");
}

// The PLY data walked element by element as `layout` declares it, each list's length checked
// against what the file still holds: OpenMesh reserves a list's declared length before reading
// it (fuzz_mesh: a face of 2^28 indices in a 200-byte file took 1 GB, a face of 10^8 in ASCII
// grew to 2.5 GB). ASCII errors name line and column, binary ones the byte offset.
void validate_ply_body(const std::filesystem::path& path, std::istream& in,
                       const PlyLayout& layout) {
    const std::string what_ends = "the file ends before its data does (";
    auto where = [](const PlyElement& e, long long k, const PlyProperty& p) {
        return "element '" + shown_text(e.name) + "' " + std::to_string(k) + " of " +
               std::to_string(e.count) + ", property '" + shown_text(p.name) + "'";
    };
    if (layout.ascii) {
        std::string line;
        std::vector<TextToken> tokens;
        std::size_t line_number = layout.header_lines, next = 0;
        // The next token, of property p of element e's k-th item (named only on error: this
        // runs once per value of the file).
        auto take = [&](const PlyElement& e, long long k,
                        const PlyProperty& p) -> const TextToken& {
            while (next == tokens.size()) {
                if (!std::getline(in, line))
                    mesh_text_error(path, {"", line_number + 1, 1},
                                    what_ends + where(e, k, p) + ")");
                tokens = line_tokens(line, ++line_number);
                next = 0;
            }
            return tokens[next++];
        };
        for (const PlyElement& e : layout.elements)
            for (long long k = 0; k < e.count; ++k)
                for (const PlyProperty& p : e.properties) {
                    if (!p.list) {
                        take(e, k, p);
                        continue;
                    }
                    const TextToken& t = take(e, k, p);
                    const long long length = integer_token(path, t, t.text, "a list length");
                    if (length < 0)
                        mesh_text_error(path, t, "list length is negative (got '" + t.text + "')");
                    const TextToken at = t;
                    for (long long i = 0; i < length; ++i) {
                        if (next == tokens.size() && in.peek() == EOF)
                            mesh_text_error(path, at,
                                            "list length " + at.text +
                                                " is more than the file holds (" + where(e, k, p) +
                                                ")");
                        take(e, k, p);
                    }
                }
        return;
    }
    std::error_code ec;
    const auto file_size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
    const std::streamoff at = in.tellg();  // -1 when the header is the whole file
    std::uint64_t offset = at < 0 ? file_size : static_cast<std::uint64_t>(at);
    auto fail = [&](const std::string& what) -> void {
        throw InvalidInput(path.string() + ": byte " + std::to_string(offset) + ": " + what);
    };
    for (const PlyElement& e : layout.elements)
        for (long long k = 0; k < e.count; ++k)
            for (const PlyProperty& p : e.properties) {
                const std::uint64_t left = file_size - std::min(offset, file_size);
                if (!p.list) {
                    const std::size_t size = ply_type_size(p.type);
                    if (size > left) fail(what_ends + where(e, k, p) + ")");
                    offset += size;
                    continue;
                }
                const std::size_t size = ply_type_size(p.count_type);
                if (size > left) fail(what_ends + where(e, k, p) + ")");
                unsigned char bytes[8] = {};
                in.seekg(static_cast<std::streamoff>(offset));
                in.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(size));
                std::uint64_t raw = 0;
                for (std::size_t b = 0; b < size; ++b)
                    raw |= std::uint64_t{bytes[layout.big_endian ? size - 1 - b : b]} << (8 * b);
                const bool is_signed = p.count_type[0] != 'u';
                const bool negative = is_signed && (raw >> (8 * size - 1)) != 0;
                if (negative) fail("list length is negative (" + where(e, k, p) + ")");
                const std::uint64_t item = ply_type_size(p.type);
                if (raw > (left - size) / item)
                    fail("list length " + std::to_string(raw) + " is more than the file holds (" +
                         where(e, k, p) + ")");
                offset += size + raw * item;
            }
}

// An OFF header keyword: [ST][C][N][4][n]OFF, each prefix optional, in that order.
bool is_off_magic(std::string_view magic) {
    for (std::string_view prefix : {"ST", "C", "N", "4", "n"})
        if (magic.substr(0, prefix.size()) == prefix) magic.remove_prefix(prefix.size());
    return magic == "OFF";
}

}  // namespace

OffMesh read_off_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(path.string() + ": cannot open mesh");
    std::vector<TextToken> tokens;
    std::string line;
    for (std::size_t n = 1; std::getline(in, line); ++n)
        for (auto& t : line_tokens(line.substr(0, line.find('#')), n))
            tokens.push_back(std::move(t));
    if (tokens.empty()) mesh_text_error(path, {"", 1, 1}, "empty file: expected an OFF header");
    const std::string& magic = tokens[0].text;
    if (!is_off_magic(magic))
        mesh_text_error(path, tokens[0],
                        "not an OFF header (got '" + shown_text(magic) +
                            "'; expected OFF, COFF, NOFF, STOFF ...)");
    if (magic.find('4') != std::string::npos || magic.find('n') != std::string::npos)
        mesh_text_error(path, tokens[0],
                        "'" + magic + "' (vertices of other than 3 coordinates) is not supported");
    if (tokens.size() > 1 && tokens[1].line == tokens[0].line) {
        if (tokens[1].text == "BINARY")
            mesh_text_error(path, tokens[1],
                            "binary OFF is not supported (write it as ASCII OFF, OBJ or PLY)");
        mesh_text_error(path, tokens[1],
                        "the OFF header line must hold only '" + magic +
                            "' (the counts go on the next line; got '" +
                            shown_text(tokens[1].text) + "')");
    }
    std::size_t next = 1;
    auto take = [&](const char* what) -> const TextToken& {
        if (next >= tokens.size()) {
            TextToken at = tokens.back();
            at.column += at.text.size();
            mesh_text_error(path, at, std::string("file ends early: expected ") + what);
        }
        return tokens[next++];
    };
    long long counts[3] = {0, 0, 0};
    for (long long& c : counts) {
        const TextToken& t = take("the vertex, face and edge counts");
        c = integer_token(path, t, t.text, "a count");
        if (c < 0) mesh_text_error(path, t, "count is negative (got '" + t.text + "')");
    }
    // Every vertex and face takes at least one value: a count larger than what is left is
    // refused before anything is reserved.
    const auto left = static_cast<long long>(tokens.size() - next);
    for (int k = 0; k < 2; ++k)
        if (counts[k] > left) {
            const TextToken& at = tokens[next - 3 + static_cast<std::size_t>(k)];
            mesh_text_error(path, at,
                            "count " + at.text + " is more than the file holds (" +
                                std::to_string(left) + " values follow the counts)");
        }
    const bool plain = magic == "OFF";
    OffMesh out;
    out.vertices.reserve(static_cast<std::size_t>(counts[0]));
    out.polygons.reserve(static_cast<std::size_t>(counts[1]));
    // The tokens of the line that starts at `next` (a variant's vertex or face line).
    auto line_end = [&] {
        std::size_t end = next;
        while (end < tokens.size() && tokens[end].line == tokens[next].line) ++end;
        return end;
    };
    for (long long v = 0; v < counts[0]; ++v) {
        const std::size_t end = plain || next >= tokens.size() ? 0 : line_end();
        if (!plain && next < tokens.size() && end - next < 3)
            mesh_text_error(path, tokens[next], "a vertex line needs 3 coordinates");
        glm::dvec3 p;
        for (int k = 0; k < 3; ++k) p[k] = check_coordinate(path, take("a vertex coordinate"));
        if (!plain) next = end;  // colour, normal, texture coordinates
        out.vertices.push_back(p);
    }
    for (long long f = 0; f < counts[1]; ++f) {
        const TextToken& ct = take("a face");
        const std::size_t face_line = ct.line;
        const long long size = integer_token(path, ct, ct.text, "a face size");
        if (size < 0) mesh_text_error(path, ct, "face size is negative (got '" + ct.text + "')");
        std::size_t on_line = 0;
        for (std::size_t k = next; k < tokens.size() && tokens[k].line == face_line; ++k) ++on_line;
        if ((plain && size > static_cast<long long>(tokens.size() - next)) ||
            (!plain && size > static_cast<long long>(on_line)))
            mesh_text_error(path, ct,
                            "face size " + ct.text + " is more than the " +
                                (plain ? "file" : "line") + " holds (" +
                                std::to_string(plain ? tokens.size() - next : on_line) +
                                " values follow)");
        std::vector<std::uint32_t> polygon;
        polygon.reserve(static_cast<std::size_t>(size));
        for (long long k = 0; k < size; ++k) {
            const TextToken& t = take("a face vertex index");
            const long long i = integer_token(path, t, t.text, "a vertex index");
            if (i < 0 || i >= counts[0])
                mesh_text_error(path, t,
                                "face names vertex " + std::to_string(i) +
                                    ", which does not exist (" + std::to_string(counts[0]) +
                                    " vertices)");
            polygon.push_back(static_cast<std::uint32_t>(i));
        }
        while (next < tokens.size() && tokens[next].line == face_line) ++next;  // face colour
        out.polygons.push_back(std::move(polygon));
    }
    return out;
}

void validate_mesh_text(const std::filesystem::path& path, const std::string& ext) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return;
    if (ext == ".obj")
        validate_obj_text(path, in);
    else if (ext == ".stl")
        validate_stl_text(path, in);
    else if (ext == ".ply")
        validate_ply_body(path, in, validate_ply_header(path, in));
}

// The vertex coordinates of an ASCII OBJ file in double precision, in file order; nothing for
// other formats or anything unexpected (OpenMesh's values are kept then).
std::optional<std::vector<glm::dvec3>> read_ascii_vertices(const std::filesystem::path& path,
                                                           const std::string& ext) {
    if (ext != ".obj") return std::nullopt;
    std::ifstream in(path);
    if (!in) return std::nullopt;
    std::vector<glm::dvec3> out;
    std::string line;
    while (std::getline(in, line)) {
        if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
        std::istringstream ls(line.substr(2));
        ls.imbue(std::locale::classic());
        glm::dvec3 v;
        if (!(ls >> v.x >> v.y >> v.z)) return std::nullopt;
        out.push_back(v);
    }
    return out;
}

}  // namespace strata::detail
