#pragma once
/// @file The segments of a work scene in a uniform grid, for the finishing stage
/// (separation.cpp): box queries in a fixed order while vertices move.

#include "strata/core/types.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace strata::detail {

/// Segment `index` of layer `layer`: a polyline with n points joins point k to point
/// (k + 1) % n.
struct SegId {
    std::uint32_t layer, index;
};

/// The segments of the work scene in a uniform grid over its bounds (compressed rows: one
/// array of segment ids, cell by cell), built at the positions of one moment. Vertices that
/// move afterwards are accounted for by growing every query by the largest move since the
/// build; past half a cell the grid is built again.
///
/// Not a UniformGrid (geometry/detail/uniform_grid.h), measured (issue 14): the finishing stage is
/// a Gauss-Seidel sweep, so the order of query() matters (sorting the segments by (layer, index)
/// instead changes the outputs and breaks the rolled cases of the tests). This order (cells row by
/// row, clamped to the region; within a cell, filing order) is not UniformGrid's (columns first): a
/// UniformGrid version that sorted each query's segments by this key gave byte-identical outputs
/// and made strata simplify 8x10k --remove 0.98 --threads 1 3-5% slower (cpu median ratio 1.028 and
/// 1.045, main against itself 0.995; tried in the tenth session, not kept).
class SegmentCells {
  public:
    // Files the segments whose box meets `region` (queries must stay inside it).
    SegmentCells(const std::vector<std::vector<Vec2>>& pts, const std::vector<char>& closed,
                 double cell, const Box2& region)
        : pts_(pts), closed_(closed), cell_(cell), region_(region) {
        offset_.assign(1, 0);
        for (std::size_t l = 0; l < pts.size(); ++l)
            offset_.push_back(offset_.back() + segment_count(l));
        stamp_.assign(offset_.back(), 0);
        build();
    }

    std::size_t segment_count(std::size_t l) const {
        const std::size_t n = pts_[l].size();
        return n < 2 ? 0 : closed_[l] ? n : n - 1;
    }
    Vec2 start(const SegId& s) const { return pts_[s.layer][s.index]; }
    Vec2 end(const SegId& s) const { return pts_[s.layer][end_index(s)]; }
    // The index of the point that ends segment s (no division: this runs in the innermost
    // loops of the finishing stage).
    std::size_t end_index(const SegId& s) const {
        const std::size_t k = s.index + 1;
        return k == pts_[s.layer].size() ? 0 : k;
    }

    // Vertex (l, v) has moved (pts was updated).
    void moved(std::size_t l, std::size_t v) {
        drift_ = std::max(drift_, glm::distance(pts_[l][v], built_[l][v]));
        if (drift_ > 0.5 * cell_) build();
    }

    // Calls f(SegId) once for every segment that may meet `box`.
    template <class F>
    void query(const Box2& box, F&& f) {
        ++tick_;
        const Box2 b = box.inflated(drift_);
        const std::size_t x0 = column(b.min.x), x1 = column(b.max.x);
        const std::size_t y0 = row(b.min.y), y1 = row(b.max.y);
        for (std::size_t iy = y0; iy <= y1; ++iy)
            for (std::size_t ix = x0; ix <= x1; ++ix) {
                const std::size_t c = iy * nx_ + ix;
                for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
                    const SegId& seg = ids_[k];
                    std::uint32_t& seen = stamp_[offset_[seg.layer] + seg.index];
                    if (seen == tick_) continue;
                    seen = tick_;
                    f(seg);
                }
            }
    }

  private:
    void build() {
        built_ = pts_;
        drift_ = 0.0;
        origin_ = region_;
        // The segments filed, in (layer, index) order: tested once, then read twice below.
        filed_.clear();
        for (std::size_t l = 0; l < pts_.size(); ++l)
            for (std::size_t k = 0; k < segment_count(l); ++k)
                if (is_filed(l, k))
                    filed_.push_back(
                        {static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(k)});
        const std::size_t segments = filed_.size();
        // At most about 4 cells per segment: a larger cell where the bounds are wide.
        const Vec2 size = origin_.size();
        double cell = cell_;
        const double budget = 4.0 * static_cast<double>(std::max<std::size_t>(segments, 1));
        while ((size.x / cell + 1.0) * (size.y / cell + 1.0) > budget) cell *= 2.0;
        step_ = cell;
        nx_ = static_cast<std::size_t>(size.x / cell) + 1;
        ny_ = static_cast<std::size_t>(size.y / cell) + 1;
        start_.assign(nx_ * ny_ + 1, 0);
        auto each_cell = [&](const SegId& s, auto&& g) {
            const Vec2 a = start(s), b = end(s);
            for (std::size_t iy = row(std::min(a.y, b.y)); iy <= row(std::max(a.y, b.y)); ++iy)
                for (std::size_t ix = column(std::min(a.x, b.x)); ix <= column(std::max(a.x, b.x));
                     ++ix)
                    g(iy * nx_ + ix, s);
        };
        for (const SegId& s : filed_)
            each_cell(s, [&](std::size_t c, const SegId&) { ++start_[c + 1]; });
        for (std::size_t c = 0; c < nx_ * ny_; ++c) start_[c + 1] += start_[c];
        ids_.resize(start_.back());
        fill_ = start_;
        for (const SegId& s : filed_)
            each_cell(s, [&](std::size_t c, const SegId& t) { ids_[fill_[c]++] = t; });
    }
    bool is_filed(std::size_t l, std::size_t k) const {
        const SegId s{static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(k)};
        Box2 box;
        box.extend(start(s));
        box.extend(end(s));
        return box.inflated(drift_ + cell_).overlaps(region_);
    }
    std::size_t column(double x) const { return clamp_index((x - origin_.min.x) / step_, nx_); }
    std::size_t row(double y) const { return clamp_index((y - origin_.min.y) / step_, ny_); }
    static std::size_t clamp_index(double v, std::size_t n) {
        if (!(v > 0.0)) return 0;  // NaN too
        return std::min(static_cast<std::size_t>(v), n - 1);
    }

    const std::vector<std::vector<Vec2>>& pts_;
    const std::vector<char>& closed_;
    double cell_;        // the cell size asked for
    Box2 region_;        // where queries are made
    double step_ = 1.0;  // the cell size built
    Box2 origin_;        // the bounds at the build
    std::size_t nx_ = 1, ny_ = 1;
    std::vector<std::uint32_t> start_, fill_;  // per cell, into ids_
    std::vector<SegId> ids_;
    std::vector<SegId> filed_;         // build()'s segments, in (layer, index) order
    std::vector<std::size_t> offset_;  // first global id of each layer's segments
    std::vector<std::uint32_t> stamp_;
    std::uint32_t tick_ = 0;
    std::vector<std::vector<Vec2>> built_;  // the positions at the build
    double drift_ = 0.0;                    // largest move since the build
};

}  // namespace strata::detail
