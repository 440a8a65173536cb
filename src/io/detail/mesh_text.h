// Mesh text read and checked by strata itself, before or instead of OpenMesh: OpenMesh drops a
// face with a bad index and keeps NaN coordinates silently (the cause, "the mesh has no faces",
// would be lost), trusts the counts and list lengths of a file (the fuzzer found files of under
// 200 bytes that made it reserve 1 to 45 GB) and loops forever on some malformed PLY headers.
// Errors name the file with line and column (byte offset in binary PLY).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace strata::detail {

// An OFF file's vertices and faces (indices checked against the vertex count).
struct OffMesh {
    std::vector<glm::dvec3> vertices;
    std::vector<std::vector<std::uint32_t>> polygons;
};

// An OFF file read by strata itself. Plain OFF is read as a stream of tokens; a variant (COFF,
// NOFF, STOFF, CNOFF ...) one vertex and one face a line, the position being the first three
// numbers of a vertex line (colours, normals and texture coordinates follow it) and a face's
// colour what follows its indices. Throws IoError (cannot open) or InvalidInput.
OffMesh read_off_text(const std::filesystem::path& path);

// Refuses, with InvalidInput, non-finite coordinates and faces naming missing vertices in OBJ and
// ASCII STL files, and malformed PLY headers and list lengths longer than the rest of the file.
// `ext` is the lower-case extension (".obj", ".stl", ".ply"); other formats pass. The rest is
// left to OpenMesh.
void validate_mesh_text(const std::filesystem::path& path, const std::string& ext);

// The vertex coordinates of an ASCII OBJ file in double precision, in file order (OpenMesh reads
// them as float); nothing for other formats or anything unexpected.
std::optional<std::vector<glm::dvec3>> read_ascii_vertices(const std::filesystem::path& path,
                                                           const std::string& ext);

}  // namespace strata::detail
