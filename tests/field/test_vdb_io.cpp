#include "strata/field/field.h"
#include "strata/field/vdb_io.h"
#include "support/fixtures.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>

using namespace strata;

TEST_CASE("write_vdb writes one grid per layer that OpenVDB reads back", "[field][io]") {
    const Scene scene = test::nested_circles(2, 128);
    const SceneFields fields(scene);
    const auto path = std::filesystem::temp_directory_path() / "strata_test_fields.vdb";
    write_vdb(scene, fields, path);
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.open();
    const openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
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
