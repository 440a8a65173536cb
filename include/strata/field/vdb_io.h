#pragma once
/// @file Writing grid fields to OpenVDB files (this header does not include OpenVDB).

#include "strata/field/field.h"
#include "strata/geometry/scene.h"

#include <filesystem>

namespace strata {

/// @brief Writes one FloatGrid per layer of `fields` (Grid backend) to `path` (.vdb), named by
/// the layer, with metadata: "strata_voxel_size" and "strata_band_width" (scene units),
/// "strata_units" (the scene's length unit), "strata_closed", "strata_outside_sign",
/// "strata_thickness", "strata_weight". The grids are 2D slabs at index z = 0 with the
/// transform createLinearTransform(voxel size) and class GRID_LEVEL_SET, extracted from the
/// layers' shared grid (layer i's plane z = i, where it has band voxels; internal nodes flood
/// filled with its signs).
/// Written to a temporary file beside `path`, then renamed.
/// @throws InvalidInput when `fields` is not a Grid field set of `scene`.
/// @throws IoError when the file cannot be written.
void write_vdb(const Scene& scene, const SceneFields& fields, const std::filesystem::path& path);

}  // namespace strata
