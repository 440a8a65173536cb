#pragma once
/// @file Reading and writing scenes by file name: the format follows the extension.

#include "strata/geometry/scene.h"

#include <filesystem>

namespace strata {

enum class SceneFormat { Json, Svg };

/// Format from the extension (.json, .svg; case-insensitive).
/// @throws InvalidInput naming the path when the extension is not one of them.
SceneFormat scene_format(const std::filesystem::path& path);

/// @throws IoError, InvalidInput (see json_io.h and svg_io.h).
Scene read_scene(const std::filesystem::path& path);
void write_scene(const Scene& scene, const std::filesystem::path& path);

}  // namespace strata
