#include "strata/simplify/scene_families.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <algorithm>
#include <cmath>

namespace strata {

namespace {

constexpr double kPi = 3.14159265358979323846;

Layer make_layer(std::string name, double thickness, bool closed = false) {
    Layer layer;
    layer.name = std::move(name);
    layer.thickness = thickness;
    layer.closed = closed;
    return layer;
}

// Stack: offsets along the normal of y = A (0.5 sin 0.6x + 0.18 sin(2.3x + 0.5)) over
// [0, 10], A chosen so that the outermost offset stays within half the smallest radius of
// curvature (0.88 / A): no layer loops over itself.
std::vector<Layer> stack(const FamilyParams& p) {
    const double width = 10.0, s = width / static_cast<double>(p.points - 1);
    const double gap = p.gap * s;
    const double total = gap * static_cast<double>(p.layers - 1);
    const double amplitude = total > 0.0 ? std::min(1.0, 0.5 * 0.88 / total) : 1.0;
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < p.layers; ++k) {
        Layer layer = make_layer("layer_" + std::to_string(k), 0.5 * gap);
        const double offset = gap * static_cast<double>(k);
        for (std::size_t i = 0; i < p.points; ++i) {
            const double x = s * static_cast<double>(i);
            const double y = amplitude * (0.5 * std::sin(0.6 * x) + 0.18 * std::sin(2.3 * x + 0.5));
            const double slope =
                amplitude * (0.3 * std::cos(0.6 * x) + 0.414 * std::cos(2.3 * x + 0.5));
            const double len = std::sqrt(1.0 + slope * slope);
            layer.points.emplace_back(x - offset * slope / len, y + offset / len);
        }
        layers.push_back(std::move(layer));
    }
    return layers;
}

// Loops: r_k(t) = 1 + k gap + 0.03 sin 7t (radial offsets of a star-shaped curve: nested,
// never self-crossing).
std::vector<Layer> loops(const FamilyParams& p) {
    const double s = 2.0 * kPi / static_cast<double>(p.points), gap = p.gap * s;
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < p.layers; ++k) {
        Layer layer = make_layer("loop_" + std::to_string(k), 0.5 * gap, true);
        for (std::size_t i = 0; i < p.points; ++i) {
            const double t = s * static_cast<double>(i);
            const double r = 1.0 + gap * static_cast<double>(k) + 0.03 * std::sin(7.0 * t);
            layer.points.emplace_back(r * std::cos(t), r * std::sin(t));
        }
        layers.push_back(std::move(layer));
    }
    return layers;
}

// Folded: a centreline of three arms of length 4 joined by two half turns of radius rho (an
// S), sampled evenly by arc length; layer k is offset by k gap to its left. The first turn
// bends toward the offsets (inner radius rho - (n - 1) gap = 1.5 gap), the second away.
std::vector<Layer> folded(const FamilyParams& p) {
    const double arm = 4.0, n = static_cast<double>(p.layers);
    const double pts = static_cast<double>(p.points);
    // gap = p.gap * (3 arm + 2 pi rho) / pts with rho = (n - 1) gap + 1.5 gap.
    const double denominator = pts - p.gap * 2.0 * kPi * (n + 0.5);
    if (!(denominator > 0.0))
        throw InvalidInput("scene family 'folded': " + std::to_string(p.points) +
                           " points are too few for " + std::to_string(p.layers) + " layers " +
                           format_number(p.gap) + " segments apart");
    const double gap = p.gap * 3.0 * arm / denominator;
    const double rho = (n - 0.5) * gap;
    const double turn = kPi * rho, total = 3.0 * arm + 2.0 * turn;
    std::vector<Layer> layers;
    for (std::size_t k = 0; k < p.layers; ++k) {
        Layer layer = make_layer("layer_" + std::to_string(k), 0.5 * gap);
        const double off = gap * static_cast<double>(k);
        for (std::size_t i = 0; i < p.points; ++i) {
            double u = total * static_cast<double>(i) / (pts - 1.0);
            Vec2 at, left;
            if (u <= arm) {
                at = {u, 0.0};
                left = {0.0, 1.0};
            } else if ((u -= arm) <= turn) {  // counter-clockwise about (arm, rho)
                const double a = -0.5 * kPi + u / rho;
                at = Vec2(arm, rho) + rho * Vec2(std::cos(a), std::sin(a));
                left = -Vec2(std::cos(a), std::sin(a));
            } else if ((u -= turn) <= arm) {
                at = {arm - u, 2.0 * rho};
                left = {0.0, -1.0};
            } else if ((u -= arm) <= turn) {  // clockwise about (0, 3 rho)
                const double a = -0.5 * kPi - u / rho;
                at = Vec2(0.0, 3.0 * rho) + rho * Vec2(std::cos(a), std::sin(a));
                left = Vec2(std::cos(a), std::sin(a));
            } else {
                u -= turn;
                at = {std::min(u, arm), 4.0 * rho};
                left = {0.0, 1.0};
            }
            layer.points.push_back(at + off * left);
        }
        layers.push_back(std::move(layer));
    }
    return layers;
}

// Rolled: the outer layer at y = gap over [0, 8]; the inner one along y = 0 to x = 9, half a
// turn of radius 1.5 gap about (9, 1.5 gap) past the outer one's end, and back over it at
// y = 3 gap to x = 5.
std::vector<Layer> rolled(const FamilyParams& p) {
    const double s = 10.0 / static_cast<double>(p.points - 1), gap = p.gap * s;
    Layer outer = make_layer("outer", 0.5 * gap), inner = make_layer("inner", 0.5 * gap);
    for (double x = 0.0; x <= 8.0 + 1e-9; x += s) outer.points.emplace_back(x, gap);
    for (double x = 0.0; x < 9.0; x += s) inner.points.emplace_back(x, 0.0);
    const double r = 1.5 * gap;
    const int steps = std::max(4, static_cast<int>(std::ceil(kPi * r / s)));
    for (int j = 0; j <= steps; ++j) {
        const double a = -0.5 * kPi + kPi * j / steps;
        inner.points.emplace_back(9.0 + r * std::cos(a), r + r * std::sin(a));
    }
    for (double x = 9.0 - s; x >= 5.0; x -= s) inner.points.emplace_back(x, 3.0 * gap);
    if (p.unrolled)  // the roll turned away from the outer layer, below the inner one's base
        for (Vec2& q : inner.points) q.y = -q.y;
    return {inner, outer};
}

// Rolled twice: as Rolled, then the inner layer's top turns up again at x = 5, half a turn of
// radius gap, and runs forward at y = 5 gap to x = 8: a cuff turned back twice over the end of
// the outer layer.
std::vector<Layer> rolled_twice(const FamilyParams& p) {
    std::vector<Layer> layers = rolled(p);
    const double s = 10.0 / static_cast<double>(p.points - 1), gap = p.gap * s;
    Layer& inner = layers[0];
    Vec2 end = inner.points.back();  // about (5, 3 gap)
    end.y = std::abs(end.y);
    const std::size_t before = inner.points.size();
    const int steps = std::max(4, static_cast<int>(std::ceil(kPi * gap / s)));
    for (int j = 1; j <= steps; ++j) {
        const double a = -0.5 * kPi - kPi * j / steps;  // around (x_end, 4 gap), on the left
        inner.points.emplace_back(end.x + gap * std::cos(a), 4.0 * gap + gap * std::sin(a));
    }
    for (double x = end.x + s; x <= 8.0 + 1e-9; x += s) inner.points.emplace_back(x, 5.0 * gap);
    if (p.unrolled)  // rolled() mirrored its first part already: mirror what was added here
        for (std::size_t k = before; k < inner.points.size(); ++k)
            inner.points[k].y = -inner.points[k].y;
    return layers;
}

// Both rolled: the two layers of Rolled rolled together around (9, 1.5 gap), with waves
// w(x) = 0.3 gap sin 2x: the inner layer (base y = 0) takes the outside of the bend (radius
// 1.5 gap), the outer one (base y = gap) its inside (radius 0.5 gap); back on top, to x = 5,
// the inner layer lies over the outer one: the order flips. Thickness a quarter gap (the
// required separation, half a gap, is what the bend leaves).
std::vector<Layer> rolled_both(const FamilyParams& p) {
    const double s = 10.0 / static_cast<double>(p.points - 1), gap = p.gap * s;
    auto w = [gap](double x) { return 0.3 * gap * std::sin(2.0 * x); };
    Layer inner = make_layer("inner", 0.25 * gap), outer = make_layer("outer", 0.25 * gap);
    auto roll = [&](Layer& layer, double base, double radius) {
        for (double x = 0.0; x < 9.0; x += s) layer.points.emplace_back(x, base + w(x));
        const int steps = std::max(4, static_cast<int>(std::ceil(kPi * radius / s)));
        for (int j = 1; j < steps; ++j) {
            const double a = -0.5 * kPi + kPi * j / steps;
            layer.points.emplace_back(9.0 + radius * std::cos(a),
                                      1.5 * gap + radius * std::sin(a) + w(9.0));
        }
        for (double x = 9.0; x >= 5.0; x -= s)
            layer.points.emplace_back(x, 3.0 * gap - base + w(x));
    };
    roll(inner, 0.0, 1.5 * gap);
    roll(outer, gap, 0.5 * gap);
    return {inner, outer};
}

// Shirt roll: a shirt rolled over the end of a jacket, both over a closed body. Body radius 1
// (`points` vertices, under the shirt), shirt at 1 + gap over the angles [0.5, 5], jacket at
// 1 + 2 gap over [0.5, 5 - 4 gap]; at angle 5 the shirt turns outward around a half circle of
// radius gap and comes back at 1 + 3 gap (over the jacket) to angle 4.
std::vector<Layer> shirt_roll(const FamilyParams& p) {
    const double s = 2.0 * kPi / static_cast<double>(p.points), gap = p.gap * s;
    auto at = [](double r, double t) { return Vec2(r * std::cos(t), r * std::sin(t)); };
    Layer body = make_layer("body", 0.5 * gap, true), shirt = make_layer("shirt", 0.5 * gap),
          coat = make_layer("jacket", 0.5 * gap);
    body.outer = std::vector<std::string>{"shirt"};
    shirt.outer = std::vector<std::string>{"jacket"};
    coat.outer = std::vector<std::string>{};
    for (std::size_t i = 0; i < p.points; ++i)
        body.points.push_back(at(1.0, s * static_cast<double>(i)));
    const double shift = p.unrolled ? 1.0 : 0.0;  // unrolled: the jacket ends before the roll
    for (double t = 0.5; t <= 5.0 - 4.0 * gap + 1e-12; t += s)
        coat.points.push_back(at(1.0 + 2.0 * gap, t - shift));
    for (double t = 0.5; t < 5.0; t += s) shirt.points.push_back(at(1.0 + gap, t));
    const int steps = std::max(4, static_cast<int>(std::ceil(kPi * gap / s)));
    const Vec2 centre = at(1.0 + 2.0 * gap, 5.0), radial = at(1.0, 5.0),
               along = at(1.0, 5.0 + 0.5 * kPi);
    for (int j = 0; j <= steps; ++j) {  // from radius 1 + gap to 1 + 3 gap, bulging forward
        const double a = kPi * j / steps;
        shirt.points.push_back(centre - gap * std::cos(a) * radial + gap * std::sin(a) * along);
    }
    for (double t = 5.0 - s; t >= 4.0; t -= s) shirt.points.push_back(at(1.0 + 3.0 * gap, t));
    return {body, shirt, coat};
}

// Collar wrap: a collar folded over a closed cord, over a closed body. Body radius 1
// (`points` vertices, under the collar); the collar at 1 + gap over the angles [0.5, 5] turns
// outward at angle 5 around a half circle of radius 1.5 gap and comes back at 1 + 4 gap to
// angle 4; the cord, a closed loop of half width 0.9 gap (thickness a quarter gap: 0.6 gap
// from the collar for 0.375 required) along the radius 1 + 2.5 gap over the angles [4.2, 5],
// fills the fold like a drawstring in its channel. The cord is under the collar (the only
// order a closed layer wrapped by an open one can have: the collar cannot be inside it), but
// it lies on the collar's outside face all along: over the collar's first part, and under its
// turned-back part, whose outside faces inward.
std::vector<Layer> collar_wrap(const FamilyParams& p) {
    const double s = 2.0 * kPi / static_cast<double>(p.points), gap = p.gap * s;
    auto at = [](double r, double t) { return Vec2(r * std::cos(t), r * std::sin(t)); };
    Layer body = make_layer("body", 0.5 * gap, true), collar = make_layer("collar", 0.5 * gap),
          cord = make_layer("cord", 0.25 * gap, true);
    body.outer = std::vector<std::string>{"collar"};
    cord.outer = std::vector<std::string>{"collar"};
    collar.outer = std::vector<std::string>{};
    for (std::size_t i = 0; i < p.points; ++i)
        body.points.push_back(at(1.0, s * static_cast<double>(i)));
    // An arc of radius r from angle t0 to t1 (t1 excluded) in steps of about one segment at
    // radius r_steps.
    auto arc = [&](Layer& layer, double r, double t0, double t1, double r_steps) {
        const int steps =
            std::max(1, static_cast<int>(std::round(std::abs(t1 - t0) * r_steps / s)));
        for (int j = 0; j < steps; ++j) layer.points.push_back(at(r, t0 + (t1 - t0) * j / steps));
    };
    // Half a turn of radius r about the point at radius `mid`, angle t, from radius mid - r to
    // mid + r (outward = +1) or back (-1), bulging forward (+1, toward larger angles) or
    // backward (-1); the end point excluded.
    auto half_turn = [&](Layer& layer, double mid, double t, double r, double outward,
                         double forward) {
        const int steps = std::max(4, static_cast<int>(std::ceil(kPi * r / s)));
        const Vec2 centre = at(mid, t), radial = at(1.0, t), along = at(1.0, t + 0.5 * kPi);
        for (int j = 0; j < steps; ++j) {
            const double a = kPi * j / steps;
            layer.points.push_back(centre - outward * r * std::cos(a) * radial +
                                   forward * r * std::sin(a) * along);
        }
    };
    const double fold = 1.5 * gap, rho = 0.9 * gap;  // the fold's and the cord's half widths
    arc(collar, 1.0 + gap, 0.5, 5.0, 1.0 + gap);
    half_turn(collar, 1.0 + gap + fold, 5.0, fold, 1.0, 1.0);
    arc(collar, 1.0 + gap + 2.0 * fold, 5.0, 4.0, 1.0 + gap + 2.0 * fold);
    collar.points.push_back(at(1.0 + gap + 2.0 * fold, 4.0));
    // Unrolled: the cord outside the turned-back part, as far from it as inside the fold
    // (with as many vertices).
    const double wrapped = 1.0 + gap + fold, from = 4.2;
    const double mid = p.unrolled ? wrapped + 2.0 * fold : wrapped;
    arc(cord, mid - rho, from, 5.0, wrapped - rho);
    half_turn(cord, mid, 5.0, rho, 1.0, 1.0);
    arc(cord, mid + rho, 5.0, from, wrapped + rho);
    half_turn(cord, mid, from, rho, -1.0, -1.0);
    return {body, cord, collar};
}

// Jacket: a body loop r = 1 + 0.02 sin 5t and, gap outside it, an open jacket over the
// angles [pi/4, 7 pi/4] with the same waves; the body's `outer` is the jacket.
std::vector<Layer> jacket(const FamilyParams& p) {
    const double s = 2.0 * kPi / static_cast<double>(p.points), gap = p.gap * s;
    Layer body = make_layer("body", 0.5 * gap, true), coat = make_layer("jacket", 0.5 * gap);
    body.outer = std::vector<std::string>{"jacket"};
    coat.outer = std::vector<std::string>{};
    for (std::size_t i = 0; i < p.points; ++i) {
        const double t = s * static_cast<double>(i), r = 1.0 + 0.02 * std::sin(5.0 * t);
        body.points.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    const std::size_t m = std::max<std::size_t>(3, p.points * 3 / 4);
    for (std::size_t i = 0; i < m; ++i) {
        const double t =
            0.25 * kPi + 1.5 * kPi * static_cast<double>(i) / static_cast<double>(m - 1);
        const double r = 1.0 + gap + 0.02 * std::sin(5.0 * t);
        coat.points.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return {body, coat};
}

// Legs: two circles of radius 0.45, gap apart, and a skirt that keeps gap from both: the
// capsule around them (two half circles of radius 0.45 + gap joined by straight sides).
std::vector<Layer> legs(const FamilyParams& p) {
    const double radius = 0.45, s = 2.0 * kPi * radius / static_cast<double>(p.points);
    const double gap = p.gap * s, c = radius + 0.5 * gap;
    std::vector<Layer> layers;
    for (const double sign : {-1.0, 1.0}) {
        Layer leg = make_layer(sign < 0.0 ? "leg_left" : "leg_right", 0.5 * gap, true);
        leg.outer = std::vector<std::string>{"skirt"};
        for (std::size_t i = 0; i < p.points; ++i) {
            const double t = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(p.points);
            leg.points.emplace_back(sign * c + radius * std::cos(t), radius * std::sin(t));
        }
        layers.push_back(std::move(leg));
    }
    Layer skirt = make_layer("skirt", 0.5 * gap, true);
    skirt.outer = std::vector<std::string>{};
    const double r = radius + gap;
    const std::size_t half = p.points, side = std::max<std::size_t>(2, p.points / 3);
    auto arc = [&](double cx, double from) {
        for (std::size_t i = 0; i < half; ++i) {
            const double t = from + kPi * static_cast<double>(i) / static_cast<double>(half);
            skirt.points.emplace_back(cx + r * std::cos(t), r * std::sin(t));
        }
    };
    auto straight = [&](double y, double from, double to) {
        for (std::size_t i = 0; i < side; ++i) {
            const double x =
                from + (to - from) * static_cast<double>(i) / static_cast<double>(side);
            skirt.points.emplace_back(x, y);
        }
    };
    arc(c, -0.5 * kPi);   // right end, bottom to top
    straight(r, c, -c);   // top, right to left
    arc(-c, 0.5 * kPi);   // left end, top to bottom
    straight(-r, -c, c);  // bottom, left to right
    layers.push_back(std::move(skirt));
    return layers;
}

}  // namespace

std::vector<SceneFamily> all_scene_families() {
    return {SceneFamily::Stack,       SceneFamily::Loops,      SceneFamily::Folded,
            SceneFamily::Rolled,      SceneFamily::Jacket,     SceneFamily::Legs,
            SceneFamily::RolledTwice, SceneFamily::RolledBoth, SceneFamily::ShirtRoll,
            SceneFamily::CollarWrap};
}

std::string family_name(SceneFamily family) {
    switch (family) {
        case SceneFamily::Stack:
            return "stack";
        case SceneFamily::Loops:
            return "loops";
        case SceneFamily::Folded:
            return "folded";
        case SceneFamily::Rolled:
            return "rolled";
        case SceneFamily::Jacket:
            return "jacket";
        case SceneFamily::Legs:
            return "legs";
        case SceneFamily::RolledTwice:
            return "rolled_twice";
        case SceneFamily::RolledBoth:
            return "rolled_both";
        case SceneFamily::ShirtRoll:
            return "shirt_roll";
        case SceneFamily::CollarWrap:
            return "collar_wrap";
    }
    return "?";
}

bool is_rolled(SceneFamily family) {
    // RolledBoth keeps it: on top both layers run back, so the side of the outer one that the
    // inner one lies on, taken along its direction of travel, is the same as below.
    return family == SceneFamily::Rolled || family == SceneFamily::RolledTwice ||
           family == SceneFamily::ShirtRoll || family == SceneFamily::CollarWrap;
}

Scene make_scene(SceneFamily family, const FamilyParams& params) {
    if (params.layers < 1 || params.points < 4)
        throw InvalidInput("scene family '" + family_name(family) +
                           "': layers must be >= 1 and points >= 4 (got " +
                           std::to_string(params.layers) + ", " + std::to_string(params.points) +
                           ")");
    if (!(params.gap > 0.0) || !std::isfinite(params.gap))
        throw InvalidInput("scene family '" + family_name(family) + "': gap must be > 0 (got " +
                           format_number(params.gap) + ")");
    if (!(params.scale > 0.0) || !std::isfinite(params.scale))
        throw InvalidInput("scene family '" + family_name(family) + "': scale must be > 0 (got " +
                           format_number(params.scale) + ")");
    std::vector<Layer> layers;
    switch (family) {
        case SceneFamily::Stack:
            layers = stack(params);
            break;
        case SceneFamily::Loops:
            layers = loops(params);
            break;
        case SceneFamily::Folded:
            layers = folded(params);
            break;
        case SceneFamily::Rolled:
            layers = rolled(params);
            break;
        case SceneFamily::Jacket:
            layers = jacket(params);
            break;
        case SceneFamily::Legs:
            layers = legs(params);
            break;
        case SceneFamily::RolledTwice:
            layers = rolled_twice(params);
            break;
        case SceneFamily::RolledBoth:
            layers = rolled_both(params);
            break;
        case SceneFamily::ShirtRoll:
            layers = shirt_roll(params);
            break;
        case SceneFamily::CollarWrap:
            layers = collar_wrap(params);
            break;
    }
    for (Layer& layer : layers) {
        layer.thickness *= params.scale;
        for (Vec2& point : layer.points) point = params.scale * point + params.offset;
    }
    return Scene(std::move(layers));
}

}  // namespace strata
