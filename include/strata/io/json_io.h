#pragma once
/// @file The native layer JSON format (documented in README.md, "Layer files").
///
/// {"strata": 1, "units": "m", "layers": [{"name": "body", "closed": true, "thickness": 0.01,
///   "weight": 1, "alpha": 0.8, "beta": 0.9, "outer": ["shirt"], "points": [[x, y], ...]}]}
///
/// Only "layers" and each layer's "points" are required. Defaults: "closed" false,
/// "thickness" 0, "weight" 1, "name" "layer_<index>". Keys strata does not know are kept
/// (scene.metadata, layer.extra) and written back unchanged; diagnostics() lists them.

#include "strata/geometry/scene.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace strata {

/// Parses a scene from JSON text. `source` names the text in messages (a file name).
/// @throws InvalidInput naming `source`, the line and column of a syntax error, or the layer,
///         key and value of a content error.
Scene parse_scene_json(std::string_view text, const std::string& source = "<json>");

/// The scene as JSON text (one layer per line group, points with full double precision).
/// @throws InvalidInput when a name, the units or a key is not UTF-8 (JSON holds no other text;
///         an SVG id can), naming it.
std::string scene_to_json(const Scene& scene);

/// read_text_file + parse_scene_json.  @throws IoError, InvalidInput.
Scene read_scene_json(const std::filesystem::path& path);

/// scene_to_json + write_file_atomic.  @throws IoError, InvalidInput (as scene_to_json).
void write_scene_json(const Scene& scene, const std::filesystem::path& path);

}  // namespace strata
