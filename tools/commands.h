#pragma once
/// @file The verbs of the `strata` command. Each verb registers itself on the CLI11 app and
/// returns, through `run`, the process exit code (0 ok, 1 the check failed, 2 bad input).
/// Tools are thin: parse -> Params -> call the library -> write. No algorithm here.

#include <CLI/CLI.hpp>

#include <functional>

namespace strata::cli {

/// What a verb's callback does once CLI11 has parsed its options; returns the exit code.
using Run = std::function<int()>;

/// `strata check IN [--reference ORIG] [--json] [--strict]`.
Run add_check_command(CLI::App& app);

/// `strata slice MESH... --axis y --at H [--every D] [--order a,b] [--components] -o OUT`.
Run add_slice_command(CLI::App& app);

/// `strata simplify [IN...] -o OUT [--remove F] [options]`; no input: the demo.
Run add_simplify_command(CLI::App& app);

/// `strata untangle IN -o OUT [--reference ORIG | --infer-sides] [--svg S] [--report R] [options]`.
Run add_untangle_command(CLI::App& app);

/// `strata grid IN [-o FIELDS.vdb] [--png FILE [--layer NAME]] [--info]`.
Run add_grid_command(CLI::App& app);

}  // namespace strata::cli
