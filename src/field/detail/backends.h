#pragma once
/// @file Internal: the backend factories behind make_field() and SceneFields.

#include "strata/field/field.h"

#include <memory>
#include <vector>

namespace strata::detail {

std::unique_ptr<LayerField> make_exact_field(const Layer& layer, int outside_sign,
                                             const ResolvedFieldParams& params, bool indexed);

/// The Grid backend's fields of several layers: one GridStack (one grid, layer i at z = i) and
/// one LayerField per layer reading and updating its own plane of it.
struct GridFields {
    std::shared_ptr<GridStack> stack;
    std::vector<std::unique_ptr<LayerField>> fields;
};

/// `outside_signs` has one entry (+1 or -1) per layer; params are checked by the caller.
GridFields make_grid_fields(const std::vector<const Layer*>& layers,
                            const std::vector<int>& outside_signs,
                            const ResolvedFieldParams& params);
/// A stack of one layer.
std::unique_ptr<LayerField> make_grid_field(const Layer& layer, int outside_sign,
                                            const ResolvedFieldParams& params);

/// SceneFields::sample_all() of a Grid stack: one probe per bilinear corner and leaf row.
void grid_sample_all(const GridStack& stack, const Vec2& x, std::vector<FieldSample>& out);
/// SceneFields::total_stats() of a Grid stack.
FieldStats grid_total_stats(const GridStack& stack);

}  // namespace strata::detail
