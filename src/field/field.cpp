#include "strata/field/field.h"

#include "field/detail/backends.h"
#include "geometry/detail/parallel.h"
#include "strata/core/error.h"
#include "strata/core/format.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace strata {

namespace {

void check_length(double value, const char* field) {
    if (!std::isfinite(value) || value < 0.0)
        throw InvalidInput(std::string("FieldParams: params.") + field +
                           " must be finite and >= 0 (got " + format_number(value) + ")");
}

double median_segment_length(const Scene& scene) {
    std::vector<double> lengths;
    for (const Layer& layer : scene.layers())
        for (std::size_t i = 0; i < layer.segment_count(); ++i) {
            const double len = glm::distance(layer.segment_start(i), layer.segment_end(i));
            if (len > 0.0) lengths.push_back(len);
        }
    if (lengths.empty()) return 0.0;
    const auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
    std::nth_element(lengths.begin(), mid, lengths.end());
    return *mid;
}

}  // namespace

void validate(const FieldParams& params) {
    switch (params.backend) {
        case FieldBackend::Grid:
        case FieldBackend::ExactBrute:
        case FieldBackend::ExactIndexed:
            break;
        default:
            throw InvalidInput("FieldParams: params.backend is not a FieldBackend");
    }
    check_length(params.voxel_size, "voxel_size");
    check_length(params.band_width, "band_width");
    check_length(params.expected_penetration, "expected_penetration");
    check_length(params.band_margin_voxels, "band_margin_voxels");
    check_length(params.bucket_size, "bucket_size");
    const Box2& r = params.region;
    if (!r.is_empty() && !(std::isfinite(r.min.x) && std::isfinite(r.min.y) &&
                           std::isfinite(r.max.x) && std::isfinite(r.max.y)))
        throw InvalidInput("FieldParams: params.region must be empty or finite (got [" +
                           format_number(r.min.x) + ", " + format_number(r.max.x) + "] x [" +
                           format_number(r.min.y) + ", " + format_number(r.max.y) + "])");
}

ResolvedFieldParams resolve(const FieldParams& params, const Scene& scene) {
    validate(params);
    const double median = median_segment_length(scene);
    const bool needs_scene = params.voxel_size == 0.0 || params.bucket_size == 0.0 ||
                             (params.band_width == 0.0 && params.expected_penetration == 0.0);
    if (needs_scene && !(median > 0.0))
        throw InvalidInput(
            "resolve(FieldParams): automatic sizes need a scene with a segment "
            "of nonzero length");
    ResolvedFieldParams out;
    out.backend = params.backend;
    out.voxel_size = params.voxel_size;
    if (out.voxel_size == 0.0) {
        out.voxel_size = 0.25 * median;
        double smallest = std::numeric_limits<double>::infinity();
        for (std::size_t a = 0; a < scene.size(); ++a)
            for (std::size_t b = a + 1; b < scene.size(); ++b) {
                const double sep = scene.required_separation(a, b);
                if (sep > 0.0) smallest = std::min(smallest, sep);
            }
        if (std::isfinite(smallest)) out.voxel_size = std::min(out.voxel_size, 0.5 * smallest);
    }
    out.band_width = params.band_width;
    if (out.band_width == 0.0) {
        double thickness = 0.0;
        for (const Layer& layer : scene.layers()) thickness += layer.thickness;
        const double penetration =
            params.expected_penetration > 0.0 ? params.expected_penetration : 2.0 * median;
        out.band_width =
            std::max(thickness + penetration + params.band_margin_voxels * out.voxel_size,
                     3.0 * out.voxel_size);
    }
    // ExactIndexed: a bucket about as wide as the band. sample_in_band() searches the band
    // around a point, and a search over many buckets finer than it costs more than the
    // segments it offers. At least 2 median segments (the nearest of a layer's own segment),
    // at most 8 (the segments a bucket holds). The Grid backend's own index (its voxel values,
    // searched next to the segments) keeps 2 median segments.
    out.bucket_size = params.bucket_size;
    if (out.bucket_size == 0.0)
        out.bucket_size = params.backend == FieldBackend::Grid
                              ? 2.0 * median
                              : std::max(2.0 * median, std::min(out.band_width, 8.0 * median));
    out.region = params.region;
    return out;
}

namespace {

void check_field_args(const Layer& layer, int outside_sign, const ResolvedFieldParams& params) {
    if (outside_sign != 1 && outside_sign != -1)
        throw InvalidInput("make_field: outside_sign must be +1 or -1 (got " +
                           std::to_string(outside_sign) + ") for layer '" + shown_text(layer.name) +
                           "'");
    if (!(params.voxel_size > 0.0) || !(params.band_width > 0.0) || !(params.bucket_size > 0.0) ||
        !std::isfinite(params.voxel_size) || !std::isfinite(params.band_width) ||
        !std::isfinite(params.bucket_size))
        throw InvalidInput(
            "make_field: resolved voxel_size, band_width and bucket_size must be "
            "finite and > 0 (got " +
            format_number(params.voxel_size) + ", " + format_number(params.band_width) + ", " +
            format_number(params.bucket_size) + ")");
}

}  // namespace

std::unique_ptr<LayerField> make_field(const Layer& layer, int outside_sign,
                                       const ResolvedFieldParams& params) {
    check_field_args(layer, outside_sign, params);
    switch (params.backend) {
        case FieldBackend::Grid:
            return detail::make_grid_field(layer, outside_sign, params);
        case FieldBackend::ExactBrute:
            return detail::make_exact_field(layer, outside_sign, params, false);
        case FieldBackend::ExactIndexed:
            return detail::make_exact_field(layer, outside_sign, params, true);
    }
    throw InvalidInput("make_field: params.backend is not a FieldBackend");
}

SceneFields::SceneFields(const Scene& scene, const FieldParams& params,
                         const std::vector<int>& outside_signs)
    : params_(resolve(params, scene)) {
    if (!outside_signs.empty() && outside_signs.size() != scene.size())
        throw InvalidInput("SceneFields: outside_signs has " +
                           std::to_string(outside_signs.size()) + " entries for " +
                           std::to_string(scene.size()) + " layers");
    std::vector<int> signs(scene.size(), 1);
    if (!outside_signs.empty()) signs = outside_signs;
    if (params_.backend == FieldBackend::Grid) {
        std::vector<const Layer*> layers;
        for (std::size_t i = 0; i < scene.size(); ++i) {
            check_field_args(scene.layer(i), signs[i], params_);
            layers.push_back(&scene.layer(i));
        }
        detail::GridFields grid = detail::make_grid_fields(layers, signs, params_);
        grid_ = std::move(grid.stack);
        fields_ = std::move(grid.fields);
        return;
    }
    // The layers side by side (a local untangling builds the fields of whole layers for a
    // few percent of them: the build is most of its fixed cost); an exception is the one of
    // the first layer that fails, as one after the other.
    fields_.resize(scene.size());
    detail::parallel_for_each_index(scene.size(), [&](std::size_t i) {
        fields_[i] = make_field(scene.layer(i), signs[i], params_);
    });
}

void SceneFields::sample_all(const Vec2& x, std::vector<FieldSample>& out) const {
    if (grid_) {
        detail::grid_sample_all(*grid_, x, out);
        return;
    }
    out.resize(fields_.size());
    for (std::size_t i = 0; i < fields_.size(); ++i) out[i] = fields_[i]->sample(x);
}

FieldStats SceneFields::total_stats() const {
    if (grid_) return detail::grid_total_stats(*grid_);
    FieldStats total;
    for (const auto& field : fields_) {
        const FieldStats st = field->stats();
        total.segments += st.segments;
        total.memory_bytes += st.memory_bytes;
        total.bounds.extend(st.bounds);
    }
    total.band_width = params_.band_width;
    return total;
}

}  // namespace strata
