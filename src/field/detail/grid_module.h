#pragma once
/// @file Internal: the Grid backend as a separately loaded module (no OpenVDB include).
///
/// Loading libopenvdb costs a process about 20 ms before main() (its ~69k symbol relocations,
/// bound at load time: the Debian library is linked with BIND_NOW), so the Grid backend
/// (grid_field.cpp, the only OpenVDB code) is built as its own shared module,
/// libstrata_field_grid.so, that the field module dlopen()s the first time a Grid field or
/// write_vdb() is asked for (grid_loader.cpp). Commands that do not use the grid never load
/// OpenVDB. The module exports one C function returning the table below.

#include "field/detail/backends.h"
#include "strata/field/field.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace strata::detail {

/// Bumped whenever GridModule or a type it passes changes layout.
inline constexpr int kGridModuleAbi = 2;

/// The Grid backend's entry points (backends.h, grid_inspect.h, vdb_io.h).
struct GridModule {
    int abi = kGridModuleAbi;
    const char* version = nullptr;  ///< STRATA_VERSION the module was built from.
    GridFields (*make_grid_fields)(const std::vector<const Layer*>&, const std::vector<int>&,
                                   const ResolvedFieldParams&) = nullptr;
    std::unique_ptr<LayerField> (*make_grid_field)(const Layer&, int,
                                                   const ResolvedFieldParams&) = nullptr;
    void (*grid_sample_all)(const GridStack&, const Vec2&, std::vector<FieldSample>&) = nullptr;
    FieldStats (*grid_total_stats)(const GridStack&) = nullptr;
    bool (*grids_identical)(const LayerField&, const LayerField&, std::string*) = nullptr;
    double (*max_box_sampler_difference)(const LayerField&, const std::vector<Vec2>&) = nullptr;
    void (*voxel_signs)(const LayerField&, int, int, int, int, std::vector<int>&,
                        std::vector<char>&) = nullptr;
    std::size_t (*shared_leaf_count)(const LayerField&, const LayerField&) = nullptr;
    void (*write_vdb)(const Scene&, const SceneFields&, const std::filesystem::path&) = nullptr;
};

/// The loaded module (loaded on the first call, then cached; thread safe).
/// @throws IoError when the module cannot be found or loaded, naming the places searched.
const GridModule& grid_module();

}  // namespace strata::detail

/// The module's one exported symbol (defined in grid_field.cpp), looked up by this name.
extern "C" const strata::detail::GridModule* strata_grid_module_v1();
#define STRATA_GRID_MODULE_ENTRY "strata_grid_module_v1"
