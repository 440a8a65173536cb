#include "simplify/detail/live_polylines.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <limits>
#include <utility>

namespace strata::detail {

LivePolylines::LivePolylines(const Scene& scene, const std::vector<std::size_t>& targets)
    : grid_(make_segment_grid<LiveSegment>(1.0)) {
    const std::size_t n = scene.size();
    layers_.resize(n);
    for (std::size_t l = 0; l < n; ++l) {
        const Layer& in = scene.layer(l);
        WorkLayer& w = layers_[l];
        const std::size_t m = in.points.size();
        w.closed = in.closed;
        w.original = w.pos = in.points;
        w.prev.resize(m);
        w.next.resize(m);
        for (std::size_t i = 0; i < m; ++i) {
            w.prev[i] = i > 0 ? i - 1 : (in.closed ? m - 1 : kNone);
            w.next[i] = i + 1 < m ? i + 1 : (in.closed ? 0 : kNone);
        }
        w.alive.assign(m, 1);
        w.locked.assign(m, 0);
        w.alive_count = m;
        w.target = targets[l];
    }
    bounds_ = scene.bounds();
    regrid();
    input_cell_ = grid_.cell();
}

// The grid again, with cells of 4 median lengths of the live segments. As removals lengthen
// the segments, a grid sized for the input's files each one in more and more cells (at 98%
// removal about 50 input segments long: every query and every unlink read dozens of cells).
// The checks do not depend on the order in which a query meets the segments.
void LivePolylines::regrid() {
    std::vector<double> lengths;
    for (std::size_t l = 0; l < layers_.size(); ++l)
        for (std::size_t i = 0; i < layers_[l].alive.size(); ++i)
            if (has_segment(l, i))
                lengths.push_back(
                    glm::distance(layers_[l].pos[i], layers_[l].pos[layers_[l].next[i]]));
    live_segments_ = gridded_segments_ = lengths.size();
    std::nth_element(lengths.begin(),
                     lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2),
                     lengths.end());
    const double median = lengths.empty() ? 1.0 : lengths[lengths.size() / 2];
    const double cell = std::max(4.0 * median, std::numeric_limits<double>::min());
    grid_ = make_segment_grid<LiveSegment>(cell, bounds_, live_segments_);
    for (std::size_t l = 0; l < layers_.size(); ++l)
        for (std::size_t i = 0; i < layers_[l].alive.size(); ++i)
            if (has_segment(l, i)) grid_.insert(record(l, i), seg_box(l, i));
}

LiveSegment LivePolylines::record(std::size_t l, std::size_t i) const {
    const WorkLayer& w = layers_[l];
    LiveSegment s = key(l, i);
    const std::size_t e = w.next[i];
    s.end = static_cast<std::uint32_t>(e);
    s.end_is_last = w.next[e] == kNone;
    s.p = w.pos[i];
    s.q = w.pos[e];
    return s;
}

void LivePolylines::unlink(std::size_t l, std::size_t v) {
    WorkLayer& w = layers_[l];
    const std::size_t a = w.prev[v], b = w.next[v];
    grid_.erase(key(l, a), seg_box(l, a));
    grid_.erase(key(l, v), seg_box(l, v));
    w.alive[v] = 0;
    w.next[a] = b;
    w.prev[b] = a;
    --w.alive_count;
    grid_.insert(record(l, a), seg_box(l, a));
    if (--live_segments_ * 4 < gridded_segments_) regrid();
}

void LivePolylines::relink(std::size_t l, std::size_t v) {
    WorkLayer& w = layers_[l];
    const std::size_t a = w.prev[v], b = w.next[v];
    grid_.erase(key(l, a), seg_box(l, a));
    w.alive[v] = 1;
    w.next[a] = v;
    w.prev[b] = v;
    ++w.alive_count;
    grid_.insert(record(l, a), seg_box(l, a));
    grid_.insert(record(l, v), seg_box(l, v));
    ++live_segments_;
}

void LivePolylines::move(std::size_t l, std::size_t v, const Vec2& to) {
    WorkLayer& w = layers_[l];
    if (w.pos[v] == to) return;
    const std::size_t a = w.prev[v];
    if (a != kNone) grid_.erase(key(l, a), seg_box(l, a));
    if (w.next[v] != kNone) grid_.erase(key(l, v), seg_box(l, v));
    w.pos[v] = to;
    if (a != kNone) grid_.insert(record(l, a), seg_box(l, a));
    if (w.next[v] != kNone) grid_.insert(record(l, v), seg_box(l, v));
}

std::vector<std::vector<std::size_t>> LivePolylines::origins() const {
    std::vector<std::vector<std::size_t>> ids(layers_.size());
    for (std::size_t l = 0; l < layers_.size(); ++l) {
        const WorkLayer& w = layers_[l];
        const std::size_t start = w.first();
        std::size_t i = start;
        do {
            ids[l].push_back(i);
            i = w.next[i];
        } while (i != kNone && i != start);
    }
    return ids;
}

Scene LivePolylines::to_scene(const Scene& input) const {
    std::vector<Layer> layers = input.layers();
    const std::vector<std::vector<std::size_t>> ids = origins();
    for (std::size_t l = 0; l < layers.size(); ++l) {
        std::vector<Vec2> points;
        points.reserve(ids[l].size());
        for (std::size_t i : ids[l]) points.push_back(layers_[l].pos[i]);
        layers[l].points = std::move(points);
    }
    Scene out(std::move(layers), input.units());
    out.metadata = input.metadata;
    return out;
}

}  // namespace strata::detail
