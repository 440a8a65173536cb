#include "strata/untangle/outside_sides.h"

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace strata {

namespace {

// Unit tangents of open `layer` at `count` points evenly spaced along its length.
std::vector<Vec2> tangents_along(const Layer& layer, std::size_t count) {
    std::vector<Vec2> out;
    const double total = layer.length();
    if (!(total > 0.0)) return out;
    std::size_t segment = 0;
    double before = 0.0;  // length of the segments before `segment`
    for (std::size_t k = 0; k < count; ++k) {
        const double at = (static_cast<double>(k) + 0.5) / static_cast<double>(count) * total;
        while (segment + 1 < layer.segment_count() &&
               before + glm::distance(layer.segment_start(segment), layer.segment_end(segment)) <
                   at) {
            before += glm::distance(layer.segment_start(segment), layer.segment_end(segment));
            ++segment;
        }
        const Vec2 d = layer.segment_end(segment) - layer.segment_start(segment);
        const double len = glm::length(d);
        out.push_back(len > 0.0 ? d / len : Vec2(0.0));
    }
    return out;
}

// The centroid of the area of closed `layer` (of its polygon; its vertex centroid when the area
// is 0) when it lies inside it (a body, not a band). The area's, not the vertices': a decimation
// that keeps more of a body's vertices on one side moves their centroid toward that side (the
// collar at 95%, seed 28: vertex centroid (-0.39, 0.29), area centroid (-0.09, 0.04), of a
// body of radius 1 centred at the origin), and the collar around it then seems to sweep the
// other way.
std::optional<Vec2> body_centre(const Layer& layer) {
    if (layer.points.empty()) return std::nullopt;
    Vec2 centre(0.0);
    for (const Vec2& p : layer.points) centre += p;
    centre /= static_cast<double>(layer.points.size());
    double area = 0.0;  // twice the signed area
    Vec2 moment(0.0);
    for (std::size_t k = 0, m = layer.points.size(); k < m; ++k) {
        const Vec2 u = layer.points[k] - centre, w = layer.points[(k + 1) % m] - centre;
        const double cross = u.x * w.y - u.y * w.x;
        area += cross;
        moment += cross * (u + w);
    }
    if (area != 0.0) centre += moment / (3.0 * area);
    bool inside = false;
    for (std::size_t k = 0, m = layer.points.size(); k < m; ++k) {
        const Vec2 u = layer.points[k], w = layer.points[(k + 1) % m];
        if ((u.y > centre.y) != (w.y > centre.y) &&
            centre.x < u.x + (centre.y - u.y) / (w.y - u.y) * (w.x - u.x))
            inside = !inside;
    }
    if (!inside) return std::nullopt;
    return centre;
}

// The largest closed layer (bounding-box diagonal) with a body_centre() under layer `b`
// (directly or with layers between them); none if there is none.
std::optional<std::size_t> largest_body_under(const Scene& scene, std::size_t b) {
    std::optional<std::size_t> best;
    double best_size = -1.0;
    for (std::size_t a = 0; a < scene.size(); ++a) {
        if (scene.relation(a, b) != Relation::Under) continue;
        const Layer& inner = scene.layer(a);
        if (!inner.closed || !body_centre(inner)) continue;
        const Vec2 size = inner.bounds().size();
        const double d = std::hypot(size.x, size.y);
        if (d > best_size) {
            best_size = d;
            best = a;
        }
    }
    return best;
}

// The angle (radians) open `layer` turns through seen from `centre`: the sum over its segments
// of the signed angle between their ends, counter-clockwise positive.
double swept_angle(const Layer& layer, const Vec2& centre) {
    double swept = 0.0;
    for (std::size_t k = 0; k + 1 < layer.points.size(); ++k) {
        const Vec2 u = layer.points[k] - centre, w = layer.points[k + 1] - centre;
        swept += std::atan2(u.x * w.y - u.y * w.x, glm::dot(u, w));
    }
    return swept;
}
}  // namespace

std::vector<int> untangling_outside_sides(const Scene& scene) {
    std::vector<int> sides = outside_sides(scene);
    const std::size_t n = scene.size();
    // An open layer with neighbours both under and over it, whose neighbours' sides (within
    // the reach of record_input_sides()) under it and over it say opposite outsides: both
    // counted together (the vote counts the layers under it alone unless they tie). A
    // decimation that scatters the vertices on one side leaves the other's count standing.
    std::optional<InputSides> recorded;
    // The outside side of layer i voted by the vertices of `layers` (recorded sides within
    // the reach of record_input_sides()): sign x side, summed.
    auto tally = [&](const std::vector<std::size_t>& layers, int sign, std::size_t i) {
        if (!recorded) recorded = record_input_sides(scene);
        long vote = 0;
        for (std::size_t j : layers)
            for (std::size_t k = 0; k < scene.layer(j).points.size(); ++k)
                vote += sign * recorded->side(j, k, i);
        return vote;
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (scene.layer(i).closed || scene.inner_of(i).empty() || scene.outer_of(i).empty())
            continue;
        const long under = tally(scene.inner_of(i), -1, i), over = tally(scene.outer_of(i), 1, i);
        if ((under > 0 && over < 0) || (under < 0 && over > 0)) {
            const long both = under + over;
            if (both != 0) sides[i] = both > 0 ? 1 : -1;
        }
    }
    // An open layer directly over a closed one that runs around it (the mean, weighted by
    // length, of the sine between its segments and the direction from the closed layer's
    // centroid, body_centre(), beyond kAround): outside away from that centroid, whatever the
    // vote.
    constexpr double kAround = 0.8;
    std::vector<char> around(n, 0);  // decided by the rule above
    for (std::size_t b = 0; b < n; ++b) {
        const Layer& layer = scene.layer(b);
        if (layer.closed) continue;
        for (std::size_t a : scene.inner_of(b)) {
            const Layer& inner = scene.layer(a);
            if (!inner.closed) continue;
            const std::optional<Vec2> centre = body_centre(inner);
            if (!centre) continue;
            double turn = 0.0, total = 0.0;
            for (std::size_t k = 0; k + 1 < layer.points.size(); ++k) {
                const Vec2 d = layer.points[k + 1] - layer.points[k];
                const Vec2 r = 0.5 * (layer.points[k] + layer.points[k + 1]) - *centre;
                const double rl = glm::length(r);
                if (!(rl > 0.0)) continue;
                turn += (r.x * d.y - r.y * d.x) / rl;
                total += glm::length(d);
            }
            if (!(total > 0.0) || std::abs(turn / total) < kAround) continue;
            // Counter-clockwise around the centre: the outside is on the right (+1).
            sides[b] = turn > 0.0 ? 1 : -1;
            around[b] = 1;
            break;
        }
    }
    // An open layer over a body that the rule above left to its vote (the largest closed
    // layer under it, directly or with layers between them, bounding-box diagonals, whose
    // body_centre() lies inside it), which it sweeps around by at least kSweep (the angle
    // its vertices turn through seen from that centroid): outside away from the body. For a
    // layer that runs back in part (a fold or a roll at its end, where the mean sine fails),
    // whose vote counts the neighbours' vertices a tangle scattered. The largest: a small loop
    // in a fold of the layer (a collar's cord) is swept around the other way. With layers
    // between: a jacket over a shirt over a body wraps the body as the shirt does, and a
    // shirt's roll over the jacket's end (its vertices on the jacket's outside) scattered by a
    // tangle turns the jacket's vote; the link of parallel layers below misses them when the
    // roll lengthens the shirt (its tangents at the same fractions of their lengths part).
    constexpr double kSweep = 2.0 * 3.14159265358979323846 / 3.0;
    for (std::size_t b = 0; b < n; ++b) {
        if (scene.layer(b).closed || around[b]) continue;
        const std::optional<std::size_t> body = largest_body_under(scene, b);
        if (!body) continue;
        const double swept = swept_angle(scene.layer(b), *body_centre(scene.layer(*body)));
        if (std::abs(swept) >= kSweep) sides[b] = swept > 0.0 ? 1 : -1;
    }
    // Directly related open layers that run along each other (the mean cosine of their
    // tangents at the same fraction of their lengths beyond +-kParallel): the same outside
    // side when they travel the same way, opposite ones when they travel opposite ways.
    constexpr std::size_t kSamples = 64;
    constexpr double kParallel = 0.8;
    std::vector<std::vector<Vec2>> tangents(n);
    for (std::size_t i = 0; i < n; ++i)
        if (!scene.layer(i).closed) tangents[i] = tangents_along(scene.layer(i), kSamples);
    // Components of such pairs, with each layer's parity to its component's first layer.
    std::vector<std::size_t> component(n);
    std::vector<int> parity(n, 1);
    for (std::size_t i = 0; i < n; ++i) component[i] = i;
    bool linked = false;
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b : scene.outer_of(a)) {
            if (tangents[a].size() != kSamples || tangents[b].size() != kSamples) continue;
            double cosine = 0.0;
            for (std::size_t k = 0; k < kSamples; ++k)
                cosine += glm::dot(tangents[a][k], tangents[b][k]);
            cosine /= static_cast<double>(kSamples);
            if (std::abs(cosine) < kParallel) continue;
            const int together = cosine > 0.0 ? 1 : -1;
            const std::size_t ca = component[a], cb = component[b];
            if (ca == cb) continue;  // the first link found decides
            const int flip = parity[a] * parity[b] * together;
            for (std::size_t i = 0; i < n; ++i)
                if (component[i] == cb) {
                    component[i] = ca;
                    parity[i] *= flip;
                }
            linked = true;
        }
    if (!linked) return sides;
    // A component whose layers' votes disagree with their parities (a tangle scatters the
    // vertices each layer's vote counts) takes the sign of the votes of all its layers'
    // neighbours' vertices counted together (under and over each layer, times its parity),
    // not a vote of the layers' votes: a layer whose neighbours tie (7 of 14 either way) or
    // nearly tie votes as much as one whose neighbours all agree. A tie: the majority of the
    // layers' votes, a tie again its innermost layer's (the lowest index).
    for (std::size_t c = 0; c < n; ++c) {
        int sum = 0, first = 0;
        long count = 0;
        bool agree = true, any = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (component[i] != c || scene.layer(i).closed) continue;
            const int vote = sides[i] * parity[i];
            if (!any) first = vote;
            agree = agree && vote == first;
            any = true;
            sum += vote;
        }
        if (!any || agree) continue;
        for (std::size_t i = 0; i < n; ++i)
            if (component[i] == c && !scene.layer(i).closed)
                count +=
                    parity[i] * (tally(scene.inner_of(i), -1, i) + tally(scene.outer_of(i), 1, i));
        const int chosen = count > 0 ? 1 : count < 0 ? -1 : sum > 0 ? 1 : sum < 0 ? -1 : first;
        for (std::size_t i = 0; i < n; ++i)
            if (component[i] == c && !scene.layer(i).closed) sides[i] = chosen * parity[i];
    }
    return sides;
}

}  // namespace strata
