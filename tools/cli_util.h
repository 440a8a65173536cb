#pragma once
/// @file Helpers shared by the verbs of the `strata` command: progress bar, output checks,
/// option parsing.

#include "strata/core/progress.h"
#include "strata/field/field.h"
#include "strata/geometry/scene.h"

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cctype>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace strata::cli {

/// A name or other text read from an input file (a layer name, the units) as a report line
/// shows it: shown_text() in full, never cut, so that a control byte or broken UTF-8 in it
/// can neither move the cursor, colour nor garble the terminal (\xNN, a backslash as \\).
std::string shown_name(std::string_view name);

/// `report` as the text of a JSON report (2-space indent). A name that is not UTF-8 (an SVG id
/// can hold any byte; JSON holds UTF-8 only) has its stray bytes replaced by U+FFFD, where
/// nlohmann's dump() would throw.
std::string json_report_text(const nlohmann::json& report);

/// A progress bar on stderr, drawn only when stderr is a terminal; never cancels.
ProgressFn terminal_progress();

/// Ends the line of a progress bar that a run left unfinished (it stopped early, or threw), so
/// that a message printed next starts on a line of its own; nothing when there is none.
void end_progress_line();

/// Throws InvalidInput when an output would overwrite an input, or its folder is missing.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

/// Adds an option `name` taking one of the keys of `choices` (any case) and storing its value
/// in `target`; a bad value is reported as "NAME: VALUE not in {a,b,...}".
template <class T>
CLI::Option* add_choice_option(CLI::App& cmd, const std::string& name, T& target,
                               const std::map<std::string, T>& choices, const std::string& help,
                               const std::string& default_name) {
    std::vector<std::string> names;
    for (const auto& entry : choices) names.push_back(entry.first);
    return cmd
        .add_option_function<std::string>(
            name,
            [&target, choices](std::string value) {
                for (char& c : value)
                    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
                target = choices.at(value);
            },
            help)
        ->check(CLI::IsMember(names, CLI::ignore_case))
        ->default_str(default_name);
}

/// Adds an option `name` storing a whole number >= `min` in `target`. Anything else (a sign, a
/// fraction, text, or a value below `min`) is reported as "NAME must be a whole number >= MIN
/// (got VALUE)"; CLI11's own conversion would wrap "-1" around to 2^64 - 1.
CLI::Option* add_count_option(CLI::App& cmd, const std::string& name, std::size_t& target,
                              const std::string& help, std::size_t min = 0);

/// Adds `--threads N` bound to `threads` (worker threads, 0: all cores).
void add_threads_option(CLI::App& cmd, int& threads);

/// The limit that `--threads N` of `verb` sets on TBB's threads, for as long as the returned
/// object lives; null for 0 (all cores).
/// @throws InvalidInput when N < 0 ("VERB: --threads must be >= 0 (got N)").
std::unique_ptr<tbb::global_control> thread_limit(const std::string& verb, int threads);

/// Adds `--backend grid|exact|indexed` bound to `backend`.
void add_backend_option(CLI::App& cmd, FieldBackend& backend);

/// `scene` with `thickness` given to its layers of thickness 0 (`--thickness`); unchanged
/// when `thickness` <= 0.
Scene with_default_thickness(const Scene& scene, double thickness);

/// "grid", "exact", "indexed".
const char* backend_name(FieldBackend backend);

// True when all `points` lie on one line (exact orientation tests): a closed layer so has no area.
bool is_flat(const std::vector<Vec2>& points);

}  // namespace strata::cli
