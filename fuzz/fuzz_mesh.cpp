// Fuzz target: the mesh reader (read_slice_mesh: OBJ, OFF, PLY, STL through OpenMesh, and the
// double-precision re-read of OBJ and OFF). The first byte picks the extension, the rest is
// the file. A file either reads or throws IoError / InvalidInput; a mesh read is well formed
// (finite vertices, indices in range) and slices without crashing.
#include "check.h"
#include "strata/core/error.h"
#include "strata/io/mesh_slice.h"

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

const std::filesystem::path& temp_dir() {
    static const std::filesystem::path dir = [] {
        std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("strata-fuzz-mesh-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    static const char* const extensions[] = {".obj", ".off", ".ply", ".stl"};
    const std::filesystem::path path = temp_dir() / (std::string("m") + extensions[data[0] % 4]);
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
    }
    strata::SliceMesh mesh;
    try {
        mesh = strata::read_slice_mesh(path, "fuzz");
    } catch (const strata::IoError&) {
        return 0;
    } catch (const strata::InvalidInput&) {
        return 0;
    }
    FUZZ_CHECK(!mesh.triangles.empty(), "a mesh read without error has no triangles");
    FUZZ_CHECK(mesh.component.size() == mesh.triangles.size(), "one component per triangle");
    for (const glm::dvec3& v : mesh.vertices)
        FUZZ_CHECK(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                   "a vertex read is not finite");
    for (const auto& t : mesh.triangles)
        for (std::uint32_t i : t) FUZZ_CHECK(i < mesh.vertices.size(), "index out of range");
    for (std::uint32_t c : mesh.component)
        FUZZ_CHECK(c < mesh.component_count, "component out of range");
    const auto box = mesh.bounds();
    const glm::dvec3 mid = 0.5 * box[0] + 0.5 * box[1];
    for (strata::Axis axis : {strata::Axis::X, strata::Axis::Y, strata::Axis::Z}) {
        const double h = axis == strata::Axis::X ? mid.x : axis == strata::Axis::Y ? mid.y : mid.z;
        strata::MeshSection section = strata::section_mesh(mesh, axis, h);
        strata::weld_section(section, strata::median_edge_length(mesh));
        for (const strata::SectionPiece& piece : section.pieces) {
            FUZZ_CHECK(piece.points.size() >= (piece.closed ? 3U : 2U), "a piece too short");
            for (std::size_t k = 0; k + 1 < piece.points.size(); ++k)
                FUZZ_CHECK(piece.points[k] != piece.points[k + 1], "repeated consecutive point");
        }
    }
    return 0;
}
