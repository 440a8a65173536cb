#pragma once
/// @file The simplification driver's index of the live segments of every layer: a uniform grid
/// (by bounding box) updated as vertices move or are removed. Private to src/simplify.

#include "strata/core/types.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace strata::detail {

struct SegRef {
    std::uint32_t layer = 0, start = 0;  // segment from vertex `start` to its next alive vertex
};

// Uniform grid of segments (by bounding box), updated as vertices move or go. Its cells are a
// dense array over `bounds` when that holds at most kDenseCellsPerSegment cells per segment
// (stacks whose layers fill their box: no hashing, neighbouring cells side by side in
// memory), a hash map elsewhere.
class SegmentGrid {
  public:
    explicit SegmentGrid(double cell) : cell_(cell) {}
    SegmentGrid(double cell, const Box2& bounds, std::size_t segments) : cell_(cell) {
        if (bounds.is_empty()) return;
        const long long x0 = coord(bounds.min.x), x1 = coord(bounds.max.x);
        const long long y0 = coord(bounds.min.y), y1 = coord(bounds.max.y);
        const double cells = static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1);
        if (cells > static_cast<double>(kDenseCellsPerSegment * segments + 1024)) return;
        x0_ = x0;
        y0_ = y0;
        nx_ = x1 - x0 + 1;
        ny_ = y1 - y0 + 1;
        dense_.resize(static_cast<std::size_t>(nx_ * ny_));
    }
    double cell() const { return cell_; }
    /// Empties every cell, keeping the cells and their capacity for the next fill.
    void clear() {
        for (auto& cell : dense_) cell.clear();
        for (auto& cell : cells_) cell.second.clear();
    }

    void insert(SegRef s, const Box2& box) {
        for_cells(box, [&](long long ix, long long iy) { slot(ix, iy).push_back(s); });
    }
    void erase(SegRef s, const Box2& box) {
        for_cells(box, [&](long long ix, long long iy) {
            std::vector<SegRef>* v = find(ix, iy);
            if (!v) return;
            for (std::size_t i = 0; i < v->size(); ++i)
                if ((*v)[i].layer == s.layer && (*v)[i].start == s.start) {
                    (*v)[i] = v->back();
                    v->pop_back();
                    break;
                }
        });
    }
    // Calls f(SegRef) for the segments of the cells `box` touches (with repeats).
    template <class F>
    void query(const Box2& box, F&& f) const {
        for_cells(box, [&](long long ix, long long iy) {
            const std::vector<SegRef>* v = find(ix, iy);
            if (!v) return;
            for (const SegRef& s : *v) f(s);
        });
    }

    // Calls f(SegRef) once per segment whose box meets `box`, without marking anything: a
    // segment is reported only from the cell holding the lower-left corner of the two boxes'
    // intersection. box_of(s) must give the box s was inserted with.
    template <class BoxOf, class F>
    void query_once(const Box2& box, BoxOf&& box_of, F&& f) const {
        for_cells(box, [&](long long ix, long long iy) {
            const std::vector<SegRef>* v = find(ix, iy);
            if (!v) return;
            for (const SegRef& s : *v) {
                const Box2 b = box_of(s);
                if (!b.overlaps(box) || coord(std::max(b.min.x, box.min.x)) != ix ||
                    coord(std::max(b.min.y, box.min.y)) != iy)
                    continue;
                f(s);
            }
        });
    }

  private:
    static constexpr std::size_t kDenseCellsPerSegment = 4;

    template <class F>
    void for_cells(const Box2& box, F&& f) const {
        const auto x0 = coord(box.min.x), x1 = coord(box.max.x);
        const auto y0 = coord(box.min.y), y1 = coord(box.max.y);
        for (auto ix = x0; ix <= x1; ++ix)
            for (auto iy = y0; iy <= y1; ++iy) f(ix, iy);
    }
    long long coord(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
    bool in_dense(long long ix, long long iy) const {
        return ix >= x0_ && ix < x0_ + nx_ && iy >= y0_ && iy < y0_ + ny_;
    }
    static std::uint64_t key(long long ix, long long iy) {
        return (static_cast<std::uint64_t>(ix) << 32) ^
               (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
    }
    std::vector<SegRef>& slot(long long ix, long long iy) {
        if (in_dense(ix, iy))
            return dense_[static_cast<std::size_t>((ix - x0_) * ny_ + (iy - y0_))];
        return cells_[key(ix, iy)];
    }
    const std::vector<SegRef>* find(long long ix, long long iy) const {
        if (in_dense(ix, iy))
            return &dense_[static_cast<std::size_t>((ix - x0_) * ny_ + (iy - y0_))];
        const auto it = cells_.find(key(ix, iy));
        return it == cells_.end() ? nullptr : &it->second;
    }
    std::vector<SegRef>* find(long long ix, long long iy) {
        return const_cast<std::vector<SegRef>*>(std::as_const(*this).find(ix, iy));
    }

    double cell_;
    long long x0_ = 0, y0_ = 0, nx_ = 0, ny_ = 0;  // the dense box of cells (empty: none)
    std::vector<std::vector<SegRef>> dense_;
    std::unordered_map<std::uint64_t, std::vector<SegRef>> cells_;  // the cells outside it
};

}  // namespace strata::detail
