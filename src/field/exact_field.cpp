// Exact backends: brute force over every segment, and uniform buckets of segments searched
// ring by ring. Both pick the nearest segment with the same tie-break (detail::beats), so they
// return identical samples.

#include "field/detail/backends.h"
#include "field/detail/segment_index.h"
#include "field/detail/segment_store.h"
#include "strata/core/error.h"
#include "strata/core/format.h"

#include <algorithm>
#include <cmath>

namespace strata::detail {

namespace {

class ExactField final : public LayerField {
  public:
    ExactField(const Layer& layer, int outside_sign, const ResolvedFieldParams& params,
               bool indexed)
        : LayerField(layer.name, layer.closed, outside_sign),
          band_(params.band_width),
          index_(make_segment_index(params.bucket_size,
                                    layer.points.empty() ? Vec2(0.0) : layer.bounds().min)),
          indexed_(indexed) {
        check_points(layer.points, layer.closed, "make_field");
        // Buckets count from the layer's corner: only its size matters, not where it lies.
        const Vec2 size = layer.bounds().size();
        if (indexed_ && (size.x + size.y) / params.bucket_size > 1e9)
            throw InvalidInput("make_field: layer '" + shown_text(layer.name) +
                               "' is too large for the bucket size");
        store_.build(layer.points, layer.closed, outside_sign);
        set_outside_sign(store_.outside_sign());
        if (indexed_) index_store(index_, store_);
    }

    FieldSample sample(const Vec2& x) const override {
        Nearest best;
        if (indexed_) {
            nearest_slot(index_, store_, x, best);
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
        nearest_slot(index_, store_, x, best, band_);
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
            if (indexed_) index_store(index_, store_);
            return;
        }
        if (!indexed_) return;
        for (std::uint32_t s : removed) erase_slot(index_, store_, s);
        for (std::uint32_t s : added) insert_slot(index_, store_, s);
    }

    FieldStats stats() const override {
        FieldStats st;
        st.segments = store_.segment_count();
        st.memory_bytes = store_.memory_bytes() + (indexed_ ? index_.memory_bytes() : 0);
        for (const Segment& s : store_.segments())
            if (s.live) st.bounds.extend(s.box());
        st.band_width = band_;
        return st;
    }

  private:
    SegmentStore store_;
    double band_ = 0.0;
    SegmentIndex index_;
    bool indexed_ = false;
};

}  // namespace

std::unique_ptr<LayerField> make_exact_field(const Layer& layer, int outside_sign,
                                             const ResolvedFieldParams& params, bool indexed) {
    return std::make_unique<ExactField>(layer, outside_sign, params, indexed);
}

}  // namespace strata::detail
