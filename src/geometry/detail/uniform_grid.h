#pragma once
/// @file Internal: the one spatial index of strata. A uniform grid of items (segments or
/// vertices of any number of layers) filed by their bounding boxes, with insert / erase / move,
/// box queries and an exact nearest search ring by ring. Used by the exact checks
/// (src/geometry/checks.cpp), the simplification driver (src/simplify/detail) and the exact
/// field backend (src/field/detail). Not installed.

#include "strata/core/types.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace strata::detail {

/// How a UniformGrid lays out its cells. Lengths in scene units.
struct UniformGridParams {
    double cell = 1.0;  ///< Side of a cell (scene units). > 0.
    Vec2 origin{0.0};   ///< Corner of cell (0, 0) (scene units): far from the scene origin,
                        ///< counting cells from the scene's corner keeps their numbers small.
    Box2 dense_bounds;  ///< The cells meeting this box are one dense array (no hashing,
                        ///< neighbours side by side in memory); the others, a hash map.
                        ///< Empty (the default): every cell in the hash map.
    double max_dense_cells =
        std::numeric_limits<double>::infinity();  ///< The dense array is
                                                  ///< made only when it has at most this many cells
                                                  ///< (else: all hashed).
    double max_item_cells =
        std::numeric_limits<double>::infinity();  ///< An item whose box
                                                  ///< touches more cells than this (a vertex
                                                  ///< carried far away) goes to one list that every
                                                  ///< query reads instead: memory stays bounded.
};

/// Uniform grid of items of type `Id` (a small copyable name, compared with ==), each filed in
/// the cells its box (scene units) touches. The grid does not store the boxes: erase() takes the
/// box the item was inserted with. Within a cell the items keep their insertion order, except
/// that erase() moves the cell's last item into the erased one's place. build() packs the dense
/// cells into one array (each cell's items side by side, cells in order: what a static index
/// reads fastest); the first insert() or erase() after it unpacks them.
template <class Id>
class UniformGrid {
  public:
    UniformGrid() : UniformGrid(UniformGridParams{}) {}
    explicit UniformGrid(const UniformGridParams& params) : params_(params) {
        const Box2& b = params.dense_bounds;
        if (b.is_empty()) return;
        const long long x0 = column(b.min.x), x1 = column(b.max.x);
        const long long y0 = row(b.min.y), y1 = row(b.max.y);
        const double cells = static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1);
        if (!(cells <= params.max_dense_cells)) return;
        x0_ = x0;
        y0_ = y0;
        nx_ = x1 - x0 + 1;
        ny_ = y1 - y0 + 1;
        // dense_ is made by the first insert() (build() packs the cells instead).
    }

    /// The items of one cell, as read by the queries.
    struct Items {
        const Id* first = nullptr;
        const Id* last = nullptr;
        const Id* begin() const { return first; }
        const Id* end() const { return last; }
        bool empty() const { return first == last; }
    };

    const UniformGridParams& params() const { return params_; }
    double cell() const { return params_.cell; }

    /// Empties every cell, keeping the cells and their capacity for the next fill.
    void clear() {
        if (packed_) drop_packed();
        for (auto& c : dense_) c.clear();
        for (auto& c : hashed_) c.second.clear();
        large_.clear();
        reset_range();
    }

    /// Empties the grid, then inserts every item of `ids` with its box `box_of(id)`, the dense
    /// cells packed (see the class comment).
    template <class BoxOf>
    void build(const std::vector<Id>& ids, BoxOf&& box_of) {
        clear();
        if (dense_cells() == 0) {
            for (const Id& id : ids) insert(id, box_of(id));
            return;
        }
        dense_ = {};
        start_.assign(dense_cells() + 1, 0);
        auto each_dense_cell = [&](const Id& id, bool first_pass, auto&& f) {
            const Box2 box = box_of(id);
            if (box.is_empty()) return;
            const Cells c = cells_of(box);
            if (is_large(c)) {
                if (first_pass) large_.push_back(id);
                return;
            }
            if (first_pass) extend_range(c);
            for (long long i = c.i0; i <= c.i1; ++i)
                for (long long j = c.j0; j <= c.j1; ++j) {
                    if (in_dense(i, j))
                        f(dense_index(i, j));
                    else if (first_pass)
                        hashed_cell(key(i, j)).push_back(id);
                }
        };
        for (const Id& id : ids) each_dense_cell(id, true, [&](std::size_t k) { ++start_[k + 1]; });
        for (std::size_t k = 0; k < dense_cells(); ++k) start_[k + 1] += start_[k];
        packed_ids_.resize(start_.back());
        std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
        for (const Id& id : ids)
            each_dense_cell(id, false, [&](std::size_t k) { packed_ids_[fill[k]++] = id; });
        packed_ = true;
    }

    /// Files `id` in the cells `box` touches (an empty box: nowhere).
    void insert(const Id& id, const Box2& box) {
        if (box.is_empty()) return;
        const Cells c = cells_of(box);
        if (is_large(c)) {
            large_.push_back(id);
            return;
        }
        unpack();
        if (dense_.empty()) dense_.resize(dense_cells());
        extend_range(c);
        for (long long i = c.i0; i <= c.i1; ++i)
            for (long long j = c.j0; j <= c.j1; ++j) slot(i, j).push_back(id);
    }

    /// Removes `id`, inserted with `box` (one copy of it from each cell).
    void erase(const Id& id, const Box2& box) {
        if (box.is_empty()) return;
        const Cells c = cells_of(box);
        if (is_large(c)) {
            remove_one(large_, id);
            return;
        }
        unpack();
        for_cells(c, [&](long long i, long long j) {
            if (std::vector<Id>* v = find_mutable(i, j)) remove_one(*v, id);
        });
    }

    /// Refiles `id` from box `from` (the one it was inserted with) to box `to`.
    void move(const Id& id, const Box2& from, const Box2& to) {
        erase(id, from);
        insert(id, to);
    }

    /// Calls f(id) for the items of the cells `box` touches and for the large ones, with
    /// repeats (an item once per such cell it is filed in): a superset of the items whose box
    /// meets `box`. Cells go column by column, bottom to top.
    template <class F>
    void query(const Box2& box, F&& f) const {
        for (const Id& id : large_) f(id);
        if (box.is_empty()) return;
        for_cells(cells_of(box), [&](long long i, long long j) {
            for (const Id& id : find(i, j)) f(id);
        });
    }

    /// Calls f(id) once per item whose box meets `box`, without marking anything: an item is
    /// reported only from the cell holding the lower-left corner of the two boxes'
    /// intersection. box_of(id) must give the box the item was inserted with.
    template <class BoxOf, class F>
    void query_once(const Box2& box, BoxOf&& box_of, F&& f) const {
        for (const Id& id : large_)
            if (box_of(id).overlaps(box)) f(id);
        if (box.is_empty()) return;
        const Cells q = cells_of(box);
        for_cells(q, [&](long long i, long long j) {
            for (const Id& id : find(i, j)) {
                const Box2 b = box_of(id);
                if (!b.overlaps(box)) continue;
                // The corner's cell; an item starting before the query box, the box's own.
                if ((b.min.x <= box.min.x ? q.i0 : column(b.min.x)) != i ||
                    (b.min.y <= box.min.y ? q.j0 : row(b.min.y)) != j)
                    continue;
                f(id);
            }
        });
    }

    /// Exact nearest search around `x` (scene units). `offer(id)` considers one item (the caller
    /// measures it and keeps the best with its own tie-break) and returns the square of the best
    /// distance so far (+inf while none). Offers the large items, then the items of the cells
    /// around x's, ring by ring (each ring clipped to the occupied cells; a cell farther than the
    /// best so far is skipped), until no item not offered yet can be as near as the best (items
    /// tied with it are all offered, so the caller's tie-break gives the brute-force winner),
    /// or, while the best is beyond `cutoff` (scene units), none can be within `cutoff`. When
    /// the rings have looked up more cells than the grid holds (x far from sparse items, e.g.
    /// outliers), every cell is read instead: the cost stays bounded by the grid's size.
    template <class Offer>
    void nearest(const Vec2& x, double cutoff, Offer&& offer) const {
        double best2 = std::numeric_limits<double>::infinity();
        for (const Id& id : large_) best2 = offer(id);
        if (imin_ > imax_) return;
        const double h = params_.cell;
        const Vec2& o = params_.origin;
        // Rounding slack of the cell corners (origin + i h) against column() / row().
        const double slack =
            1e-9 * (h + std::abs(x.x) + std::abs(x.y) + std::abs(o.x) + std::abs(o.y));
        // Squared distance from x to cell (i, j), grown by the slack.
        auto cell_distance2 = [&](long long i, long long j) {
            const double lo_x = o.x + static_cast<double>(i) * h - slack;
            const double lo_y = o.y + static_cast<double>(j) * h - slack;
            const double dx = std::max({lo_x - x.x, 0.0, x.x - (lo_x + h + 2.0 * slack)});
            const double dy = std::max({lo_y - x.y, 0.0, x.y - (lo_y + h + 2.0 * slack)});
            return dx * dx + dy * dy;
        };
        auto offer_cell = [&](long long i, long long j, const Items& v) {
            if (cell_distance2(i, j) > best2) return;
            for (const Id& id : v) best2 = offer(id);
        };
        const std::size_t budget = dense_cells() + hashed_.size() + 16;
        std::size_t looked_up = 0;
        auto visit = [&](long long i, long long j) {
            ++looked_up;
            // A cell farther than the best so far is not even looked up: the lookups, not the
            // offers, are most of a search through empty cells.
            if (cell_distance2(i, j) > best2) return;
            if (const Items v = find(i, j); !v.empty())
                for (const Id& id : v) best2 = offer(id);
        };
        const long long ci = column(x.x), cj = row(x.y);
        const long long start = std::max({imin_ - ci, ci - imax_, jmin_ - cj, cj - jmax_, 0LL});
        for (long long r = start;; ++r) {
            const long long i0 = std::max(ci - r, imin_), i1 = std::min(ci + r, imax_);
            const long long j0 = std::max(cj - r, jmin_), j1 = std::min(cj + r, jmax_);
            if (cj - r >= jmin_)
                for (long long i = i0; i <= i1 && looked_up <= budget; ++i) visit(i, cj - r);
            if (r > 0 && cj + r <= jmax_)
                for (long long i = i0; i <= i1 && looked_up <= budget; ++i) visit(i, cj + r);
            const long long k0 = std::max(j0, cj - r + 1), k1 = std::min(j1, cj + r - 1);
            if (ci - r >= imin_)
                for (long long j = k0; j <= k1 && looked_up <= budget; ++j) visit(ci - r, j);
            if (r > 0 && ci + r <= imax_)
                for (long long j = k0; j <= k1 && looked_up <= budget; ++j) visit(ci + r, j);
            if (looked_up > budget) {
                for (std::size_t c = 0; c < dense_cells(); ++c)
                    if (const Items v = dense_items(c); !v.empty())
                        offer_cell(x0_ + static_cast<long long>(c) / ny_,
                                   y0_ + static_cast<long long>(c) % ny_, v);
                for (const auto& cell : hashed_)  // keys do not hold far cell numbers: no pruning
                    for (const Id& id : cell.second) best2 = offer(id);
                return;
            }
            if (ci - r <= imin_ && ci + r >= imax_ && cj - r <= jmin_ && cj + r >= jmax_) return;
            // Distance from x to the cells outside this ring.
            const double lo_x = o.x + static_cast<double>(ci - r) * h;
            const double hi_x = o.x + static_cast<double>(ci + r + 1) * h;
            const double lo_y = o.y + static_cast<double>(cj - r) * h;
            const double hi_y = o.y + static_cast<double>(cj + r + 1) * h;
            const double margin =
                std::min({x.x - lo_x, hi_x - x.x, x.y - lo_y, hi_y - x.y}) - slack;
            if (margin > 0.0 && best2 < margin * margin) return;
            if (margin > cutoff && !(best2 <= cutoff * cutoff)) return;
        }
    }

    /// The same exact search as nearest(x, +inf, offer) for a caller that already holds a
    /// candidate at distance `within` of x (scene units; from an item it measured itself, e.g.
    /// the previous query's winner): offers the large items, then the items of the cells
    /// meeting the square of half-side `within` around x, each cell only while it is not
    /// farther than the best so far. Every item as near as the best is offered (ties included),
    /// so the caller's tie-break gives the brute-force winner. A wide square (more cells than
    /// kWithinCells) falls back to nearest().
    template <class Offer>
    void nearest_within(const Vec2& x, double within, Offer&& offer) const {
        constexpr long long kWithinCells = 16;
        if (!(within < std::numeric_limits<double>::infinity())) {
            nearest(x, within, offer);
            return;
        }
        double best2 = within * within;
        for (const Id& id : large_) best2 = offer(id);
        if (imin_ > imax_) return;
        const double h = params_.cell;
        const Vec2& o = params_.origin;
        const double slack =
            1e-9 * (h + std::abs(x.x) + std::abs(x.y) + std::abs(o.x) + std::abs(o.y));
        const double reach = within + slack;
        const long long i0 = std::max(column(x.x - reach), imin_);
        const long long i1 = std::min(column(x.x + reach), imax_);
        const long long j0 = std::max(row(x.y - reach), jmin_);
        const long long j1 = std::min(row(x.y + reach), jmax_);
        if (i0 > i1 || j0 > j1) return;
        if ((i1 - i0 + 1) * (j1 - j0 + 1) > kWithinCells) {
            nearest(x, std::numeric_limits<double>::infinity(), offer);
            return;
        }
        for (long long i = i0; i <= i1; ++i) {
            const double lo_x = o.x + static_cast<double>(i) * h - slack;
            const double dx = std::max({lo_x - x.x, 0.0, x.x - (lo_x + h + 2.0 * slack)});
            for (long long j = j0; j <= j1; ++j) {
                const Items v = find(i, j);
                if (v.empty()) continue;
                const double lo_y = o.y + static_cast<double>(j) * h - slack;
                const double dy = std::max({lo_y - x.y, 0.0, x.y - (lo_y + h + 2.0 * slack)});
                if (dx * dx + dy * dy > best2) continue;
                for (const Id& id : v) best2 = offer(id);
            }
        }
    }

    /// Cells, their item lists and the hash table's nodes and bucket array, in bytes.
    std::size_t memory_bytes() const {
        std::size_t bytes =
            dense_.capacity() * sizeof(std::vector<Id>) + start_.capacity() * sizeof(std::size_t) +
            packed_ids_.capacity() * sizeof(Id) + hashed_.bucket_count() * sizeof(void*) +
            large_.capacity() * sizeof(Id) + filter_.capacity() * sizeof(std::uint64_t);
        for (const auto& c : dense_) bytes += c.capacity() * sizeof(Id);
        // One node per hashed cell: key, list and the node's next pointer.
        for (const auto& [key, ids] : hashed_)
            bytes += sizeof(key) + sizeof(ids) + sizeof(void*) + ids.capacity() * sizeof(Id);
        return bytes;
    }

    /// The number of the cell holding coordinate `v` (in cells from the origin): floor(v),
    /// clamped to +-2^40, so that a coordinate far out (or NaN) stays a valid number.
    static long long to_cell(double v) {
        constexpr double kMax = 1099511627776.0;
        if (!(v > -kMax)) return -static_cast<long long>(kMax);
        if (!(v < kMax)) return static_cast<long long>(kMax);
        return static_cast<long long>(std::floor(v));
    }

  private:
    long long column(double x) const { return to_cell((x - params_.origin.x) / params_.cell); }
    long long row(double y) const { return to_cell((y - params_.origin.y) / params_.cell); }

    // The cells a box touches: columns i0..i1, rows j0..j1.
    struct Cells {
        long long i0, i1, j0, j1;
    };
    Cells cells_of(const Box2& box) const {
        return {column(box.min.x), column(box.max.x), row(box.min.y), row(box.max.y)};
    }
    bool is_large(const Cells& c) const {
        const double columns = static_cast<double>(c.i1 - c.i0 + 1);
        const double rows = static_cast<double>(c.j1 - c.j0 + 1);
        return !(columns * rows <= params_.max_item_cells);
    }

    void reset_range() {
        imin_ = jmin_ = std::numeric_limits<long long>::max();
        imax_ = jmax_ = std::numeric_limits<long long>::min();
    }

    // The occupied ones of cells `c`, column by column, bottom to top.
    template <class F>
    void for_cells(const Cells& c, F&& f) const {
        const long long i0 = std::max(c.i0, imin_), i1 = std::min(c.i1, imax_);
        const long long j0 = std::max(c.j0, jmin_), j1 = std::min(c.j1, jmax_);
        for (long long i = i0; i <= i1; ++i)
            for (long long j = j0; j <= j1; ++j) f(i, j);
    }

    static void remove_one(std::vector<Id>& v, const Id& id) {
        for (std::size_t k = 0; k < v.size(); ++k)
            if (v[k] == id) {
                v[k] = v.back();
                v.pop_back();
                return;
            }
    }

    bool in_dense(long long i, long long j) const {
        return i >= x0_ && i < x0_ + nx_ && j >= y0_ && j < y0_ + ny_;
    }
    static std::uint64_t key(long long i, long long j) {
        return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
               static_cast<std::uint64_t>(static_cast<std::uint32_t>(j));
    }
    std::size_t dense_cells() const { return static_cast<std::size_t>(nx_ * ny_); }
    std::size_t dense_index(long long i, long long j) const {
        return static_cast<std::size_t>((i - x0_) * ny_ + (j - y0_));
    }
    void extend_range(const Cells& c) {
        imin_ = std::min(imin_, c.i0);
        imax_ = std::max(imax_, c.i1);
        jmin_ = std::min(jmin_, c.j0);
        jmax_ = std::max(jmax_, c.j1);
    }
    void drop_packed() {
        start_ = {};
        packed_ids_ = {};
        packed_ = false;
    }
    // The dense cells back in one list each (before an edit).
    void unpack() {
        if (!packed_) return;
        dense_.resize(dense_cells());
        for (std::size_t k = 0; k < dense_cells(); ++k)
            dense_[k].assign(packed_ids_.begin() + static_cast<std::ptrdiff_t>(start_[k]),
                             packed_ids_.begin() + static_cast<std::ptrdiff_t>(start_[k + 1]));
        drop_packed();
    }
    std::vector<Id>& slot(long long i, long long j) {
        if (in_dense(i, j)) return dense_[dense_index(i, j)];
        return hashed_cell(key(i, j));
    }
    // The hashed cell `k`, made (and marked in filter_) if new.
    std::vector<Id>& hashed_cell(std::uint64_t k) {
        const auto [it, made] = hashed_.try_emplace(k);
        if (made) {
            if (hashed_.size() * kFilterBitsPerCell > filter_.size() * 64) grow_filter();
            mark(k);
        }
        return it->second;
    }
    // filter_: one bit per hash of a cell key, set for every key in hashed_ (a cell emptied
    // keeps its bit, as it keeps its entry). A clear bit says that a cell is not hashed
    // without a lookup in hashed_, whose division by its bucket count (and one per node of
    // the bucket) made most of the cost of a nearest search through empty hashed cells.
    static constexpr std::size_t kFilterBitsPerCell = 16;
    std::size_t filter_bit(std::uint64_t k) const {
        return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> filter_shift_);
    }
    void mark(std::uint64_t k) {
        const std::size_t b = filter_bit(k);
        filter_[b >> 6] |= std::uint64_t{1} << (b & 63);
    }
    bool may_be_hashed(std::uint64_t k) const {
        const std::size_t b = filter_bit(k);
        return (filter_[b >> 6] >> (b & 63)) & 1u;
    }
    // Makes filter_ the smallest power of two of at least 4,096 bits with kFilterBitsPerCell
    // bits a hashed cell, and marks every key again.
    void grow_filter() {
        std::size_t bits = 4096;
        int shift = 64 - 12;
        while (bits < hashed_.size() * kFilterBitsPerCell) {
            bits *= 2;
            --shift;
        }
        filter_.assign(bits / 64, 0);
        filter_shift_ = shift;
        for (const auto& cell : hashed_) mark(cell.first);
    }
    Items dense_items(std::size_t k) const {
        if (packed_) return {packed_ids_.data() + start_[k], packed_ids_.data() + start_[k + 1]};
        if (dense_.empty()) return {};  // nothing inserted yet
        return {dense_[k].data(), dense_[k].data() + dense_[k].size()};
    }
    Items find(long long i, long long j) const {
        if (in_dense(i, j)) return dense_items(dense_index(i, j));
        if (hashed_.empty()) return {};
        const std::uint64_t k = key(i, j);
        if (!may_be_hashed(k)) return {};
        const auto it = hashed_.find(k);
        if (it == hashed_.end()) return {};
        return {it->second.data(), it->second.data() + it->second.size()};
    }
    std::vector<Id>* find_mutable(long long i, long long j) {
        if (in_dense(i, j)) return dense_.empty() ? nullptr : &dense_[dense_index(i, j)];
        const auto it = hashed_.find(key(i, j));
        return it == hashed_.end() ? nullptr : &it->second;
    }

    UniformGridParams params_;
    long long x0_ = 0, y0_ = 0, nx_ = 0, ny_ = 0;  // the dense block of cells (empty: none)
    std::vector<std::vector<Id>> dense_;           // unpacked dense cells
    bool packed_ = false;             // the dense cells are start_ / packed_ids_ instead
    std::vector<std::size_t> start_;  // packed: cell k's items are [start_[k], start_[k+1])
    std::vector<Id> packed_ids_;
    std::unordered_map<std::uint64_t, std::vector<Id>> hashed_;  // the cells outside it
    std::vector<std::uint64_t> filter_;  // see hashed_cell(): empty while hashed_ is
    int filter_shift_ = 64;              // filter_bit(): the top 64 - filter_shift_ bits
    std::vector<Id> large_;                                      // items of too many cells
    // Range of the cells occupied since the last clear() (erase() does not shrink it).
    long long imin_ = std::numeric_limits<long long>::max();
    long long imax_ = std::numeric_limits<long long>::min();
    long long jmin_ = std::numeric_limits<long long>::max();
    long long jmax_ = std::numeric_limits<long long>::min();
};

}  // namespace strata::detail
