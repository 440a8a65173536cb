#pragma once
/// @file Internal: checks on Grid-backend fields that the tests need (no OpenVDB include).

#include "strata/field/field.h"

#include <string>
#include <vector>

namespace strata::detail {

/// True when both are Grid fields whose trees hold the same leaves (origins, value masks and
/// buffers compared bit for bit) and the same value at every voxel of the z = 0 plane around
/// their bounding boxes (tiles included). `why` receives the first difference.
bool grids_identical(const LayerField& a, const LayerField& b, std::string* why = nullptr);

/// Largest |BoxSampler at (x / h, y / h, 0) - sample(x).value| over `points` (Grid field):
/// shows that OpenVDB's trilinear sampler at z = 0 is the bilinear interpolant the field uses.
double max_box_sampler_difference(const LayerField& field, const std::vector<Vec2>& points);

/// Sign of the stored value (-1, 0, +1) at every voxel (i, j, 0) with i in [i0, i1], j in
/// [j0, j1], row by row, and whether each is active (Grid field); for the flood-fill tests.
void voxel_signs(const LayerField& field, int i0, int i1, int j0, int j1, std::vector<int>& signs,
                 std::vector<char>& active);

}  // namespace strata::detail
