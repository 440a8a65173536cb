#include "strata/io/scene_io.h"

#include "strata/core/error.h"
#include "strata/io/json_io.h"
#include "strata/io/svg_io.h"

#include <algorithm>
#include <cctype>

namespace strata {

SceneFormat scene_format(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".json") return SceneFormat::Json;
    if (ext == ".svg") return SceneFormat::Svg;
    throw InvalidInput(path.string() + ": unknown scene format '" + ext +
                       "' (expected .json or .svg)");
}

Scene read_scene(const std::filesystem::path& path) {
    return scene_format(path) == SceneFormat::Json ? read_scene_json(path) : read_scene_svg(path);
}

void write_scene(const Scene& scene, const std::filesystem::path& path) {
    if (scene_format(path) == SceneFormat::Json)
        write_scene_json(scene, path);
    else
        write_scene_svg(scene, path);
}

}  // namespace strata
