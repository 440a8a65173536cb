// The Grid backend's entry points in the field module: each loads libstrata_field_grid.so (the
// only code that links OpenVDB, see detail/grid_module.h) on first use and calls into it.
#include "field/detail/grid_inspect.h"
#include "field/detail/grid_module.h"
#include "strata/core/error.h"
#include "strata/field/vdb_io.h"

#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <vector>

#ifndef STRATA_GRID_MODULE_VERSION
#error "STRATA_GRID_MODULE_VERSION must be defined (src/field/CMakeLists.txt)"
#endif

namespace strata::detail {

namespace {

constexpr const char* kModuleFile = "libstrata_field_grid.so";

// An object of this binary: dladdr() on it names the executable or shared object holding the
// field module (the CLI, a test, the Python extension ...).
const char kAnchor = 0;

// Where to look, in order: STRATA_GRID_MODULE alone when set; beside the binary holding this
// code and in its ../<libdir> (an installed CLI); the build tree and the install prefix this
// was configured with; then the bare name (LD_LIBRARY_PATH, RUNPATH, ld.so cache).
std::vector<std::string> candidates() {
    if (const char* env = std::getenv("STRATA_GRID_MODULE"); env != nullptr && *env != '\0')
        return {env};
    std::vector<std::string> out;
    Dl_info info{};
    if (dladdr(&kAnchor, &info) != 0 && info.dli_fname != nullptr && *info.dli_fname != '\0') {
        std::string dir = info.dli_fname;
        const auto slash = dir.find_last_of('/');
        dir = slash == std::string::npos ? std::string(".") : dir.substr(0, slash);
        out.push_back(dir + "/" + kModuleFile);
        out.push_back(dir + "/../" STRATA_GRID_MODULE_LIBDIR "/" + kModuleFile);
    }
    out.push_back(STRATA_GRID_MODULE_BUILD_DIR "/" + std::string(kModuleFile));
    out.push_back(STRATA_GRID_MODULE_INSTALL_DIR "/" + std::string(kModuleFile));
    out.push_back(kModuleFile);
    return out;
}

const GridModule& load() {
    std::string tried;
    for (const std::string& path : candidates()) {
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (handle == nullptr) {
            const char* err = dlerror();
            // A missing file is the common case: name the path only.
            const std::string why = err != nullptr ? err : "not loadable";
            tried += "\n  " +
                     (why.find("No such file") != std::string::npos ? path + ": not found" : why);
            continue;
        }
        using Entry = const GridModule* (*)();
        const auto entry = reinterpret_cast<Entry>(dlsym(handle, STRATA_GRID_MODULE_ENTRY));
        const GridModule* module = entry != nullptr ? entry() : nullptr;
        if (module != nullptr && module->abi == kGridModuleAbi && module->version != nullptr &&
            std::string(module->version) == STRATA_GRID_MODULE_VERSION)
            return *module;  // kept loaded for the life of the process
        tried += "\n  " + path + ": not a strata " STRATA_GRID_MODULE_VERSION " grid module";
        dlclose(handle);
    }
    throw IoError(
        "grid field backend: cannot load " + std::string(kModuleFile) +
        " (the OpenVDB backend, loaded on first use); set STRATA_GRID_MODULE to its path or "
        "use the exact or indexed backend. Tried:" +
        tried);
}

}  // namespace

const GridModule& grid_module() {
    static const GridModule& module = load();  // retried on the next call if it throws
    return module;
}

GridFields make_grid_fields(const std::vector<const Layer*>& layers,
                            const std::vector<int>& outside_signs,
                            const ResolvedFieldParams& params) {
    return grid_module().make_grid_fields(layers, outside_signs, params);
}

std::unique_ptr<LayerField> make_grid_field(const Layer& layer, int outside_sign,
                                            const ResolvedFieldParams& params) {
    return grid_module().make_grid_field(layer, outside_sign, params);
}

void grid_sample_all(const GridStack& stack, const Vec2& x, std::vector<FieldSample>& out) {
    grid_module().grid_sample_all(stack, x, out);
}

FieldStats grid_total_stats(const GridStack& stack) {
    return grid_module().grid_total_stats(stack);
}

bool grids_identical(const LayerField& a, const LayerField& b, std::string* why) {
    return grid_module().grids_identical(a, b, why);
}

double max_box_sampler_difference(const LayerField& field, const std::vector<Vec2>& points) {
    return grid_module().max_box_sampler_difference(field, points);
}

void voxel_signs(const LayerField& field, int i0, int i1, int j0, int j1, std::vector<int>& signs,
                 std::vector<char>& active) {
    grid_module().voxel_signs(field, i0, i1, j0, j1, signs, active);
}

std::size_t shared_leaf_count(const LayerField& a, const LayerField& b) {
    return grid_module().shared_leaf_count(a, b);
}

}  // namespace strata::detail

namespace strata {

void write_vdb(const Scene& scene, const SceneFields& fields, const std::filesystem::path& path) {
    detail::grid_module().write_vdb(scene, fields, path);
}

}  // namespace strata
