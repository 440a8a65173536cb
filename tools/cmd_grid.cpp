// `strata grid`: builds the per-layer fields of a scene and writes them for inspection: a .vdb
// file (one grid per layer), a PNG heat map, or a per-layer summary.

#include "cli_util.h"
#include "commands.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/field/field.h"
#include "strata/field/vdb_io.h"
#include "strata/geometry/checks.h"
#include "strata/io/atomic_file.h"
#include "strata/io/scene_io.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace strata::cli {

namespace {

struct GridOptions {
    std::filesystem::path input, vdb, png;
    std::string layer;
    bool info = false;
    int width = 800;
    std::vector<double> region;  // --region X0,Y0,X1,Y1, empty: none
    FieldParams params;
};

/// The box of `--region X0,Y0,X1,Y1`.
/// @throws InvalidInput not four finite numbers with X0 <= X1 and Y0 <= Y1.
Box2 region_box(const std::vector<double>& v) {
    const auto shown = [&] {
        std::string out;
        for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + format_number(v[i]);
        return out;
    };
    if (v.size() != 4 ||
        !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }) ||
        v[0] > v[2] || v[1] > v[3])
        throw InvalidInput(
            "strata grid: --region must be X0,Y0,X1,Y1, four finite numbers with "
            "X0 <= X1 and Y0 <= Y1 (got " +
            shown() + ")");
    Box2 box;
    box.extend(Vec2(v[0], v[1]));
    box.extend(Vec2(v[2], v[3]));
    return box;
}

void append_png(void* context, void* data, int size) {
    auto* out = static_cast<std::string*>(context);
    out->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
}

/// Heat map of one layer's field (blue inside, red outside, brighter near the curve), the zero
/// contour in black and the band edge in grey; pixels span the layer's box plus twice the band,
/// or, with a region, the region plus the band (where the grid is built).
void write_png(const Scene& scene, const SceneFields& fields, std::size_t layer, int width,
               const std::filesystem::path& path) {
    const double band = fields.params().band_width;
    const Box2& region = fields.params().region;
    const Box2 box = region.is_empty() ? scene.layer(layer).bounds().inflated(2.0 * band)
                                       : region.inflated(band);
    const double px = box.size().x / static_cast<double>(width);
    const int height = std::max(1, static_cast<int>(std::ceil(box.size().y / px)));
    const auto w = static_cast<std::size_t>(width), h = static_cast<std::size_t>(height);
    std::vector<FieldSample> s(w * h);
    for (std::size_t j = 0; j < h; ++j)
        for (std::size_t i = 0; i < w; ++i)
            s[j * w + i] =
                fields.field(layer).sample(Vec2(box.min.x + (static_cast<double>(i) + 0.5) * px,
                                                box.max.y - (static_cast<double>(j) + 0.5) * px));
    std::vector<std::uint8_t> rgb(w * h * 3);
    for (std::size_t j = 0; j < h; ++j)
        for (std::size_t i = 0; i < w; ++i) {
            const FieldSample& c = s[j * w + i];
            const double t = std::clamp(std::abs(c.value) / band, 0.0, 1.0);
            const auto level = static_cast<std::uint8_t>(255.0 * (1.0 - 0.75 * t));
            std::uint8_t r = c.value >= 0.0 ? level : 40, g = 40, b = c.value < 0.0 ? level : 40;
            const bool right = i + 1 < w, down = j + 1 < h;
            const FieldSample* nr = right ? &s[j * w + i + 1] : nullptr;
            const FieldSample* nd = down ? &s[(j + 1) * w + i] : nullptr;
            const auto crosses = [&](const FieldSample* n) {
                return n != nullptr && (n->value < 0.0) != (c.value < 0.0);
            };
            const auto edge = [&](const FieldSample* n) {
                return n != nullptr && n->in_band != c.in_band;
            };
            if (edge(nr) || edge(nd)) r = g = b = 160;
            if (crosses(nr) || crosses(nd)) r = g = b = 0;
            std::uint8_t* p = &rgb[(j * w + i) * 3];
            p[0] = r;
            p[1] = g;
            p[2] = b;
        }
    std::string bytes;
    if (stbi_write_png_to_func(append_png, &bytes, width, height, 3, rgb.data(), width * 3) == 0)
        throw IoError("strata grid: cannot encode '" + path.string() + "'");
    write_file_atomic(path, bytes);
}

}  // namespace

Run add_grid_command(CLI::App& app) {
    auto opt = std::make_shared<GridOptions>();
    CLI::App* cmd = app.add_subcommand(
        "grid",
        "Builds the per-layer signed distance grids and writes them (.vdb, PNG) or a summary");
    cmd->add_option("input", opt->input, "Scene file (.json or .svg)")->required();
    cmd->add_option("-o,--output", opt->vdb, "Write one OpenVDB grid per layer to this .vdb file");
    cmd->add_option("--png", opt->png,
                    "Write a heat map of one layer's field (zero contour, band edge)");
    cmd->add_option("--layer", opt->layer, "Layer of the PNG (default: the first)");
    cmd->add_option("--width", opt->width, "PNG width in pixels")
        ->capture_default_str()
        ->check(CLI::Range(16, 16384));
    cmd->add_flag("--info", opt->info,
                  "Print per layer: active voxels, leaves, memory (its segments and its share "
                  "of the shared grid), bbox; then the totals, voxel size, band");
    cmd->add_option("--voxel-size", opt->params.voxel_size,
                    "Voxel size, scene units (0 = auto: median segment / 4, <= half the smallest "
                    "separation)")
        ->capture_default_str();
    cmd->add_option("--band", opt->params.band_width,
                    "Band half-width, scene units (0 = auto: thickness + penetration + 2 voxels)")
        ->capture_default_str();
    cmd->add_option("--region", opt->region,
                    "Build the grid only around the box X0,Y0,X1,Y1 (scene units; within a band "
                    "width of it): a part of a large scene, fast")
        ->expected(4)
        ->delimiter(',');
    return [opt]() {
        if (opt->vdb.empty() && opt->png.empty() && !opt->info)
            throw InvalidInput(
                "strata grid: nothing to do (give -o FILE.vdb, --png FILE or --info)");
        for (const auto& out : {opt->vdb, opt->png})
            if (!out.empty()) ensure_not_an_input(out, {opt->input});
        opt->params.backend = FieldBackend::Grid;
        if (!opt->region.empty()) opt->params.region = region_box(opt->region);
        validate(opt->params);
        const Scene scene = read_scene(opt->input);
        std::vector<int> sides(scene.size());
        for (std::size_t i = 0; i < scene.size(); ++i) sides[i] = outside_side(scene, i);
        const SceneFields fields(scene, opt->params, sides);
        if (!opt->vdb.empty()) write_vdb(scene, fields, opt->vdb);
        if (!opt->png.empty()) {
            std::size_t layer = 0;
            if (!opt->layer.empty()) {
                const auto found = scene.find(opt->layer);
                if (!found)
                    throw InvalidInput("strata grid: no layer named '" + shown_text(opt->layer) +
                                       "'");
                layer = *found;
            }
            write_png(scene, fields, layer, opt->width, opt->png);
        }
        if (opt->info) {
            std::cout << "voxel size " << format_number(fields.params().voxel_size) << ", band "
                      << format_number(fields.params().band_width) << " (scene units"
                      << (scene.units().empty() ? "" : ": " + shown_name(scene.units())) << ")";
            if (const Box2& r = fields.params().region; !r.is_empty())
                std::cout << ", only within a band of the region [" << format_number(r.min.x)
                          << ", " << format_number(r.min.y) << "] - [" << format_number(r.max.x)
                          << ", " << format_number(r.max.y) << "]";
            std::cout << "\n";
            for (std::size_t i = 0; i < fields.size(); ++i) {
                const FieldStats st = fields.field(i).stats();
                std::cout << shown_name(scene.layer(i).name) << ": " << st.segments << " segments, "
                          << st.active_voxels << " active voxels, " << st.leaves << " leaves, "
                          << st.memory_bytes << " bytes ("
                          << st.memory_bytes / std::max<std::size_t>(st.segments, 1)
                          << " per segment), bbox ";
                if (st.bounds.is_empty()) {
                    std::cout << "none\n";  // no band voxel in the region
                    continue;
                }
                std::cout << "[" << format_number(st.bounds.min.x) << ", "
                          << format_number(st.bounds.min.y) << "] - ["
                          << format_number(st.bounds.max.x) << ", "
                          << format_number(st.bounds.max.y) << "]\n";
            }
            const FieldStats total = fields.total_stats();
            std::cout << "all layers (one shared grid): " << total.segments << " segments, "
                      << total.active_voxels << " active voxels, " << total.leaves << " leaves, "
                      << total.memory_bytes << " bytes ("
                      << total.memory_bytes / std::max<std::size_t>(total.segments, 1)
                      << " per segment)\n";
        }
        return 0;
    };
}

}  // namespace strata::cli
