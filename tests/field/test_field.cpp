#include "field/detail/grid_inspect.h"
#include "field/detail/segment_store.h"
#include "strata/core/error.h"
#include "strata/field/field.h"
#include "strata/io/json_io.h"
#include "support/fixtures.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace strata;

namespace {

constexpr double kPi = 3.14159265358979323846;

ResolvedFieldParams with_backend(ResolvedFieldParams p, FieldBackend b) {
    p.backend = b;
    return p;
}

ResolvedFieldParams explicit_params(double h, double band, FieldBackend b = FieldBackend::Grid) {
    ResolvedFieldParams p;
    p.backend = b;
    p.voxel_size = h;
    p.band_width = band;
    p.bucket_size = 4.0 * h;
    return p;
}

Layer make_layer(std::vector<Vec2> points, bool closed, const std::string& name = "l") {
    Layer layer;
    layer.name = name;
    layer.closed = closed;
    layer.points = std::move(points);
    return layer;
}

/// A simple closed star-shaped polygon: radius 1 + smooth random bumps.
Layer random_star(std::mt19937& rng, std::size_t n, bool clockwise) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double a1 = 0.2 * u(rng), a2 = 0.1 * u(rng), a5 = 0.05 * u(rng), ph = kPi * u(rng);
    std::vector<Vec2> pts;
    for (std::size_t i = 0; i < n; ++i) {
        double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        if (clockwise) t = -t;
        const double r = 1.0 + a1 * std::cos(t + ph) + a2 * std::sin(2.0 * t) +
                         a5 * std::cos(5.0 * t - ph) + 0.002 * u(rng);
        pts.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return make_layer(std::move(pts), true, "star");
}

/// A simple open x-monotone curve.
Layer random_graph(std::mt19937& rng, std::size_t n) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double a = 0.3 * u(rng), b = 0.2 * u(rng), ph = kPi * u(rng);
    std::vector<Vec2> pts;
    for (std::size_t i = 0; i < n; ++i) {
        const double x = 4.0 * static_cast<double>(i) / static_cast<double>(n - 1);
        pts.emplace_back(x, a * std::sin(2.0 * x + ph) + b * std::cos(5.0 * x) + 0.002 * u(rng));
    }
    return make_layer(std::move(pts), false, "graph");
}

double angle(const Vec2& a, const Vec2& b) {
    const double la = glm::length(a), lb = glm::length(b);
    if (la == 0.0 || lb == 0.0) return kPi;
    return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

/// Voxels of `field`'s plane (about `per_row` per row and column of the voxels of `box`) whose
/// sign is not the exact one; voxels on the curve are skipped, and with `band_only` those
/// outside the exact field's band. `checked` is increased by the voxels compared.
std::size_t voxel_sign_errors(const LayerField& field, const LayerField& exact, const Box2& box,
                              double h, int per_row, bool band_only, std::size_t& checked) {
    const int i0 = static_cast<int>(std::floor(box.min.x / h));
    const int i1 = static_cast<int>(std::ceil(box.max.x / h));
    const int j0 = static_cast<int>(std::floor(box.min.y / h));
    const int j1 = static_cast<int>(std::ceil(box.max.y / h));
    std::vector<int> signs;
    std::vector<char> active;
    detail::voxel_signs(field, i0, i1, j0, j1, signs, active);
    const int stride = std::max(1, (i1 - i0) / per_row);
    std::size_t errors = 0, k = 0;
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i, ++k) {
            if ((i - i0) % stride != 0 || (j - j0) % stride != 0) continue;
            const FieldSample es = exact.sample(Vec2(i * h, j * h));
            if (std::abs(es.value) < 1e-9) continue;
            if (band_only && !es.in_band) continue;
            ++checked;
            if (signs[k] != (es.value < 0.0 ? -1 : 1)) ++errors;
        }
    return errors;
}

/// Grid-vs-exact statistics over one layer.
struct Agreement {
    std::size_t in_band = 0, smooth = 0, sign_errors = 0, corner_mismatch = 0, jumps = 0;
    std::size_t voxel_sign_errors = 0, voxels_checked = 0;
    double max_error = 0.0;         // voxels, all in-band points
    double max_smooth_error = 0.0;  // voxels, smooth cells
    double max_smooth_angle = 0.0;  // radians, smooth cells
};

/// Smooth cell: the exact gradients at the four corners agree within kSmoothAngle.
constexpr double kSmoothAngle = 0.1;

Agreement compare(const Layer& layer, int outside_sign, const ResolvedFieldParams& p,
                  std::size_t queries, std::uint32_t seed, bool check_far_signs) {
    const auto grid = make_field(layer, outside_sign, with_backend(p, FieldBackend::Grid));
    const auto exact = make_field(layer, outside_sign, with_backend(p, FieldBackend::ExactIndexed));
    const double h = p.voxel_size;
    Agreement a;
    const Box2 box = layer.bounds().inflated(p.band_width);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> ux(box.min.x, box.max.x), uy(box.min.y, box.max.y);
    std::uniform_int_distribution<std::size_t> pick(0, layer.points.size() - 1);
    std::normal_distribution<double> near(0.0, 0.5 * p.band_width);
    for (std::size_t q = 0; q < queries; ++q) {
        // Half near the curve, half anywhere in the box.
        const Vec2 x = q % 2 == 0 ? layer.points[pick(rng)] + Vec2(near(rng), near(rng))
                                  : Vec2(ux(rng), uy(rng));
        const FieldSample g = grid->sample(x);
        if (!g.in_band) continue;
        ++a.in_band;
        const FieldSample e = exact->sample(x);
        const double err = std::abs(g.value - e.value) / h;
        const double ci = std::floor(x.x / h), cj = std::floor(x.y / h);
        double spread = 0.0;
        double corner[4];
        for (int di = 0; di < 2; ++di)
            for (int dj = 0; dj < 2; ++dj) {
                const Vec2 c((ci + di) * h, (cj + dj) * h);
                const FieldSample ec = exact->sample(c);
                const FieldSample gc = grid->sample(c);
                corner[2 * di + dj] = ec.value;
                // Corner values are the exact ones (up to the float rounding of values <= band
                // and of c / h).
                if (std::abs(gc.value - ec.value) > 1e-7 * p.band_width) ++a.corner_mismatch;
                spread = std::max(spread, angle(ec.gradient, e.gradient));
            }
        // Open layers: f jumps where the nearest feature switches between the extension past
        // an end and another part of the layer. Cells whose corners break the Lipschitz bound
        // straddle a jump: counted, excluded from the bounds.
        const double lip = h * (1.0 + 1e-6);
        if (std::abs(corner[0] - corner[1]) > lip || std::abs(corner[2] - corner[3]) > lip ||
            std::abs(corner[0] - corner[2]) > lip || std::abs(corner[1] - corner[3]) > lip ||
            std::abs(corner[0] - corner[3]) > std::sqrt(2.0) * lip ||
            std::abs(corner[1] - corner[2]) > std::sqrt(2.0) * lip) {
            ++a.jumps;
            continue;
        }
        a.max_error = std::max(a.max_error, err);
        if (std::abs(e.value) > 0.71 * h && (g.value < 0.0) != (e.value < 0.0)) ++a.sign_errors;
        if (spread <= kSmoothAngle) {
            ++a.smooth;
            a.max_smooth_error = std::max(a.max_smooth_error, err);
            a.max_smooth_angle = std::max(a.max_smooth_angle, angle(g.gradient, e.gradient));
        }
    }
    // Every voxel of the box (band voxels and flood-filled ones) has the exact sign.
    // Open layers out of the band: the region around an end connects both sides, so the flood
    // fill's sign there is arbitrary (docs/field.md); band voxels only.
    if (check_far_signs)
        a.voxel_sign_errors = voxel_sign_errors(*grid, *exact, box.inflated(4.0 * p.band_width), h,
                                                300, !layer.closed, a.voxels_checked);
    return a;
}

void require_agreement(const Agreement& a) {
    INFO("in band " << a.in_band << ", jump cells " << a.jumps << ", smooth " << a.smooth
                    << ", max error " << a.max_error << " voxel, smooth max error "
                    << a.max_smooth_error << " voxel, smooth max gradient angle "
                    << a.max_smooth_angle << " rad, voxel sign errors " << a.voxel_sign_errors
                    << " / " << a.voxels_checked);
    CHECK(a.in_band > 0);
    CHECK(a.corner_mismatch == 0);
    CHECK(a.sign_errors == 0);
    CHECK(a.voxel_sign_errors == 0);
    // Bilinear interpolation of a 1-Lipschitz function: |error| <= max over the cell of the
    // weighted corner distances <= sqrt(2) / 2 voxel.
    CHECK(a.max_error <= 0.7072);
    // Smooth cells (corner gradients within 0.1 rad): curvature radius >= h / (sqrt 2 * 0.1), so
    // |error| <= h^2 / (4 r) <= 0.036 h; asserted 0.05 h. Gradient error <= h |Hess| <= 0.15 rad.
    CHECK(a.max_smooth_error <= 0.05);
    CHECK(a.max_smooth_angle <= 0.15);
    WARN("in band " << a.in_band << ", smooth " << a.smooth << ", max error " << a.max_error
                    << " voxel, smooth max error " << a.max_smooth_error
                    << " voxel, smooth max gradient angle " << a.max_smooth_angle << " rad");
}

}  // namespace

namespace {

/// `count` copies of one random star scaled by 1, 1 + gap, 1 + 2 gap, ...: nested closed layers
/// closer than the band, so that they share leaves of the stacked grid.
Scene nested_stars(std::mt19937& rng, std::size_t count, std::size_t n, double gap) {
    const Layer star = random_star(rng, n, false);
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < count; ++k) {
        Layer l = star;
        l.name = "star" + std::to_string(k);
        for (Vec2& p : l.points) p *= 1.0 + gap * static_cast<double>(k);
        layers.push_back(std::move(l));
    }
    return Scene(layers);
}

bool same_sample(const FieldSample& a, const FieldSample& b) {
    return a.value == b.value && a.gradient == b.gradient && a.in_band == b.in_band &&
           (a.border == b.border || (std::isnan(a.border) && std::isnan(b.border))) &&
           a.past_end == b.past_end;
}

/// Query points: near every layer's vertices (in and just out of the band) and anywhere in the
/// scene's box inflated by 4 bands (tiles included).
std::vector<Vec2> scene_queries(const Scene& scene, double band, std::size_t count,
                                std::uint32_t seed) {
    std::mt19937 rng(seed);
    Box2 box;
    for (const Layer& l : scene.layers()) box.extend(l.bounds());
    box = box.inflated(4.0 * band);
    std::uniform_real_distribution<double> ux(box.min.x, box.max.x), uy(box.min.y, box.max.y);
    std::normal_distribution<double> near(0.0, band);
    std::vector<Vec2> out;
    for (std::size_t q = 0; q < count; ++q) {
        if (q % 2 == 0) {
            out.emplace_back(ux(rng), uy(rng));
        } else {
            const Layer& l = scene.layer(q / 2 % scene.size());
            const Vec2& p = l.points[(q * 7919) % l.points.size()];
            out.push_back(p + Vec2(near(rng), near(rng)));
        }
    }
    return out;
}

}  // namespace

TEST_CASE("validate and resolve FieldParams", "[field]") {
    FieldParams bad;
    bad.voxel_size = -1.0;
    CHECK_THROWS_AS(validate(bad), InvalidInput);
    bad.voxel_size = std::nan("");
    CHECK_THROWS_AS(validate(bad), InvalidInput);
    FieldParams ok;
    CHECK_NOTHROW(validate(ok));

    const Scene circles = test::nested_circles(2, 100, 1.0, 0.25, 0.0);
    const ResolvedFieldParams r = resolve(ok, circles);
    // Two regular 100-gons of radii 1 and 1.25: the median segment is the outer one.
    const double seg = 2.0 * 1.25 * std::sin(kPi / 100.0);
    CHECK(r.voxel_size == Approx(0.25 * seg));
    CHECK(r.band_width == Approx(2.0 * seg + 2.0 * r.voxel_size));
    CHECK(r.bucket_size == Approx(2.0 * seg));  // the grid's own index
    // ExactIndexed: the band, within 2-8 median segments.
    FieldParams indexed;
    indexed.backend = FieldBackend::ExactIndexed;
    CHECK(resolve(indexed, circles).bucket_size == Approx(r.band_width));
    FieldParams narrow = indexed;
    narrow.band_width = 0.5 * seg;
    CHECK(resolve(narrow, circles).bucket_size == Approx(2.0 * seg));
    FieldParams wide = indexed;
    wide.band_width = 100.0 * seg;
    CHECK(resolve(wide, circles).bucket_size == Approx(8.0 * seg));
    FieldParams tight;
    tight.voxel_size = 0.0;
    const Scene thin = test::nested_circles(2, 100, 1.0, 0.25, 0.004);
    CHECK(resolve(tight, thin).voxel_size == Approx(0.002));  // half the separation 0.004
}

TEST_CASE("closed layers are negative inside for both windings", "[field]") {
    std::mt19937 rng(7);
    for (bool clockwise : {false, true}) {
        const Layer star = random_star(rng, 200, clockwise);
        for (FieldBackend b :
             {FieldBackend::Grid, FieldBackend::ExactBrute, FieldBackend::ExactIndexed}) {
            for (int sign : {1, -1}) {
                const auto f = make_field(star, sign, explicit_params(0.01, 0.05, b));
                CHECK(f->sample(Vec2(0.0)).value < 0.0);
                CHECK(f->sample(Vec2(3.0, 0.5)).value > 0.0);
                CHECK(f->sample(Vec2(-0.3, 0.2)).value < 0.0);
                const FieldSample s = f->sample(Vec2(0.0));
                CHECK(s.border == std::numeric_limits<double>::infinity());
                if (b != FieldBackend::Grid) {
                    CHECK_FALSE(s.in_band);
                }
            }
        }
    }
}

TEST_CASE("exact brute force and indexed backends agree exactly", "[field]") {
    // sample_in_band() is checked against sample() here too.
    std::mt19937 rng(11);
    std::vector<Layer> layers;
    for (int k = 0; k < 3; ++k) {
        layers.push_back(random_star(rng, 150 + 50 * static_cast<std::size_t>(k), k == 1));
        layers.push_back(random_graph(rng, 120 + 60 * static_cast<std::size_t>(k)));
    }
    layers.push_back(test::spiral(3.0, 300).layer(0));
    std::uniform_real_distribution<double> u(-3.0, 5.0);
    for (const Layer& layer : layers) {
        for (double cell : {0.01, 0.05, 0.3}) {
            ResolvedFieldParams p = explicit_params(0.01, 0.05);
            p.bucket_size = cell;
            const auto brute = make_field(layer, 1, with_backend(p, FieldBackend::ExactBrute));
            const auto indexed = make_field(layer, 1, with_backend(p, FieldBackend::ExactIndexed));
            std::size_t differ = 0, differ_in_band = 0, in_band = 0;
            for (int q = 0; q < 2000; ++q) {
                Vec2 x(u(rng), u(rng));
                if (q % 3 == 0) x = layer.points[static_cast<std::size_t>(q) % layer.points.size()];
                if (q % 3 == 1) x = 0.5 * (layer.points[0] + layer.points[1]);  // exact ties
                if (q == 5) x = Vec2(1e6, -1e6);
                if (q % 7 == 6)  // near the curve: in and just out of the band (0.05)
                    x = layer.points[static_cast<std::size_t>(q) % layer.points.size()] +
                        Vec2(0.07 * u(rng) / 5.0, 0.07 * u(rng) / 5.0);
                const FieldSample a = brute->sample(x), b = indexed->sample(x);
                if (a.value != b.value || a.gradient != b.gradient || a.in_band != b.in_band ||
                    a.border != b.border)
                    ++differ;
                // sample_in_band(): the same answer in the band, "out of band" outside it.
                for (const auto* field : {brute.get(), indexed.get()}) {
                    const FieldSample c = field->sample_in_band(x);
                    if (c.in_band != a.in_band) ++differ_in_band;
                    if (c.in_band &&
                        (c.value != a.value || c.gradient != a.gradient || c.border != a.border))
                        ++differ_in_band;
                    in_band += c.in_band ? 1 : 0;
                }
            }
            CHECK(differ == 0);
            CHECK(differ_in_band == 0);
            CHECK(in_band > 400);  // both branches of sample_in_band() were taken
            CHECK(in_band < 2 * 2000 - 400);
        }
    }
}

TEST_CASE("open layers: sides, extension past the ends and border field", "[field]") {
    const Layer line = make_layer({{0, 0}, {0.5, 0}, {1, 0}, {1.5, 0}, {2, 0}}, false);
    for (FieldBackend b :
         {FieldBackend::Grid, FieldBackend::ExactBrute, FieldBackend::ExactIndexed}) {
        // Travel is +x: the right is -y, the outside for outside_sign = +1.
        const auto f = make_field(line, 1, explicit_params(0.0625, 1.0, b));
        const double tol = b == FieldBackend::Grid ? 1e-6 : 1e-12;
        FieldSample s = f->sample(Vec2(1.0, -0.25));
        CHECK(s.value == Approx(0.25).margin(tol));
        CHECK(s.border == Approx(1.0));
        s = f->sample(Vec2(1.0, 0.25));
        CHECK(s.value == Approx(-0.25).margin(tol));
        CHECK(s.gradient.y == Approx(-1.0).margin(1e-5));
        // Beyond the last end c = (2, 0), t = (1, 0), n = (0, -1): value (x - c).n, b = (c - x).t.
        s = f->sample(Vec2(2.5, 0.375));
        CHECK(s.value == Approx(-0.375).margin(tol));
        CHECK(s.border == Approx(-0.5));
        CHECK(s.in_band);
        // Beyond the first end c = (0, 0), t = (-1, 0).
        s = f->sample(Vec2(-0.5, -0.125));
        CHECK(s.value == Approx(0.125).margin(tol));
        CHECK(s.border == Approx(-0.5));
        // Over the layer near the first end: b > 0.
        CHECK(f->sample(Vec2(0.25, 0.1)).border == Approx(0.25));
        const auto flipped = make_field(line, -1, explicit_params(0.0625, 1.0, b));
        CHECK(flipped->sample(Vec2(1.0, -0.25)).value == Approx(-0.25).margin(tol));
        CHECK(flipped->sample(Vec2(2.5, 0.375)).value == Approx(0.375).margin(tol));
        CHECK(flipped->outside_sign() == -1);
    }
}

TEST_CASE("past_end: past an end only where the nearest feature is that end", "[field]") {
    // A layer folded back beside its own start: (0, 0) -> (2, 0), then a fold to the left of
    // x = 0 and back to (2, 1). Left of x = 0 the border field of the start is negative, but
    // near the fold the nearest feature is the fold, not the start.
    const Layer folded = make_layer(
        {{0, 0}, {1, 0}, {2, 0}, {2, 0.5}, {0, 0.5}, {-0.5, 0.75}, {0, 1}, {2, 1}}, false);
    for (FieldBackend b :
         {FieldBackend::Grid, FieldBackend::ExactBrute, FieldBackend::ExactIndexed}) {
        const auto f = make_field(folded, 1, explicit_params(0.0625, 1.0, b));
        const FieldSample past = f->sample(Vec2(-0.25, -0.125));  // nearest: the start
        CHECK(past.border < 0.0);
        CHECK(past.past_end);
        const FieldSample fold = f->sample(Vec2(-0.75, 0.625));  // nearest: the fold
        CHECK(fold.border < 0.0);
        CHECK(fold.past_end == (b == FieldBackend::Grid));  // the grid cannot tell
        CHECK_FALSE(f->sample(Vec2(1.0, 0.25)).past_end);
    }
}

TEST_CASE("the sign at a vertex comes from the pseudo-normal", "[field]") {
    // A right angle: (0,1) -> (0,0) -> (1,0). Outside on the right of travel: west of the
    // downward leg, south of the eastward one, so the outer corner side.
    const Layer corner = make_layer({{0, 1}, {0, 0}, {1, 0}}, false);
    for (FieldBackend b :
         {FieldBackend::ExactBrute, FieldBackend::ExactIndexed, FieldBackend::Grid}) {
        const auto f = make_field(corner, 1, explicit_params(0.03125, 0.5, b));
        CHECK(f->sample(Vec2(-0.1, -0.1)).value > 0.0);  // outer corner, nearest = the vertex
        CHECK(f->sample(Vec2(0.1, 0.2)).value < 0.0);
        // On the bisector of the inner corner (a kink of f): the grid is off by up to h / 2.
        CHECK(f->sample(Vec2(0.1, 0.1)).value ==
              Approx(-0.1).margin(b == FieldBackend::Grid ? 0.5 * 0.03125 : 1e-12));
        CHECK(f->sample(Vec2(-0.1, -0.1)).value == Approx(std::sqrt(0.02)).margin(1e-3));
    }
}

TEST_CASE("BoxSampler at z = 0 is the bilinear interpolant", "[field]") {
    std::mt19937 rng(3);
    const Layer star = random_star(rng, 300, false);
    const auto f = make_field(star, 1, explicit_params(0.01, 0.06));
    std::vector<Vec2> pts;
    std::uniform_real_distribution<double> u(-1.4, 1.4);
    for (int i = 0; i < 20000; ++i) pts.emplace_back(u(rng), u(rng));
    // OpenVDB interpolates in float; ours in double: equal to float rounding of values <= band.
    CHECK(detail::max_box_sampler_difference(*f, pts) <= 1e-7);
    // Layers of a shared stack: the slab of each (its z plane, flood filled) is its field too.
    const Scene stack = nested_stars(rng, 3, 300, 0.03);
    const SceneFields fields(stack);
    for (std::size_t i = 0; i < stack.size(); ++i)
        CHECK(detail::max_box_sampler_difference(fields.field(i), pts) <= 1e-7);
}

TEST_CASE("grid agrees with the exact field: circles, sines, spiral", "[field]") {
    SECTION("circles") {
        const Scene scene = test::nested_circles(3, 256, 1.0, 0.25);
        const ResolvedFieldParams p = resolve({}, scene);
        for (std::size_t i = 0; i < scene.size(); ++i)
            require_agreement(
                compare(scene.layer(i), 1, p, 6000, 1 + static_cast<std::uint32_t>(i), true));
    }
    SECTION("sines") {
        const Scene scene = test::stacked_sines(3, 400);
        const ResolvedFieldParams p = resolve({}, scene);
        for (std::size_t i = 0; i < scene.size(); ++i)
            require_agreement(
                compare(scene.layer(i), 1, p, 6000, 7 + static_cast<std::uint32_t>(i), true));
    }
    SECTION("spiral") {
        const Scene scene = test::spiral(3.0, 600);
        const ResolvedFieldParams p = resolve({}, scene);
        require_agreement(compare(scene.layer(0), 1, p, 6000, 5, true));
    }
}

TEST_CASE("grid agrees with the exact field: random simple polylines", "[field]") {
    std::mt19937 rng(2024);
    for (int k = 0; k < 6; ++k) {
        const Layer layer =
            k % 2 == 0 ? random_star(rng, 100 + 80 * static_cast<std::size_t>(k), k % 4 == 0)
                       : random_graph(rng, 100 + 80 * static_cast<std::size_t>(k));
        const Scene scene({layer});
        FieldParams fp;
        if (k >= 3) fp.expected_penetration = 0.05;
        const ResolvedFieldParams p = resolve(fp, scene);
        INFO("random layer " << k);
        require_agreement(compare(layer, k % 3 == 1 ? -1 : 1, p, 5000,
                                  100 + static_cast<std::uint32_t>(k), true));
    }
}

TEST_CASE("grid agrees with the exact field: real slices", "[field][slow]") {
    for (const char* file :
         {"slices/cipc_multilayer_y+0.00.json", "slices/mh_casualsuit03_y+1.50.json",
          "slices/mh_elegantsuit01_y+0.50.json"}) {
        INFO(file);
        const Scene scene = read_scene_json(test::test_data(file));
        const ResolvedFieldParams p = resolve({}, scene);
        for (std::size_t i = 0; i < scene.size(); ++i) {
            INFO("layer " << scene.layer(i).name);
            require_agreement(
                compare(scene.layer(i), 1, p, 3000, 50 + static_cast<std::uint32_t>(i), true));
        }
    }
}

namespace {

/// Applies a random local edit to `points`; returns it.
PolylineEdit random_edit(std::mt19937& rng, std::vector<Vec2>& points, double scale) {
    std::uniform_int_distribution<int> kind(0, 3);
    std::uniform_real_distribution<double> u(-scale, scale);
    const std::size_t n = points.size();
    std::uniform_int_distribution<std::size_t> at(0, n - 4);
    const std::size_t i = at(rng);
    switch (kind(rng)) {
        case 0:  // move one vertex
            points[i] += Vec2(u(rng), u(rng));
            return {i, 1, 1};
        case 1:  // remove one vertex
            points.erase(points.begin() + static_cast<std::ptrdiff_t>(i));
            return {i, 1, 0};
        case 2: {  // insert one vertex between i and i + 1
            const Vec2 m = 0.5 * (points[i] + points[i + 1]) + Vec2(0.2 * u(rng), 0.2 * u(rng));
            points.insert(points.begin() + static_cast<std::ptrdiff_t>(i + 1), m);
            return {i + 1, 0, 1};
        }
        default:  // move three vertices
            for (std::size_t k = i; k < i + 3; ++k) points[k] += Vec2(0.5 * u(rng), 0.5 * u(rng));
            return {i, 3, 3};
    }
}

}  // namespace

TEST_CASE("localized updates equal a full rebuild", "[field]") {
    std::mt19937 rng(99);
    for (int k = 0; k < 4; ++k) {
        Layer layer = k % 2 == 0 ? random_star(rng, 400, k == 2) : random_graph(rng, 400);
        const Scene scene({layer});
        const ResolvedFieldParams p = resolve({}, scene);
        const int sign = k == 3 ? -1 : 1;
        auto grid = make_field(layer, sign, with_backend(p, FieldBackend::Grid));
        auto brute = make_field(layer, sign, with_backend(p, FieldBackend::ExactBrute));
        auto indexed = make_field(layer, sign, with_backend(p, FieldBackend::ExactIndexed));
        for (int step = 0; step < 40; ++step) {
            const PolylineEdit edit = random_edit(rng, layer.points, 0.02);
            grid->update(layer.points, edit);
            brute->update(layer.points, edit);
            indexed->update(layer.points, edit);
            if (step % 8 != 7) continue;
            const auto fresh = make_field(layer, sign, with_backend(p, FieldBackend::Grid));
            std::string why;
            INFO("layer " << k << " step " << step << ": " << why);
            CHECK(detail::grids_identical(*grid, *fresh, &why));
            INFO(why);
            const auto fresh_exact =
                make_field(layer, sign, with_backend(p, FieldBackend::ExactBrute));
            std::uniform_real_distribution<double> u(-1.5, 4.5);
            std::size_t differ = 0;
            for (int q = 0; q < 500; ++q) {
                const Vec2 x(u(rng), u(rng));
                const FieldSample a = fresh_exact->sample(x), b = brute->sample(x),
                                  c = indexed->sample(x);
                if (a.value != b.value || a.value != c.value || a.gradient != b.gradient ||
                    a.gradient != c.gradient || a.border != c.border)
                    ++differ;
            }
            CHECK(differ == 0);
        }
        CHECK(grid->stats().segments == layer.segment_count());
    }
}

TEST_CASE("indexed field: a vertex carried far away keeps memory bounded and answers exact",
          "[field]") {
    // A runaway vertex (seen in an untangling of a rolled scene) made one segment span 1e8
    // buckets: it now goes to the index's plain list instead of the buckets.
    std::mt19937 rng(5);
    Layer layer = random_star(rng, 200, false);
    const Scene scene({layer});
    ResolvedFieldParams p = resolve({}, scene);
    p.bucket_size = 0.01;
    auto brute = make_field(layer, 1, with_backend(p, FieldBackend::ExactBrute));
    auto indexed = make_field(layer, 1, with_backend(p, FieldBackend::ExactIndexed));
    const std::size_t before = indexed->stats().memory_bytes;
    for (const Vec2& far : {Vec2(1e6, 3e5), Vec2(-2e6, 1e6), Vec2(0.5, 0.5)}) {
        layer.points[7] = far;
        const PolylineEdit edit{7, 1, 1};
        brute->update(layer.points, edit);
        indexed->update(layer.points, edit);
        CHECK(indexed->stats().memory_bytes < 2 * before + 4096);
        std::uniform_real_distribution<double> u(-3.0, 5.0);
        std::size_t differ = 0;
        for (int q = 0; q < 500; ++q) {
            Vec2 x(u(rng), u(rng));
            if (q % 50 == 0) x = 0.5 * far + Vec2(u(rng), u(rng));  // near the long segments
            const FieldSample a = brute->sample(x), b = indexed->sample(x);
            if (a.value != b.value || a.gradient != b.gradient || a.border != b.border) ++differ;
        }
        CHECK(differ == 0);
    }
}

TEST_CASE("indexed field: a small layer far from the origin (buckets from its corner)", "[field]") {
    // Found by fuzz_pipeline: the legs family at scale 1.3e-3 offset by 8.5e5 was refused
    // ("too large for the bucket size") when buckets were counted from the scene's origin.
    std::mt19937 rng(8);
    Layer layer = random_star(rng, 150, true);
    for (Vec2& p : layer.points) p = 1.3e-3 * p + Vec2(8.5e5, -8.5e5);
    const Scene scene({layer});
    const ResolvedFieldParams p = resolve({}, scene);
    const auto brute = make_field(layer, 1, with_backend(p, FieldBackend::ExactBrute));
    std::unique_ptr<LayerField> indexed;
    REQUIRE_NOTHROW(indexed = make_field(layer, 1, with_backend(p, FieldBackend::ExactIndexed)));
    std::uniform_real_distribution<double> u(-0.01, 0.01);
    std::size_t differ = 0;
    for (int q = 0; q < 500; ++q) {
        const Vec2 x =
            layer.points[static_cast<std::size_t>(q) % layer.points.size()] + Vec2(u(rng), u(rng));
        const FieldSample a = brute->sample(x), b = indexed->sample(x);
        if (a.value != b.value || a.gradient != b.gradient || a.border != b.border) ++differ;
    }
    CHECK(differ == 0);
}

TEST_CASE("the blocked slot sequence splices like a vector", "[field]") {
    // Enough entries for several blocks; edits that empty blocks, split them and touch the ends.
    detail::SlotSequence seq;
    std::vector<std::uint32_t> ref(5000);
    seq.assign(ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) ref[i] = static_cast<std::uint32_t>(i);
    std::mt19937 rng(17);
    std::uint32_t next = 100000;
    std::vector<std::uint32_t> got;
    for (int step = 0; step < 3000; ++step) {
        std::uniform_int_distribution<std::size_t> at(0, ref.size());
        const std::size_t first = at(rng);
        std::size_t count =
            std::min<std::size_t>(ref.size() - first, static_cast<std::size_t>(step % 5));
        std::size_t inserted = static_cast<std::size_t>(step % 7);
        if (step % 500 == 250) count = std::min<std::size_t>(ref.size() - first, 1500);
        if (step % 500 == 0) inserted = 2500;
        if (ref.size() < 100) inserted += 50;
        std::vector<std::uint32_t> values(inserted);
        for (auto& v : values) v = next++;
        seq.replace(first, count, values);
        ref.erase(ref.begin() + static_cast<std::ptrdiff_t>(first),
                  ref.begin() + static_cast<std::ptrdiff_t>(first + count));
        ref.insert(ref.begin() + static_cast<std::ptrdiff_t>(first), values.begin(), values.end());
        REQUIRE(seq.size() == ref.size());
        const std::size_t probe = std::min<std::size_t>(first, ref.size() - 1);
        const std::size_t len = std::min<std::size_t>(ref.size() - probe, 9);
        seq.read(probe, len, got);
        REQUIRE(
            std::equal(got.begin(), got.end(), ref.begin() + static_cast<std::ptrdiff_t>(probe)));
    }
    seq.read(0, ref.size(), got);
    CHECK(got == ref);
    seq.replace(0, ref.size(), {});
    CHECK(seq.size() == 0);
    seq.replace(0, 0, {7, 8});
    seq.read(0, 2, got);
    CHECK(got == std::vector<std::uint32_t>{7, 8});
}

TEST_CASE("localized updates equal a full rebuild on a layer of several index blocks", "[field]") {
    // 6000 segments: the segment index spans several blocks of the slot sequence.
    std::mt19937 rng(31);
    Layer layer = random_star(rng, 6000, false);
    const Scene scene({layer});
    const ResolvedFieldParams p = resolve({}, scene);
    auto grid = make_field(layer, 1, with_backend(p, FieldBackend::Grid));
    auto indexed = make_field(layer, 1, with_backend(p, FieldBackend::ExactIndexed));
    for (int step = 0; step < 200; ++step) {
        const PolylineEdit edit = random_edit(rng, layer.points, 0.002);
        grid->update(layer.points, edit);
        indexed->update(layer.points, edit);
    }
    const auto fresh = make_field(layer, 1, with_backend(p, FieldBackend::Grid));
    std::string why;
    CHECK(detail::grids_identical(*grid, *fresh, &why));
    INFO(why);
    const auto brute = make_field(layer, 1, with_backend(p, FieldBackend::ExactBrute));
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::size_t differ = 0;
    for (int q = 0; q < 500; ++q) {
        const Vec2 x(u(rng), u(rng));
        const FieldSample a = brute->sample(x), b = indexed->sample(x);
        if (a.value != b.value || a.gradient != b.gradient) ++differ;
    }
    CHECK(differ == 0);
    CHECK(grid->stats().segments == layer.segment_count());
}

TEST_CASE("bad edits throw and leave the field unchanged", "[field]") {
    std::mt19937 rng(5);
    const Layer layer = random_graph(rng, 50);
    for (FieldBackend b :
         {FieldBackend::Grid, FieldBackend::ExactBrute, FieldBackend::ExactIndexed}) {
        const auto f = make_field(layer, 1, explicit_params(0.02, 0.1, b));
        const double before = f->sample(Vec2(1.0, 0.05)).value;
        CHECK_THROWS_AS(f->update(layer.points, {10, 1, 0}), InvalidInput);
        std::vector<Vec2> bad = layer.points;
        bad[3].x = std::nan("");
        CHECK_THROWS_AS(f->update(bad, {3, 1, 1}), InvalidInput);
        CHECK(f->sample(Vec2(1.0, 0.05)).value == before);
        CHECK_THROWS_AS(make_field(layer, 0, explicit_params(0.02, 0.1, b)), InvalidInput);
    }
}

TEST_CASE("SceneFields samples every layer", "[field]") {
    const Scene scene = test::nested_circles(3, 128);
    const SceneFields fields(scene);
    std::vector<FieldSample> out;
    fields.sample_all(Vec2(1.1, 0.0), out);
    REQUIRE(out.size() == 3);
    CHECK(out[0].value > 0.0);
    CHECK(out[1].value < 0.0);
    CHECK(out[2].value < 0.0);
    const FieldStats st = fields.field(0).stats();
    CHECK(st.segments == 128);
    CHECK(st.leaves > 0);
    CHECK(st.active_voxels > 0);
    CHECK(st.memory_bytes > 0);
}

TEST_CASE("stacked grid: layers share leaves and keep their own planes", "[field]") {
    std::mt19937 rng(41);
    const Scene scene = nested_stars(rng, 3, 400, 0.03);
    const SceneFields fields(scene);
    const ResolvedFieldParams& p = fields.params();
    REQUIRE(p.band_width > 0.03);  // neighbours are within the band of each other
    CHECK(detail::shared_leaf_count(fields.field(0), fields.field(1)) > 10);
    CHECK(detail::shared_leaf_count(fields.field(0), fields.field(2)) > 0);
    const FieldStats total = fields.total_stats();
    std::size_t sum_leaves = 0, sum_bytes = 0, sum_active = 0;
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const FieldStats st = fields.field(i).stats();
        sum_leaves += st.leaves;
        sum_bytes += st.memory_bytes;
        sum_active += st.active_voxels;
        // Some leaves of the stack hold no band voxel of layer i: its plane there is uniform.
        CHECK(st.leaves < total.leaves);
    }
    CHECK(total.leaves < sum_leaves);  // shared leaves are counted once
    CHECK(total.active_voxels == sum_active);
    // Each layer's share of the grid is rounded down: the total is at most one byte per layer
    // more than the sum.
    CHECK(sum_bytes <= total.memory_bytes);
    CHECK(total.memory_bytes - sum_bytes <= scene.size());
    CHECK(total.segments == 3 * 400);

    // A closed layer's field does not depend on the layers it shares the grid with: bit for bit
    // the field of a stack of one, everywhere (band values, spread and uniform planes, tiles).
    const std::vector<Vec2> qs = scene_queries(scene, p.band_width, 20000, 5);
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const auto alone = make_field(scene.layer(i), 1, p);
        std::size_t differ = 0, in_band = 0;
        for (const Vec2& x : qs) {
            const FieldSample a = fields.field(i).sample(x), b = alone->sample(x);
            if (!same_sample(a, b)) ++differ;
            in_band += a.in_band ? 1u : 0u;
        }
        INFO("layer " << i);
        CHECK(differ == 0);
        CHECK(in_band > 1000);
    }

    // Every voxel of every plane (band, spread, uniform, out of every leaf) has the exact sign.
    Box2 box;
    for (const Layer& l : scene.layers()) box.extend(l.bounds());
    box = box.inflated(5.0 * p.band_width);
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const auto exact =
            make_field(scene.layer(i), 1, with_backend(p, FieldBackend::ExactIndexed));
        std::size_t checked = 0;
        CHECK(voxel_sign_errors(fields.field(i), *exact, box, p.voxel_size, 200, false, checked) ==
              0);
        CHECK(checked > 10000);
    }
}

TEST_CASE("stacked grid: sample_all equals every layer's sample", "[field]") {
    std::mt19937 rng(43);
    for (std::size_t count : {1u, 3u, 9u}) {
        const Scene scene = nested_stars(rng, count, 200, 0.02);
        for (FieldBackend b : {FieldBackend::Grid, FieldBackend::ExactIndexed}) {
            FieldParams fp;
            fp.backend = b;
            const SceneFields fields(scene, fp);
            std::vector<FieldSample> all;
            std::size_t differ = 0, in_band = 0;
            for (const Vec2& x : scene_queries(scene, fields.params().band_width, 6000, 9)) {
                fields.sample_all(x, all);
                REQUIRE(all.size() == count);
                for (std::size_t i = 0; i < count; ++i) {
                    if (!same_sample(all[i], fields.field(i).sample(x))) ++differ;
                    in_band += all[i].in_band ? 1u : 0u;
                }
            }
            INFO(count << " layers, backend " << static_cast<int>(b));
            CHECK(differ == 0);
            CHECK(in_band > 500);
        }
    }
}

TEST_CASE("stacked grid: 9 layers span two leaf rows", "[field]") {
    // Layers 0-7 in the leaves of z in [0, 8), layer 8 alone in the row z in [8, 16).
    std::mt19937 rng(47);
    const Scene scene = nested_stars(rng, 9, 300, 0.02);
    const SceneFields fields(scene);
    const ResolvedFieldParams& p = fields.params();
    CHECK(detail::shared_leaf_count(fields.field(7), fields.field(8)) == 0);  // other rows
    CHECK(detail::shared_leaf_count(fields.field(6), fields.field(7)) > 0);
    Box2 box;
    for (const Layer& l : scene.layers()) box.extend(l.bounds());
    box = box.inflated(5.0 * p.band_width);
    const std::vector<Vec2> qs = scene_queries(scene, p.band_width, 4000, 3);
    for (std::size_t i : {0u, 7u, 8u}) {
        INFO("layer " << i);
        const auto exact =
            make_field(scene.layer(i), 1, with_backend(p, FieldBackend::ExactIndexed));
        std::size_t checked = 0;
        CHECK(voxel_sign_errors(fields.field(i), *exact, box, p.voxel_size, 200, false, checked) ==
              0);
        const auto alone = make_field(scene.layer(i), 1, p);
        std::size_t differ = 0;
        for (const Vec2& x : qs)
            if (!same_sample(fields.field(i).sample(x), alone->sample(x))) ++differ;
        CHECK(differ == 0);
    }
}

TEST_CASE("stacked grid: updates of several layers equal a rebuild of the scene", "[field]") {
    std::mt19937 rng(53);
    for (std::size_t count : {3u, 9u}) {
        Scene scene = nested_stars(rng, count, 300, 0.02);
        // One open layer in the stack too: a graph through the stars.
        std::vector<Layer> layers = scene.layers();
        Layer graph = random_graph(rng, 200);
        for (Vec2& q : graph.points) q += Vec2(-2.0, 0.1);
        layers.insert(layers.begin() + 1, graph);
        scene = Scene(layers);
        SceneFields fields(scene);
        const FieldParams fixed = [&] {
            FieldParams fp;
            fp.voxel_size = fields.params().voxel_size;
            fp.band_width = fields.params().band_width;
            fp.bucket_size = fields.params().bucket_size;
            return fp;
        }();
        REQUIRE(detail::shared_leaf_count(fields.field(0), fields.field(2)) > 0);
        std::uniform_int_distribution<std::size_t> pick(0, scene.size() - 1);
        for (int step = 0; step < 120; ++step) {
            const std::size_t l = pick(rng);
            std::vector<Vec2> pts = scene.layer(l).points;
            const PolylineEdit edit = random_edit(rng, pts, 0.008);
            fields.field(l).update(pts, edit);
            layers[l].points = pts;
            scene = Scene(layers);
            if (step % 30 != 29) continue;
            const SceneFields fresh(scene, fixed);
            for (std::size_t i = 0; i < scene.size(); ++i) {
                std::string why;
                const bool same = detail::grids_identical(fields.field(i), fresh.field(i), &why);
                INFO(count << " stars, step " << step << ", layer " << i << ": " << why);
                CHECK(same);
            }
            CHECK(fields.total_stats().leaves == fresh.total_stats().leaves);
            CHECK(fields.total_stats().active_voxels == fresh.total_stats().active_voxels);
        }
        CHECK(detail::shared_leaf_count(fields.field(0), fields.field(2)) > 0);
    }
}

TEST_CASE("stacked grid: a layer swept across others' leaves updates its planes there", "[field]") {
    // Layer 2 dented deep through layers 0 and 1 (which share leaves) and back, then pushed out
    // into empty space: its uniform planes in their leaves flip sign far from its band (inside
    // the loop of the old and new chains), leaves are created (the other layers' planes signed
    // there) and removed again.
    std::vector<Layer> layers = test::nested_circles(2, 256, 1.0, 0.05).layers();
    Layer outer = test::nested_circles(1, 256, 1.3).layer(0);
    outer.name = "outer";
    layers.push_back(outer);
    Scene scene(layers);
    SceneFields fields(scene);
    FieldParams fixed;
    fixed.voxel_size = fields.params().voxel_size;
    fixed.band_width = fields.params().band_width;
    fixed.bucket_size = fields.params().bucket_size;
    REQUIRE(detail::shared_leaf_count(fields.field(0), fields.field(1)) > 10);
    REQUIRE(0.25 > 2.0 * fields.params().band_width);
    const std::size_t first = 10, count = 21;
    for (double radius : {0.55, 1.3, 1.9, 1.3}) {
        for (std::size_t k = first; k < first + count; ++k)
            layers[2].points[k] = outer.points[k] * (radius / 1.3);
        scene = Scene(layers);
        fields.field(2).update(scene.layer(2).points, {first, count, count});
        const SceneFields fresh(scene, fixed);
        for (std::size_t i = 0; i < 3; ++i) {
            std::string why;
            const bool same = detail::grids_identical(fields.field(i), fresh.field(i), &why);
            INFO("radius " << radius << ", layer " << i << ": " << why);
            CHECK(same);
        }
        // Inside the dent, on layer 0's curve: outside layer 2 (positive) when dented.
        const Vec2 probe = scene.layer(0).points[first + count / 2];
        CHECK((fields.field(2).sample(probe).value > 0.0) == (radius < 1.0));
    }
}

TEST_CASE("out-of-band signs are exact far from every leaf", "[field]") {
    // A square 10000 voxels wide: its centre lies in no root child (no leaf within one root
    // child's 1024 voxels, nor within the 4096 of OpenVDB's default tree), which a flood fill
    // of the internal nodes could not sign.
    const Layer square =
        make_layer({{0, 0}, {10000, 0}, {10000, 10000}, {0, 10000}}, true, "square");
    const auto f = make_field(square, 1, explicit_params(1.0, 3.0));
    for (const Vec2& x : {Vec2(5000.5, 5000.5), Vec2(100.25, 9000.0), Vec2(9990.0, 20.0)})
        CHECK(f->sample(x).value == -3.0);
    for (const Vec2& x : {Vec2(-5000.0, 5000.0), Vec2(15000.0, 5000.0), Vec2(5000.0, 20000.0)})
        CHECK(f->sample(x).value == 3.0);
    std::vector<int> signs;
    std::vector<char> active;
    detail::voxel_signs(*f, -20, 10020, 5000, 5000, signs, active);
    std::size_t wrong = 0;
    for (std::size_t k = 0; k < signs.size(); ++k) {
        const int i = -20 + static_cast<int>(k);
        if (i != 0 && i != 10000 && signs[k] != (i > 0 && i < 10000 ? -1 : 1)) ++wrong;
    }
    CHECK(wrong == 0);
}

TEST_CASE("stacked grid: a real 9-layer slice with an open layer", "[field]") {
    // Body, suit (one open piece) and six small loops far from them: layers 0-7 in the first leaf
    // row, layer 8 in the second.
    Scene scene = read_scene_json(test::test_data("slices/mh_casualsuit03_y+1.50.json"));
    REQUIRE(scene.size() == 9);
    SceneFields fields(scene);
    const ResolvedFieldParams& p = fields.params();
    const std::vector<Vec2> qs = scene_queries(scene, p.band_width, 20000, 13);
    for (std::size_t i = 0; i < scene.size(); ++i) {
        INFO("layer " << scene.layer(i).name);
        const auto alone = make_field(scene.layer(i), 1, p);
        std::size_t differ = 0;
        for (const Vec2& x : qs) {
            const FieldSample a = fields.field(i).sample(x), b = alone->sample(x);
            // An open layer's sign out of its band carries no information: band samples only.
            if (scene.layer(i).closed ? !same_sample(a, b)
                                      : a.in_band != b.in_band || (a.in_band && !same_sample(a, b)))
                ++differ;
        }
        CHECK(differ == 0);
    }
    FieldParams fixed;
    fixed.voxel_size = p.voxel_size;
    fixed.band_width = p.band_width;
    fixed.bucket_size = p.bucket_size;
    std::mt19937 rng(59);
    std::vector<Layer> layers = scene.layers();
    for (int step = 0; step < 60; ++step) {
        const std::size_t l = static_cast<std::size_t>(step) % 3;  // body, suit, open suit piece
        const PolylineEdit edit = random_edit(rng, layers[l].points, 0.2 * p.band_width);
        fields.field(l).update(layers[l].points, edit);
    }
    scene = Scene(layers);
    const SceneFields fresh(scene, fixed);
    for (std::size_t i = 0; i < scene.size(); ++i) {
        std::string why;
        const bool same = detail::grids_identical(fields.field(i), fresh.field(i), &why);
        INFO("layer " << scene.layer(i).name << ": " << why);
        CHECK(same);
    }
}
