// Fuzz target: the slicer (make_slice_mesh, section_mesh, weld_section, nest_layers through
// slice_meshes) on small generated meshes: vertices on a coarse grid (so that vertices lie on
// the planes and triangles are degenerate) or anywhere, random polygons, random planes and
// parameters. Valid parameters and a valid mesh never throw, pieces are well formed, and
// every slice is a valid scene (slice_meshes builds it, so the nesting has no cycle).
#include "byte_reader.h"
#include "check.h"
#include "strata/core/error.h"
#include "strata/io/mesh_slice.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace {

double coordinate(strata::fuzz::ByteReader& in, bool fine) {
    const double grid = (static_cast<double>(in.byte()) - 128.0) / 16.0;
    return fine ? grid + static_cast<double>(in.byte()) / 4096.0 : grid;
}

std::optional<strata::SliceMesh> make_mesh(strata::fuzz::ByteReader& in, const std::string& name) {
    const bool fine = in.boolean();
    const std::size_t n = in.range(3, 48);
    std::vector<glm::dvec3> vertices;
    for (std::size_t i = 0; i < n; ++i) {
        const double x = coordinate(in, fine), y = coordinate(in, fine), z = coordinate(in, fine);
        vertices.emplace_back(x, y, z);
    }
    const std::size_t faces = in.range(1, 80);
    std::vector<std::vector<std::uint32_t>> polygons;
    for (std::size_t f = 0; f < faces && !in.empty(); ++f) {
        const std::size_t corners = in.range(3, 5);
        std::vector<std::uint32_t> polygon;
        for (std::size_t c = 0; c < corners; ++c)
            polygon.push_back(static_cast<std::uint32_t>(in.range(0, n - 1)));
        polygons.push_back(std::move(polygon));
    }
    try {
        return strata::make_slice_mesh(name, std::move(vertices), polygons);
    } catch (const strata::InvalidInput&) {
        return std::nullopt;
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    strata::fuzz::ByteReader in(data, size);
    strata::SliceParams params;
    params.axis = static_cast<strata::Axis>(in.range(0, 2));
    const std::size_t planes = in.range(1, 3);
    for (std::size_t i = 0; i < planes; ++i)
        params.heights.push_back((static_cast<double>(in.byte()) - 128.0) / 16.0 +
                                 (in.boolean() ? 0.0 : static_cast<double>(in.byte()) / 512.0));
    params.split_components = in.boolean();
    params.weld.enabled = in.byte() % 4 != 0;
    params.weld.tolerance = in.boolean() ? 0.0 : in.unit();
    params.weld.overlap_segments = static_cast<int>(in.range(0, 4));
    params.nesting.distance = in.boolean() ? 0.0 : in.unit() * 4.0;
    params.nesting.coverage = 0.05 + 0.95 * in.unit();
    params.thickness = in.boolean() ? 0.0 : in.unit() * 0.1;

    std::vector<strata::SliceMesh> meshes;
    const std::size_t count = in.range(1, 2);
    for (std::size_t m = 0; m < count; ++m) {
        std::optional<strata::SliceMesh> mesh = make_mesh(in, m == 0 ? "body" : "shirt");
        if (!mesh) return 0;
        meshes.push_back(std::move(*mesh));
    }
    if (count == 2 && in.boolean()) params.order = {"shirt", "body"};

    // The chain by hand for the first mesh (every piece well formed) ...
    const strata::SliceMesh& first = meshes.front();
    strata::MeshSection section = strata::section_mesh(first, params.axis, params.heights[0]);
    strata::weld_section(section, strata::median_edge_length(first), params.weld);
    for (const strata::SectionPiece& piece : section.pieces) {
        FUZZ_CHECK(piece.points.size() >= (piece.closed ? 3U : 2U), "a piece too short");
        for (std::size_t k = 0; k + 1 < piece.points.size(); ++k)
            FUZZ_CHECK(piece.points[k] != piece.points[k + 1], "repeated consecutive point");
        if (piece.closed)
            FUZZ_CHECK(piece.points.front() != piece.points.back(),
                       "closed piece repeats its start");
        for (const strata::Vec2& p : piece.points)
            FUZZ_CHECK(std::isfinite(p.x) && std::isfinite(p.y), "a section point is not finite");
    }
    // ... then the whole of slice_meshes(): valid params and meshes never throw.
    try {
        const strata::SliceReport report = strata::slice_meshes(meshes, params);
        FUZZ_CHECK(report.slices.size() == params.heights.size(), "one slice per height");
        for (const strata::PlaneSlice& s : report.slices)
            if (s.scene)
                FUZZ_CHECK(s.scene->size() == s.closed_layers + s.open_layers,
                           "layer counts disagree");
    } catch (const strata::InvalidInput& e) {
        std::fprintf(stderr, "slice_meshes threw: %s\n", e.what());
        FUZZ_CHECK(false, "slice_meshes refused valid meshes and parameters");
    }
    return 0;
}
