#include "strata/field/field.h"
#include "strata/field/vdb_io.h"
#include "support/fixtures.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>

using namespace strata;

namespace {

// Every grid of the .vdb file at `path`, read with OpenVDB's own reader.
openvdb::GridPtrVecPtr read_grids(const std::filesystem::path& path) {
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.open();
    openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    return grids;
}

}  // namespace

TEST_CASE("write_vdb writes one grid per layer that OpenVDB reads back", "[field][io]") {
    const Scene scene = test::nested_circles(2, 128);
    const SceneFields fields(scene);
    const auto path = std::filesystem::temp_directory_path() / "strata_test_fields.vdb";
    write_vdb(scene, fields, path);
    const openvdb::GridPtrVecPtr grids = read_grids(path);
    REQUIRE(grids->size() == 2);
    for (std::size_t i = 0; i < 2; ++i) {
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids)[i]);
        REQUIRE(grid);
        CHECK(grid->getName() == scene.layer(i).name);
        CHECK(grid->getGridClass() == openvdb::GRID_LEVEL_SET);
        CHECK(grid->metaValue<double>("strata_voxel_size") == fields.params().voxel_size);
        CHECK(grid->metaValue<double>("strata_band_width") == fields.params().band_width);
        CHECK(grid->voxelSize()[0] == Approx(fields.params().voxel_size));
        CHECK(grid->activeVoxelCount() == fields.field(i).stats().active_voxels);
        // Far inside the inner circle: the flood-filled tile value is -band.
        const float centre = grid->tree().getValue(openvdb::Coord(0, 0, 0));
        CHECK(centre < 0.f);
    }
    if (std::system("command -v vdb_print > /dev/null 2>&1") == 0) {
        const std::string cmd = "vdb_print '" + path.string() + "' > /dev/null 2>&1";
        CHECK(std::system(cmd.c_str()) == 0);
    }
    std::filesystem::remove(path);
}

TEST_CASE("write_vdb extracts every layer of a 9-layer stacked grid as a z = 0 slab",
          "[field][io]") {
    // Layers closer than the band share leaves; layer 8 lies in the second leaf row (z >= 8).
    const Scene scene = test::nested_circles(9, 96, 1.0, 0.02);
    const SceneFields fields(scene);
    const auto path = std::filesystem::temp_directory_path() / "strata_test_fields9.vdb";
    write_vdb(scene, fields, path);
    const openvdb::GridPtrVecPtr grids = read_grids(path);
    std::filesystem::remove(path);
    REQUIRE(grids->size() == 9);
    const double h = fields.params().voxel_size;
    for (std::size_t i = 0; i < 9; ++i) {
        INFO("layer " << i);
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids)[i]);
        REQUIRE(grid);
        CHECK(grid->getName() == scene.layer(i).name);
        const FieldStats st = fields.field(i).stats();
        CHECK(grid->activeVoxelCount() == st.active_voxels);
        CHECK(grid->tree().leafCount() == st.leaves);
        const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
        CHECK(bb.min().z() == 0);
        CHECK(bb.max().z() == 0);
        // Band voxels hold the field's values; the centre is inside every circle.
        std::size_t checked = 0;
        openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
        for (std::size_t k = 0; k < scene.layer(i).points.size(); ++k) {
            const Vec2 p = scene.layer(i).points[k];
            const openvdb::Coord c(static_cast<int>(std::lround(p.x / h)),
                                   static_cast<int>(std::lround(p.y / h)), 0);
            float v = 0.f;
            if (!acc.probeValue(c, v)) continue;
            ++checked;
            // At the voxel centre (x / h is c up to rounding): the stored value.
            CHECK(static_cast<double>(v) ==
                  Approx(fields.field(i).sample(Vec2(c.x() * h, c.y() * h)).value)
                      .margin(1e-9 * fields.params().band_width));
        }
        CHECK(checked == scene.layer(i).points.size());
        CHECK(grid->tree().getValue(openvdb::Coord(0, 0, 0)) < 0.f);
    }
}
