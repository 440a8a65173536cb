#pragma once
/// @file Internal: the backend factories behind make_field().

#include "strata/field/field.h"

#include <memory>

namespace strata::detail {

std::unique_ptr<LayerField> make_exact_field(const Layer& layer, int outside_sign,
                                             const ResolvedFieldParams& params, bool indexed);
std::unique_ptr<LayerField> make_grid_field(const Layer& layer, int outside_sign,
                                            const ResolvedFieldParams& params);

}  // namespace strata::detail
