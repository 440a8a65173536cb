#include "cli_util.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"
#include "strata/io/atomic_file.h"

#include <unistd.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

namespace strata::cli {

std::string shown_name(std::string_view name) {
    return shown_text(name, std::numeric_limits<std::size_t>::max());
}

std::string json_report_text(const nlohmann::json& report) {
    return report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {
// A progress bar is drawn on stderr's current line, not yet ended by a newline.
std::atomic<bool> bar_open{false};
}  // namespace

ProgressFn terminal_progress() {
    if (!isatty(fileno(stderr))) return {};
    auto last = std::make_shared<std::chrono::steady_clock::time_point>();
    return [last](std::string_view stage, double fraction) {
        const auto now = std::chrono::steady_clock::now();
        if (fraction < 1.0 && now - *last < std::chrono::milliseconds(100)) return true;
        *last = now;
        const int width = 30;
        const int filled = static_cast<int>(fraction * width + 0.5);
        std::fprintf(stderr, "\r%-12.*s [%.*s%*s] %3d%%", static_cast<int>(stage.size()),
                     stage.data(), filled, "##############################", width - filled, "",
                     static_cast<int>(fraction * 100.0 + 0.5));
        if (fraction >= 1.0) std::fputc('\n', stderr);
        bar_open = fraction < 1.0;
        std::fflush(stderr);
        return true;
    };
}

void end_progress_line() {
    if (bar_open.exchange(false)) std::fputc('\n', stderr);
}

void check_outputs(const std::vector<std::string>& outputs,
                   const std::vector<std::string>& inputs) {
    std::vector<std::filesystem::path> in(inputs.begin(), inputs.end());
    for (const std::string& out : outputs) {
        if (out.empty()) continue;
        ensure_not_an_input(out, in);
        const std::filesystem::path parent = std::filesystem::path(out).parent_path();
        if (!parent.empty() && !std::filesystem::is_directory(parent))
            throw InvalidInput(out + ": folder '" + parent.string() + "' does not exist");
    }
}

CLI::Option* add_count_option(CLI::App& cmd, const std::string& name, std::size_t& target,
                              const std::string& help, std::size_t min) {
    const CLI::Validator whole(
        [min](std::string& value) -> std::string {
            const std::string error =
                "must be a whole number >= " + std::to_string(min) + " (got " + value + ")";
            if (value.empty() || value.size() > 18 ||
                value.find_first_not_of("0123456789") != std::string::npos)
                return error;
            return std::stoull(value) < min ? error : std::string();
        },
        "UINT>=" + std::to_string(min));
    return cmd.add_option(name, target, help)->check(whole)->capture_default_str();
}

void add_threads_option(CLI::App& cmd, int& threads) {
    cmd.add_option("--threads", threads, "Worker threads (0: all cores)")->capture_default_str();
}

std::unique_ptr<tbb::global_control> thread_limit(const std::string& verb, int threads) {
    if (threads < 0)
        throw InvalidInput(verb + ": --threads must be >= 0 (got " + std::to_string(threads) + ")");
    if (threads == 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<std::size_t>(threads));
}

void add_backend_option(CLI::App& cmd, FieldBackend& backend) {
    static const std::map<std::string, FieldBackend> names{{"grid", FieldBackend::Grid},
                                                           {"exact", FieldBackend::ExactBrute},
                                                           {"indexed", FieldBackend::ExactIndexed}};
    add_choice_option(cmd, "--backend", backend, names,
                      "Field backend: grid (OpenVDB narrow band), exact (brute force) or indexed "
                      "(exact, bucketed)",
                      backend_name(backend));
}

Scene with_default_thickness(const Scene& scene, double thickness) {
    if (thickness <= 0.0) return scene;
    std::vector<Layer> layers = scene.layers();
    for (Layer& layer : layers)
        if (layer.thickness == 0.0) layer.thickness = thickness;
    Scene out(std::move(layers), scene.units());
    out.metadata = scene.metadata;
    return out;
}

const char* backend_name(FieldBackend backend) {
    switch (backend) {
        case FieldBackend::Grid:
            return "grid";
        case FieldBackend::ExactBrute:
            return "exact";
        case FieldBackend::ExactIndexed:
            return "indexed";
    }
    return "?";
}

bool is_flat(const std::vector<Vec2>& points) {
    std::size_t far = 1;
    while (far < points.size() && points[far] == points[0]) ++far;
    for (std::size_t i = far + 1; i < points.size(); ++i)
        if (orient2d(points[0], points[far], points[i]) != 0) return false;
    return true;
}

}  // namespace strata::cli
