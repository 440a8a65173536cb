// strata slice: planar slices of 3D meshes (a body and its garments) as nested layer scenes.
#include "commands.h"

#include "cli_util.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/io/atomic_file.h"
#include "strata/io/json_io.h"
#include "strata/io/mesh_slice.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace strata::cli {

namespace {

struct SliceOptions {
    std::vector<std::string> meshes;
    std::string axis = "y";
    std::vector<double> at;
    double every = 0.0;
    std::vector<std::string> order;
    std::string output;
    std::string prefix;
    std::string thickness;
    bool no_weld = false;
    SliceParams params;
};

// "NAME=PATH" or "PATH" (the name is then the file stem).
std::pair<std::string, std::string> split_mesh_spec(const std::string& spec) {
    const std::size_t eq = spec.find('=');
    if (eq != std::string::npos && eq > 0 && spec.find('/') > eq)
        return {spec.substr(0, eq), spec.substr(eq + 1)};
    return {std::string(), spec};
}

bool ends_with_json(const std::string& s) {
    std::string ext = std::filesystem::path(s).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".json";
}

void note_read(const std::string& path, const MeshReadReport& r) {
    if (r.complex_faces > 0)
        std::cerr << "strata: note: " << path << ": OpenMesh could not connect " << r.complex_faces
                  << " complex (non-manifold) faces; their vertices were mapped back, so they are "
                     "sliced with their neighbours\n";
    if (r.dropped_faces > 0)
        std::cerr << "strata: note: " << path << ": OpenMesh dropped " << r.dropped_faces
                  << " faces with repeated or invalid vertices\n";
    if (r.degenerate_triangles > 0)
        std::cerr << "strata: note: " << path << ": " << r.degenerate_triangles
                  << " degenerate triangles (repeated vertex) removed\n";
}

// A finite length >= 0 written in full (no trailing characters).
double parse_length(const std::string& text, const std::string& what) {
    std::size_t used = 0;
    double v = 0.0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v) || v < 0.0)
        throw InvalidInput("slice: " + what + " must be a finite length >= 0 (got '" + text + "')");
    return v;
}

}  // namespace

Run add_slice_command(CLI::App& app) {
    auto opt = std::make_shared<SliceOptions>();
    const SliceParams defaults{};
    CLI::App* cmd = app.add_subcommand(
        "slice",
        "Slice meshes (OBJ, OFF, PLY, STL) by planes into nested layer scenes (exit 0 written, "
        "1 nothing written, 2 bad input)");
    cmd->add_option(
           "meshes", opt->meshes,
           "Mesh files, innermost first, each [NAME=]PATH (NAME defaults to the file stem)")
        ->required();
    cmd->add_option("--axis", opt->axis, "Axis the planes are perpendicular to: x, y or z")
        ->capture_default_str();
    cmd->add_option("--at", opt->at, "Plane position along the axis (mesh units); repeatable");
    cmd->add_option(
        "--every", opt->every,
        "Also slice at every multiple of D strictly inside the meshes' extent (mesh units)");
    cmd->add_option("--order", opt->order, "Mesh names innermost first, e.g. body,shirt,jacket")
        ->delimiter(',');
    cmd->add_flag("--components", opt->params.split_components,
                  "Name layers after connected components: NAME.c<k>_<j> (k = 0 is the largest)");
    cmd->add_option("--nesting-distance", opt->params.nesting.distance,
                    "Layers farther apart than this are not related (open layers; 0 = 5% of the "
                    "slice diagonal)")
        ->default_str(format_number(defaults.nesting.distance));
    cmd->add_option("--coverage", opt->params.nesting.coverage,
                    "Share of a layer within the nesting distance of another to run alongside it")
        ->default_str(format_number(defaults.nesting.coverage));
    cmd->add_option("--thickness", opt->thickness,
                    "Thickness written to the layers (mesh units): T for every mesh, or per mesh "
                    "NAME=T,NAME=T (e.g. body=0,suit=0.002; unnamed meshes get 0)")
        ->default_str(format_number(defaults.thickness));
    cmd->add_flag("--no-weld", opt->no_weld,
                  "Keep every open piece its own layer (default: join pieces whose ends meet or "
                  "overlap at a seam)");
    cmd->add_option("--weld-tolerance", opt->params.weld.tolerance,
                    "Join open ends at most this far apart (mesh units; 0 = " +
                        format_number(kAutoWeldFraction) + " x the median edge length)")
        ->default_str(format_number(defaults.weld.tolerance));
    cmd->add_option("--units", opt->params.units, "Length unit written to the scenes (e.g. dm, m)");
    cmd->add_option("--prefix", opt->prefix,
                    "File name prefix in a folder output (default: the mesh names joined by '+')");
    cmd->add_option("-o,--output", opt->output,
                    "A .json file (one height) or a folder, created if needed, of "
                    "<prefix>_<axis><+-h>.json files")
        ->required();
    return [opt]() {
        SliceParams params = opt->params;
        params.axis = parse_axis(opt->axis);
        params.order = opt->order;
        params.weld.enabled = !opt->no_weld;
        params.thickness = 0.0;
        if (!opt->thickness.empty()) {
            if (opt->thickness.find('=') == std::string::npos) {
                params.thickness = parse_length(opt->thickness, "--thickness");
            } else {
                std::stringstream items(opt->thickness);
                for (std::string item; std::getline(items, item, ',');) {
                    const std::size_t eq = item.find('=');
                    if (eq == std::string::npos || eq == 0)
                        throw InvalidInput("slice: --thickness item '" + item + "' is not NAME=T");
                    params.mesh_thickness[item.substr(0, eq)] =
                        parse_length(item.substr(eq + 1), "--thickness " + item.substr(0, eq));
                }
            }
        }
        validate(params.nesting);
        validate(params.weld);

        std::vector<SliceMesh> meshes;
        std::vector<std::filesystem::path> inputs;
        for (const std::string& spec : opt->meshes) {
            auto [name, path] = split_mesh_spec(spec);
            inputs.emplace_back(path);
            meshes.push_back(read_slice_mesh(path, name));
            note_read(path, meshes.back().read_report);
        }
        params.heights = opt->at;
        if (opt->every != 0.0) {
            const int ax = params.axis == Axis::X ? 0 : (params.axis == Axis::Y ? 1 : 2);
            double lo = meshes.front().bounds()[0][ax], hi = meshes.front().bounds()[1][ax];
            for (const SliceMesh& m : meshes) {
                lo = std::min(lo, m.bounds()[0][ax]);
                hi = std::max(hi, m.bounds()[1][ax]);
            }
            for (double h : regular_heights(lo, hi, opt->every)) params.heights.push_back(h);
        }
        std::sort(params.heights.begin(), params.heights.end());
        params.heights.erase(std::unique(params.heights.begin(), params.heights.end()),
                             params.heights.end());
        if (params.heights.empty())
            throw InvalidInput(
                "slice: no plane: give --at H or --every D (inside the meshes' extent)");

        const bool single_file = ends_with_json(opt->output);
        if (single_file && params.heights.size() != 1)
            throw InvalidInput("slice: output '" + opt->output + "' is one file but there are " +
                               std::to_string(params.heights.size()) + " heights; give a folder");
        std::string prefix = opt->prefix;
        if (prefix.empty())
            for (const SliceMesh& m : meshes) prefix += (prefix.empty() ? "" : "+") + m.name;
        const int decimals = slice_name_decimals(params.heights);
        std::filesystem::path folder(opt->output);
        if (single_file) {
            ensure_not_an_input(opt->output, inputs);
        } else {
            std::error_code ec;
            std::filesystem::create_directories(folder, ec);
            if (ec)
                throw IoError(folder.string() + ": cannot create folder (" + ec.message() + ")");
        }

        const SliceReport report = slice_meshes(meshes, params, terminal_progress());
        std::size_t written = 0, crossing = 0;
        for (const PlaneSlice& s : report.slices) {
            const std::string plane =
                std::string(axis_name(params.axis)) + " = " + format_number(s.height);
            if (!s.scene) {
                std::cerr << "strata: warning: " << plane
                          << ": the plane misses every mesh; nothing written\n";
                continue;
            }
            const std::filesystem::path out =
                single_file ? folder
                            : folder / slice_file_name(prefix, params.axis, s.height, decimals);
            write_scene_json(*s.scene, out);
            ++written;
            const CheckReport check = check_scene(*s.scene);
            const bool crosses = check.crossing_count > 0 || check.total_self_crossings() > 0;
            crossing += crosses ? 1 : 0;
            std::string misses;
            for (const std::string& m : s.missed_meshes)
                misses += (misses.empty() ? " (misses " : ", ") + shown_name(m);
            if (!misses.empty()) misses += ")";
            std::printf(
                "%s: %zu layers (%zu closed, %zu open), %zu vertices, %zu nesting links, "
                "crossings %zu (%zu touching), self-crossings %zu, nesting violations %zu%s%s -> "
                "%s\n",
                plane.c_str(), s.closed_layers + s.open_layers, s.closed_layers, s.open_layers,
                s.vertices, s.nesting.links, check.crossing_count, check.touch_count,
                check.total_self_crossings(), check.nesting_violation_count,
                crosses ? " [input already crosses]" : "", misses.c_str(), out.string().c_str());
            if (!s.welded.empty()) {
                std::string welds;
                for (const WeldedLayer& w : s.welded)
                    welds += (welds.empty() ? "" : ", ") + shown_name(w.name) + " (" +
                             std::to_string(w.pieces) + (w.pieces == 1 ? " piece" : " pieces") +
                             (w.overlaps > 0 ? ", " + std::to_string(w.overlaps) + " overlapping"
                                             : std::string()) +
                             (w.closed ? ", closed" : ", open") + ")";
                std::printf("  welded: %s\n", welds.c_str());
            }
        }
        std::printf("%zu of %zu slices written, %zu already crossing\n", written,
                    report.slices.size(), crossing);
        if (written == 0) {
            std::cerr << "strata: error: no slice written: every plane misses the meshes\n";
            return 1;
        }
        return 0;
    };
}

}  // namespace strata::cli
