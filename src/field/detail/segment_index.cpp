#include "field/detail/segment_index.h"

#include <algorithm>
#include <cmath>

namespace strata::detail {

namespace {

std::uint64_t cell_key(long i, long j) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
           static_cast<std::uint64_t>(static_cast<std::uint32_t>(j));
}

}  // namespace

bool SegmentIndex::is_large(const Box2& box) const {
    const double columns = std::floor((box.max.x - origin_.x) / cell_) -
                           std::floor((box.min.x - origin_.x) / cell_) + 1.0;
    const double rows = std::floor((box.max.y - origin_.y) / cell_) -
                        std::floor((box.min.y - origin_.y) / cell_) + 1.0;
    return !(columns * rows <= kMaxCells);  // NaN too
}

long SegmentIndex::column(double x) const {
    return static_cast<long>(std::floor((x - origin_.x) / cell_));
}

long SegmentIndex::row(double y) const {
    return static_cast<long>(std::floor((y - origin_.y) / cell_));
}

template <typename F>
void SegmentIndex::for_cells(const Box2& box, F&& f) const {
    for (long i = column(box.min.x); i <= column(box.max.x); ++i)
        for (long j = row(box.min.y); j <= row(box.max.y); ++j) f(i, j);
}

void SegmentIndex::build(const SegmentStore& store) {
    buckets_.clear();
    large_.clear();
    imin_ = jmin_ = std::numeric_limits<long>::max();
    imax_ = jmax_ = std::numeric_limits<long>::min();
    for (std::uint32_t s = 0; s < store.segments().size(); ++s) insert(store, s);
}

void SegmentIndex::insert(const SegmentStore& store, std::uint32_t slot) {
    const Segment& s = store.segments()[slot];
    if (!s.live) return;
    if (is_large(s.box())) {
        large_.push_back(slot);
        return;
    }
    for_cells(s.box(), [&](long i, long j) {
        buckets_[cell_key(i, j)].push_back(slot);
        imin_ = std::min(imin_, i);
        imax_ = std::max(imax_, i);
        jmin_ = std::min(jmin_, j);
        jmax_ = std::max(jmax_, j);
    });
}

void SegmentIndex::erase(const SegmentStore& store, std::uint32_t slot) {
    if (is_large(store.segments()[slot].box())) {
        large_.erase(std::remove(large_.begin(), large_.end(), slot), large_.end());
        return;
    }
    for_cells(store.segments()[slot].box(), [&](long i, long j) {
        const auto it = buckets_.find(cell_key(i, j));
        if (it == buckets_.end()) return;
        auto& ids = it->second;
        ids.erase(std::remove(ids.begin(), ids.end(), slot), ids.end());
        if (ids.empty()) buckets_.erase(it);
    });
}

void SegmentIndex::visit(const SegmentStore& store, const Vec2& x, long i, long j,
                         Nearest& best) const {
    const auto it = buckets_.find(cell_key(i, j));
    if (it == buckets_.end()) return;
    for (std::uint32_t s : it->second) store.offer(x, s, best);
}

void SegmentIndex::search(const SegmentStore& store, const Vec2& x, Nearest& best,
                          double limit) const {
    for (std::uint32_t s : large_) store.offer(x, s, best);
    if (imin_ > imax_) return;
    const long ci = column(x.x), cj = row(x.y);
    const long start = std::max({imin_ - ci, ci - imax_, jmin_ - cj, cj - jmax_, 0L});
    for (long r = start;; ++r) {
        const long i0 = std::max(ci - r, imin_), i1 = std::min(ci + r, imax_);
        const long j0 = std::max(cj - r, jmin_), j1 = std::min(cj + r, jmax_);
        if (cj - r >= jmin_)
            for (long i = i0; i <= i1; ++i) visit(store, x, i, cj - r, best);
        if (r > 0 && cj + r <= jmax_)
            for (long i = i0; i <= i1; ++i) visit(store, x, i, cj + r, best);
        if (ci - r >= imin_)
            for (long j = std::max(j0, cj - r + 1); j <= std::min(j1, cj + r - 1); ++j)
                visit(store, x, ci - r, j, best);
        if (r > 0 && ci + r <= imax_)
            for (long j = std::max(j0, cj - r + 1); j <= std::min(j1, cj + r - 1); ++j)
                visit(store, x, ci + r, j, best);
        if (ci - r <= imin_ && ci + r >= imax_ && cj - r <= jmin_ && cj + r >= jmax_) return;
        const double lo_x = origin_.x + static_cast<double>(ci - r) * cell_;
        const double hi_x = origin_.x + static_cast<double>(ci + r + 1) * cell_;
        const double lo_y = origin_.y + static_cast<double>(cj - r) * cell_;
        const double hi_y = origin_.y + static_cast<double>(cj + r + 1) * cell_;
        const double margin = std::min({x.x - lo_x, hi_x - x.x, x.y - lo_y, hi_y - x.y});
        if (best.found() && margin > 0.0 && best.dist2 < margin * margin) return;
        if (margin > limit && !(best.dist2 <= limit * limit)) return;
    }
}

void SegmentIndex::candidates(const Box2& box, std::vector<std::uint32_t>& out) const {
    out.clear();
    for (std::uint32_t s : large_) out.push_back(s);
    if (imin_ > imax_ && out.empty()) return;
    const long i0 = std::max(column(box.min.x), imin_), i1 = std::min(column(box.max.x), imax_);
    const long j0 = std::max(row(box.min.y), jmin_), j1 = std::min(row(box.max.y), jmax_);
    for (long i = i0; i <= i1; ++i)
        for (long j = j0; j <= j1; ++j) {
            const auto it = buckets_.find(cell_key(i, j));
            if (it != buckets_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

std::size_t SegmentIndex::memory_bytes() const {
    // One node per bucket: key, slot vector and the node's next pointer.
    std::size_t bytes =
        buckets_.bucket_count() * sizeof(void*) + large_.capacity() * sizeof(std::uint32_t);
    for (const auto& [key, ids] : buckets_)
        bytes += sizeof(key) + sizeof(ids) + sizeof(void*) + ids.capacity() * sizeof(std::uint32_t);
    return bytes;
}

}  // namespace strata::detail
