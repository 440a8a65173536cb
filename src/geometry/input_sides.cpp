#include "strata/geometry/input_sides.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace strata {

// record_input_sides() is defined in checks.cpp, with the side rule of check_scene().

void validate(const InputSideParams& params) {
    if (!std::isfinite(params.reach) || params.reach < 0.0)
        throw InvalidInput("input sides: params.reach must be a finite value >= 0 (got " +
                           format_number(params.reach) + ")");
}

InputSides InputSides::renumbered(const std::vector<std::vector<std::size_t>>& origin) const {
    if (empty()) return {};
    if (origin.size() != n_)
        throw InvalidInput("input sides: renumbered() got " + std::to_string(origin.size()) +
                           " layers for " + std::to_string(n_));
    InputSides out = *this;
    out.origin_.assign(n_, {});
    for (std::size_t a = 0; a < n_; ++a) {
        const std::size_t count = vertex_count(a);
        std::vector<std::size_t>& to = out.origin_[a];
        to.reserve(origin[a].size());
        for (std::size_t k : origin[a]) {
            if (k >= count)
                throw InvalidInput("input sides: renumbered(): vertex " + std::to_string(k) +
                                   " of layer " + std::to_string(a) + " out of range (" +
                                   std::to_string(count) + " vertices)");
            to.push_back(origin_.empty() ? k : origin_[a][k]);
        }
    }
    return out;
}

namespace {

// True when segment [p, q] meets polyline `b` (its segments, closed or not).
bool meets(const Vec2& p, const Vec2& q, const Layer& b) {
    const std::size_t m = b.points.size();
    const std::size_t segments = b.closed ? m : (m > 0 ? m - 1 : 0);
    for (std::size_t j = 0; j < segments; ++j)
        if (segment_contact(p, q, b.points[j], b.points[(j + 1) % m]) != SegmentContact::None)
            return true;
    return false;
}

}  // namespace

InputSides InputSides::by_region(const Scene& scene) const {
    if (n_ != scene.size())
        throw InvalidInput("input sides: by_region() got a scene of " +
                           std::to_string(scene.size()) + " layers for " + std::to_string(n_));
    std::vector<std::vector<signed char>> codes(n_ * n_);
    for (std::size_t a = 0; a < n_; ++a)
        for (std::size_t b = 0; b < n_; ++b) {
            const Layer& layer = scene.layer(a);
            const std::size_t n = layer.points.size();
            if (a == b || n == 0 || vertex_count(a) != n) continue;
            std::vector<signed char>& s = codes[a * n_ + b];
            bool any = false;
            for (std::size_t k = 0; k < n; ++k) {
                s.push_back(static_cast<signed char>(code(a, k, b)));
                any = any || s.back() != 0;
            }
            if (!any) {
                s.clear();
                continue;
            }
            auto has_side = [&](std::size_t k) { return s[k] == 1 || s[k] == -1; };
            // joins[k]: vertex k and the next one are in one region.
            std::vector<char> joins(n, 0);
            for (std::size_t k = 0; k < n; ++k) {
                const std::size_t next = k + 1 < n ? k + 1 : 0;
                if ((next == 0 && !layer.closed) || !has_side(k) || !has_side(next)) continue;
                joins[k] =
                    s[k] == s[next] || meets(layer.points[k], layer.points[next], scene.layer(b));
            }
            // Start where a region starts (a closed layer's regions may wrap around).
            std::size_t start = 0;
            if (layer.closed) {
                while (start < n && joins[(start + n - 1) % n]) ++start;
                if (start == n) start = 0;  // one region around the whole loop
            }
            for (std::size_t i = 0; i < n;) {
                const std::size_t first = (start + i) % n;
                std::size_t count = 1;
                while (i + count < n && joins[(first + count - 1) % n]) ++count;
                if (has_side(first)) {
                    int votes = 0;
                    for (std::size_t c = 0; c < count; ++c) votes += s[(first + c) % n];
                    const signed char side = votes > 0 ? 1 : (votes < 0 ? -1 : 0);
                    for (std::size_t c = 0; c < count; ++c) s[(first + c) % n] = side;
                }
                i += count;
            }
        }
    return from_codes(scene, std::move(codes));
}

InputSides infer_input_sides(const Scene& scene, const InputSideParams& params) {
    return record_input_sides(scene, params).by_region(scene);
}

std::size_t InputSides::rolled_count(const Scene& scene,
                                     const std::vector<int>& outside_sides) const {
    std::size_t count = 0;
    for (std::size_t a = 0; a < n_ && a < scene.size(); ++a)
        for (std::size_t b = 0; b < n_ && b < outside_sides.size(); ++b) {
            if (a == b) continue;
            const int wanted = global_side(scene.relation(a, b), outside_sides[b]);
            const std::size_t vertices = std::min(vertex_count(a), scene.layer(a).points.size());
            for (std::size_t k = 0; k < vertices; ++k) {
                const int s = side(a, k, b);
                if (s != 0 && s != wanted) ++count;
            }
        }
    return count;
}

int global_side(Relation relation_of_a_to_b, int outside) {
    switch (relation_of_a_to_b) {
        case Relation::Under:
            return -outside;
        case Relation::Over:
            return outside;
        default:
            return 0;
    }
}

}  // namespace strata
