#pragma once
/// @file Helpers shared by the verbs of the `strata` command: progress bar, output checks,
/// option parsing.

#include "strata/core/progress.h"
#include "strata/field/field.h"
#include "strata/geometry/scene.h"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace strata::cli {

/// A progress bar on stderr, drawn only when stderr is a terminal; never cancels.
ProgressFn terminal_progress();

/// Throws InvalidInput when an output would overwrite an input, or its folder is missing.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

/// Adds `--backend grid|exact|indexed` bound to `backend`.
void add_backend_option(CLI::App& cmd, FieldBackend& backend);

/// `scene` with `thickness` given to its layers of thickness 0 (`--thickness`); unchanged
/// when `thickness` <= 0.
Scene with_default_thickness(const Scene& scene, double thickness);

/// "grid", "exact", "indexed".
const char* backend_name(FieldBackend backend);

}  // namespace strata::cli
