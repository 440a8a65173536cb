// Exact backends: brute force over every segment, and uniform buckets of segments searched
// ring by ring. Both pick the nearest segment with the same tie-break (detail::beats), so they
// return identical samples.

#include "field/detail/backends.h"
#include "field/detail/segment_store.h"
#include "strata/core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace strata::detail {

namespace {

std::uint64_t cell_key(long i, long j) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
           static_cast<std::uint64_t>(static_cast<std::uint32_t>(j));
}

class ExactField final : public LayerField {
  public:
    ExactField(const Layer& layer, int outside_sign, const ResolvedFieldParams& params,
               bool indexed)
        : LayerField(layer.name, layer.closed, outside_sign),
          band_(params.band_width),
          cell_(params.bucket_size),
          indexed_(indexed) {
        check_points(layer.points, layer.closed, "make_field");
        const Box2 box = layer.bounds();
        const double reach = std::max(std::abs(box.min.x), std::abs(box.max.x)) +
                             std::max(std::abs(box.min.y), std::abs(box.max.y));
        if (indexed_ && reach / cell_ > 1e9)
            throw InvalidInput("make_field: layer '" + layer.name +
                               "' is too large for the bucket size");
        store_.build(layer.points, layer.closed, outside_sign);
        set_outside_sign(store_.outside_sign());
        if (indexed_)
            for (std::uint32_t s = 0; s < store_.segments().size(); ++s) insert(s);
    }

    FieldSample sample(const Vec2& x) const override {
        Nearest best;
        if (indexed_) {
            search(x, best);
        } else {
            const auto& segs = store_.segments();
            for (std::uint32_t s = 0; s < segs.size(); ++s)
                if (segs[s].live) store_.offer(x, s, best);
        }
        FieldSample out = store_.evaluate(x, best);
        out.in_band = std::sqrt(best.dist2) <= band_;
        return out;
    }

    FieldSample sample_in_band(const Vec2& x) const override {
        if (!indexed_) return sample(x);
        Nearest best;
        search(x, best, band_);
        if (!best.found() || !(best.dist2 <= band_ * band_)) {
            FieldSample out;
            out.value = band_;
            return out;
        }
        FieldSample out = store_.evaluate(x, best);
        out.in_band = true;
        return out;
    }

    void update(const std::vector<Vec2>& points, const PolylineEdit& edit) override {
        std::vector<std::uint32_t> removed, added;
        if (!store_.splice(points, edit, removed, added)) {
            set_outside_sign(store_.outside_sign());
            if (indexed_) {
                buckets_.clear();
                reset_bounds();
                for (std::uint32_t s = 0; s < store_.segments().size(); ++s) insert(s);
            }
            return;
        }
        if (!indexed_) return;
        for (std::uint32_t s : removed) erase(s);
        for (std::uint32_t s : added) insert(s);
    }

    FieldStats stats() const override {
        FieldStats st;
        st.segments = store_.segment_count();
        st.memory_bytes = store_.memory_bytes();
        for (const auto& [key, ids] : buckets_)
            st.memory_bytes += sizeof(key) + sizeof(ids) + ids.capacity() * sizeof(std::uint32_t);
        for (const Segment& s : store_.segments())
            if (s.live) st.bounds.extend(s.box());
        st.band_width = band_;
        return st;
    }

  private:
    void reset_bounds() {
        imin_ = jmin_ = std::numeric_limits<long>::max();
        imax_ = jmax_ = std::numeric_limits<long>::min();
    }
    long cell_of(double v) const { return static_cast<long>(std::floor(v / cell_)); }

    template <typename F>
    void for_cells(const Box2& box, F&& f) const {
        for (long i = cell_of(box.min.x); i <= cell_of(box.max.x); ++i)
            for (long j = cell_of(box.min.y); j <= cell_of(box.max.y); ++j) f(i, j);
    }
    void insert(std::uint32_t slot) {
        const Segment& s = store_.segments()[slot];
        if (!s.live) return;
        for_cells(s.box(), [&](long i, long j) {
            buckets_[cell_key(i, j)].push_back(slot);
            imin_ = std::min(imin_, i);
            imax_ = std::max(imax_, i);
            jmin_ = std::min(jmin_, j);
            jmax_ = std::max(jmax_, j);
        });
    }
    void erase(std::uint32_t slot) {
        for_cells(store_.segments()[slot].box(), [&](long i, long j) {
            const auto it = buckets_.find(cell_key(i, j));
            if (it == buckets_.end()) return;
            auto& ids = it->second;
            ids.erase(std::remove(ids.begin(), ids.end(), slot), ids.end());
            if (ids.empty()) buckets_.erase(it);
        });
    }
    void visit(const Vec2& x, long i, long j, Nearest& best) const {
        const auto it = buckets_.find(cell_key(i, j));
        if (it == buckets_.end()) return;
        for (std::uint32_t s : it->second) store_.offer(x, s, best);
    }
    // Rings of cells around x's cell, clipped to the occupied cells, until no unvisited
    // segment can be as near as the best one (ties included, so the winner is the brute one),
    // or, when nothing within `limit` has been found, none can be within `limit` either.
    void search(const Vec2& x, Nearest& best,
                double limit = std::numeric_limits<double>::infinity()) const {
        if (imin_ > imax_) return;
        const long ci = cell_of(x.x), cj = cell_of(x.y);
        const long start = std::max({imin_ - ci, ci - imax_, jmin_ - cj, cj - jmax_, 0L});
        for (long r = start;; ++r) {
            const long i0 = std::max(ci - r, imin_), i1 = std::min(ci + r, imax_);
            const long j0 = std::max(cj - r, jmin_), j1 = std::min(cj + r, jmax_);
            if (cj - r >= jmin_)
                for (long i = i0; i <= i1; ++i) visit(x, i, cj - r, best);
            if (r > 0 && cj + r <= jmax_)
                for (long i = i0; i <= i1; ++i) visit(x, i, cj + r, best);
            if (ci - r >= imin_)
                for (long j = std::max(j0, cj - r + 1); j <= std::min(j1, cj + r - 1); ++j)
                    visit(x, ci - r, j, best);
            if (r > 0 && ci + r <= imax_)
                for (long j = std::max(j0, cj - r + 1); j <= std::min(j1, cj + r - 1); ++j)
                    visit(x, ci + r, j, best);
            if (ci - r <= imin_ && ci + r >= imax_ && cj - r <= jmin_ && cj + r >= jmax_) return;
            const double lo_x = static_cast<double>(ci - r) * cell_;
            const double hi_x = static_cast<double>(ci + r + 1) * cell_;
            const double lo_y = static_cast<double>(cj - r) * cell_;
            const double hi_y = static_cast<double>(cj + r + 1) * cell_;
            const double margin = std::min({x.x - lo_x, hi_x - x.x, x.y - lo_y, hi_y - x.y});
            if (best.found() && margin > 0.0 && best.dist2 < margin * margin) return;
            if (margin > limit && !(best.dist2 <= limit * limit)) return;
        }
    }

    SegmentStore store_;
    double band_ = 0.0;
    double cell_ = 1.0;
    bool indexed_ = false;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets_;
    long imin_ = std::numeric_limits<long>::max(), imax_ = std::numeric_limits<long>::min();
    long jmin_ = std::numeric_limits<long>::max(), jmax_ = std::numeric_limits<long>::min();
};

}  // namespace

std::unique_ptr<LayerField> make_exact_field(const Layer& layer, int outside_sign,
                                             const ResolvedFieldParams& params, bool indexed) {
    return std::make_unique<ExactField>(layer, outside_sign, params, indexed);
}

}  // namespace strata::detail
