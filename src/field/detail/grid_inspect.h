#pragma once
/// @file Internal: checks on Grid-backend fields that the tests need (no OpenVDB include).

#include "strata/field/field.h"

#include <string>
#include <vector>

namespace strata::detail {

/// True when both are Grid fields of the same layer index in stacks of as many layers whose
/// trees are the same: root table, internal nodes (child and value masks, tile values), leaves
/// (origins, value masks and buffers of every plane, bit for bit), and the same value of the
/// layer's z plane (as sample() reads it, out-of-leaf signs included) at every voxel around
/// their bounding boxes. `why` receives the first difference.
bool grids_identical(const LayerField& a, const LayerField& b, std::string* why = nullptr);

/// Largest |BoxSampler at (x / h, y / h, 0) - sample(x).value| over `points` (Grid field), the
/// sampler reading the layer's z = 0 slab as write_vdb() writes it: shows that the field is the
/// bilinear interpolant of that standard slab (OpenVDB's trilinear sampler at z = 0).
double max_box_sampler_difference(const LayerField& field, const std::vector<Vec2>& points);

/// Sign of the layer's value (-1, 0, +1) at every voxel (i, j) with i in [i0, i1], j in
/// [j0, j1], row by row, and whether each is active (Grid field): the stored value of its z
/// plane in a leaf, the sign sample() takes elsewhere (first leaf voxel of the plane along +x).
void voxel_signs(const LayerField& field, int i0, int i1, int j0, int j1, std::vector<int>& signs,
                 std::vector<char>& active);

/// Leaves of the shared grid in which both layers have band voxels (0 for different stacks).
std::size_t shared_leaf_count(const LayerField& a, const LayerField& b);

}  // namespace strata::detail
