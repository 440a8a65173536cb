// Grid backend: the layers of a scene share one OpenVDB FloatGrid, layer i at index z = i
// (layers 8k..8k+7 in the k-th row of leaves along z), in index space (voxel (i, j) is the
// point (i h, j h); the shared grid keeps a unit transform, since OpenVDB refuses a linear
// transform whose determinant h^3 is near 0, as for scenes in kilometres drawn in metres, and
// only the exported slabs carry createLinearTransform(h)). In every leaf, layer i's band voxels hold its exact signed values and
// its other voxels the band width with layer i's sign. Points whose bilinear corners fall in no
// leaf take layer i's sign from the first leaf voxel of its plane along +x. The only translation
// unit of the field module that includes OpenVDB (it also writes .vdb files).

#include "field/detail/backends.h"
#include "field/detail/grid_inspect.h"
#include "field/detail/grid_module.h"
#include "field/detail/segment_index.h"
#include "field/detail/segment_store.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/field/vdb_io.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <system_error>
#include <utility>

namespace strata::detail {

namespace {

// Internal nodes of 16^3 and 8^3 children (1024^3 and 64^3 voxels) instead of OpenVDB's default
// 32^3 and 16^3 (4096^3 and 128^3): the layers fill one leaf row along z, so most of an internal
// node's table is empty; the smaller tables hold less of that (docs/field.md). The leaves are the
// standard 8^3 ones, and the .vdb files hold standard FloatGrids (write_vdb extracts slabs).
using Tree = openvdb::tree::Tree4<float, 4, 3, 3>::Type;
using StackGrid = openvdb::Grid<Tree>;
using Leaf = Tree::LeafNodeType;
using ConstAccessor = openvdb::tree::ValueAccessor<const Tree, false>;
using N2 = Tree::RootNodeType::ChildNodeType;  // 1024^3 voxels
using N1 = N2::ChildNodeType;                  // 64^3 voxels

constexpr int kLeafDim = 8;                  // voxels per leaf side; layers per leaf row
constexpr int kPlane = kLeafDim * kLeafDim;  // voxels of one z plane of a leaf
constexpr double kMaxIndex = 1073741824.0;   // 2^30: voxel coordinates stay in int32
constexpr std::uint64_t kPlaneBits = 0x0101010101010101ull;  // z = 0 bits of a mask word

long floor_div(long v, long d) {
    return v >= 0 ? v / d : -((-v + d - 1) / d);
}

std::uint64_t leaf_key(long i, long j) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
           static_cast<std::uint64_t>(static_cast<std::uint32_t>(j));
}
long key_i(std::uint64_t k) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(k >> 32));
}
long key_j(std::uint64_t k) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(k & 0xffffffffu));
}

/// Offset in a leaf of voxel (vx, vy) of the plane z (any z: its position in the leaf row).
openvdb::Index voxel_offset(int vx, int vy, int z) {
    return static_cast<openvdb::Index>((vx << 6) | (vy << 3) | (z & (kLeafDim - 1)));
}

/// Number of active voxels of plane z in `leaf`.
std::size_t plane_active_count(const Leaf& leaf, int z) {
    std::size_t count = 0;
    const std::uint64_t bits = kPlaneBits << (z & (kLeafDim - 1));
    for (openvdb::Index w = 0; w < 8; ++w)
        count += static_cast<std::size_t>(
            __builtin_popcountll(leaf.getValueMask().getWord<std::uint64_t>(w) & bits));
    return count;
}

/// True when a plane other than z of `leaf` has an active voxel.
bool other_planes_active(const Leaf& leaf, int z) {
    const std::uint64_t others = ~(kPlaneBits << (z & (kLeafDim - 1)));
    for (openvdb::Index w = 0; w < 8; ++w)
        if ((leaf.getValueMask().getWord<std::uint64_t>(w) & others) != 0) return true;
    return false;
}

/// The bilinear interpolant of the 4 corner values (00, 10, 01, 11) at (fx, fy) in [0, 1]^2,
/// in double, and its gradient; every sampling path goes through here.
FieldSample bilinear(const float (&v)[4], double fx, double fy, double h) {
    FieldSample out;
    const double d00 = v[0], d10 = v[1], d01 = v[2], d11 = v[3];
    out.value = (1.0 - fy) * ((1.0 - fx) * d00 + fx * d10) + fy * ((1.0 - fx) * d01 + fx * d11);
    out.gradient = Vec2(((1.0 - fy) * (d10 - d00) + fy * (d11 - d01)) / h,
                        ((1.0 - fx) * (d01 - d00) + fx * (d11 - d10)) / h);
    return out;
}

}  // namespace

/// @brief The layer-stacked grid of a scene and the segments of every layer.
/// Invariants (a full build establishes them, update() keeps them):
/// - the leaf of row r (z in [8r, 8r + 8)) at (li, lj) exists iff a layer of that row has a band
///   voxel (voxel centre within band_width of the layer) in it;
/// - in an existing leaf, plane z = i holds layer i's plane: if layer i has band voxels there,
///   their exact values (active) and +-band with the sign spread from the 4-neighbours
///   elsewhere; if not, +-band (inactive) with the sign of layer i at the leaf's origin voxel for
///   closed layers (exact nearest-segment search), +band for open layers;
/// - planes of a row beyond the last layer, and every tile, hold the background +band;
/// - internal nodes without children are tiles, so the tree equals a fresh build's.
/// Each plane depends only on its layer and its leaf, so updating one layer's planes where its
/// geometry changed equals a rebuild.
/// With a region (FieldParams::region), only the leaves of the region's leaf range exist (the
/// region grown by the band and a voxel, so that a sample within band of the region reads the
/// corners a whole grid would); a walk that leaves that range takes the exact sign instead.
class GridStack {
  public:
    GridStack(const std::vector<const Layer*>& layers, const std::vector<int>& outside_signs,
              const ResolvedFieldParams& params)
        : h_(params.voxel_size), band_(params.band_width) {
        set_region(params.region);
        layers_.reserve(layers.size());
        for (std::size_t l = 0; l < layers.size(); ++l) {
            const Layer& layer = *layers[l];
            check_points(layer.points, layer.closed, "make_field");
            check_extent(layer.name, layer.points, 0, layer.points.size());
            LayerData& d = layers_.emplace_back(params.bucket_size);
            d.name = layer.name;
            d.closed = layer.closed;
            d.store.build(layer.points, layer.closed, outside_signs[l]);
            index_store(d.index, d.store);
        }
        build();
    }

    std::size_t size() const { return layers_.size(); }
    const std::string& name(std::size_t l) const { return layers_[l].name; }
    bool is_closed(std::size_t l) const { return layers_[l].closed; }
    int outside_sign(std::size_t l) const { return layers_[l].store.outside_sign(); }
    double voxel_size() const { return h_; }
    const Tree& tree() const { return grid_->tree(); }

    FieldSample sample(std::size_t l, const Vec2& x) const {
        FieldSample out;
        int i0 = 0, j0 = 0;
        double fx = 0.0, fy = 0.0;
        if (!cell_of(x, i0, j0, fx, fy)) {
            out.value = band_;
        } else {
            ConstAccessor acc(tree());
            const int z = static_cast<int>(l);
            const Leaf* leaf[4];
            probe_corners(acc, i0, j0, z, leaf);
            float v[4];
            const bool on = read_corners(acc, leaf, i0, j0, z, v);
            out = bilinear(v, fx, fy, h_);
            out.in_band = on;
        }
        out.border = layers_[l].store.border(x);
        out.past_end = out.border < 0.0;
        return out;
    }

    // Stops at the first corner out of the band: no walk through the tiles.
    FieldSample sample_in_band(std::size_t l, const Vec2& x) const {
        FieldSample out;
        int i0 = 0, j0 = 0;
        double fx = 0.0, fy = 0.0;
        if (!cell_of(x, i0, j0, fx, fy)) return out;
        ConstAccessor acc(tree());
        const int z = static_cast<int>(l);
        float v[4];
        for (int c = 0; c < 4; ++c) {
            const openvdb::Coord xyz(i0 + (c & 1), j0 + (c >> 1), z);
            const Leaf* leaf = acc.probeConstLeaf(xyz);
            if (leaf == nullptr) return out;
            const openvdb::Index n = Leaf::coordToOffset(xyz);
            if (!leaf->isValueOn(n)) return out;
            v[c] = leaf->getValue(n);
        }
        out = bilinear(v, fx, fy, h_);
        out.in_band = true;
        out.border = layers_[l].store.border(x);
        out.past_end = out.border < 0.0;
        return out;
    }

    // One probe per corner and leaf row serves every layer of the row.
    void sample_all(const Vec2& x, std::vector<FieldSample>& out) const {
        out.resize(layers_.size());
        int i0 = 0, j0 = 0;
        double fx = 0.0, fy = 0.0;
        if (!cell_of(x, i0, j0, fx, fy)) {
            for (std::size_t l = 0; l < layers_.size(); ++l) {
                out[l] = FieldSample{};
                out[l].value = band_;
                out[l].border = layers_[l].store.border(x);
                out[l].past_end = out[l].border < 0.0;
            }
            return;
        }
        ConstAccessor acc(tree());
        const Leaf* leaf[4] = {nullptr, nullptr, nullptr, nullptr};
        for (std::size_t l = 0; l < layers_.size(); ++l) {
            const int z = static_cast<int>(l);
            if (z % kLeafDim == 0) probe_corners(acc, i0, j0, z, leaf);
            float v[4];
            const bool on = read_corners(acc, leaf, i0, j0, z, v);
            out[l] = bilinear(v, fx, fy, h_);
            out[l].in_band = on;
            out[l].border = layers_[l].store.border(x);
            out[l].past_end = out[l].border < 0.0;
        }
    }

    void update(std::size_t l, const std::vector<Vec2>& points, const PolylineEdit& edit) {
        LayerData& d = layers_[l];
        if (edit.first + edit.inserted <= points.size())
            check_extent(d.name, points, edit.first, edit.first + edit.inserted);
        std::vector<std::uint32_t> removed, added;
        if (!d.store.splice(points, edit, removed, added)) {
            // Not local: the store was rebuilt. Recompute the layer's plane in every leaf of its
            // row and in every leaf its new segments reach.
            index_store(d.index, d.store);
            std::vector<std::uint64_t> keys;
            const int row_z = row_origin_z(l);
            for (auto it = tree().cbeginLeaf(); it; ++it)
                if (it->origin().z() == row_z)
                    keys.push_back(
                        leaf_key(it->origin().x() / kLeafDim, it->origin().y() / kLeafDim));
            const auto& segs = d.store.segments();
            for (const Segment& s : segs)
                if (s.live) for_leaves(s, [&](std::uint64_t k) { keys.push_back(k); });
            refresh(l, std::move(keys));
            return;
        }
        if (removed.empty() && added.empty()) return;
        std::vector<std::uint64_t> keys;
        Box2 chain;
        for (std::uint32_t s : removed) {
            const Segment& seg = d.store.segments()[s];
            for_leaves(seg, [&](std::uint64_t k) { keys.push_back(k); });
            chain.extend(seg.box());
            erase_slot(d.index, d.store, s);
        }
        for (std::uint32_t s : added) {
            const Segment& seg = d.store.segments()[s];
            for_leaves(seg, [&](std::uint64_t k) { keys.push_back(k); });
            chain.extend(seg.box());
            insert_slot(d.index, d.store, s);
        }
        // A closed layer's sign changes only inside the loop of the old and new chains (which
        // share their end vertices), so within the chain's box: the planes of leaves there where
        // the layer has no band voxel take the new sign.
        if (d.closed) leaves_touching(chain, row_origin_z(l), keys);
        refresh(l, std::move(keys));
    }

    FieldStats stats(std::size_t l) const {
        const LayerData& d = layers_[l];
        FieldStats st;
        st.segments = d.store.segment_count();
        const int z = static_cast<int>(l), row_z = row_origin_z(l);
        openvdb::CoordBBox bb;
        for (auto it = tree().cbeginLeaf(); it; ++it) {
            if (it->origin().z() != row_z) continue;
            const std::size_t on = plane_active_count(*it, z);
            if (on == 0) continue;
            st.active_voxels += on;
            ++st.leaves;
            for (int vx = 0; vx < kLeafDim; ++vx)
                for (int vy = 0; vy < kLeafDim; ++vy)
                    if (it->isValueOn(voxel_offset(vx, vy, z)))
                        bb.expand(openvdb::Coord(it->origin().x() + vx, it->origin().y() + vy, 0));
        }
        if (!bb.empty()) {
            st.bounds.extend(Vec2(bb.min().x(), bb.min().y()) * h_);
            st.bounds.extend(Vec2(bb.max().x(), bb.max().y()) * h_);
        }
        // The shared grid is attributed in proportion to the layer's band voxels.
        const auto total_active = static_cast<double>(grid_->activeVoxelCount());
        const double share =
            total_active > 0.0 ? static_cast<double>(st.active_voxels) / total_active : 0.0;
        st.memory_bytes = d.store.memory_bytes() + d.index.memory_bytes() +
                          static_cast<std::size_t>(share * static_cast<double>(grid_->memUsage()));
        st.voxel_size = h_;
        st.band_width = band_;
        return st;
    }

    FieldStats total_stats() const {
        FieldStats st;
        st.memory_bytes = static_cast<std::size_t>(grid_->memUsage());
        for (const LayerData& d : layers_) {
            st.segments += d.store.segment_count();
            st.memory_bytes += d.store.memory_bytes() + d.index.memory_bytes();
        }
        st.active_voxels = static_cast<std::size_t>(grid_->activeVoxelCount());
        st.leaves = leaf_count_;
        const openvdb::CoordBBox bb = grid_->evalActiveVoxelBoundingBox();
        if (!bb.empty()) {
            st.bounds.extend(Vec2(bb.min().x(), bb.min().y()) * h_);
            st.bounds.extend(Vec2(bb.max().x(), bb.max().y()) * h_);
        }
        st.voxel_size = h_;
        st.band_width = band_;
        return st;
    }

    /// Layer l's value at voxels (i, j) for i in [i0, i1] (row j) into `values` / `active`
    /// (appended): the stored plane value in a leaf, the walked +-band elsewhere.
    void plane_row(std::size_t l, int i0, int i1, int j, std::vector<float>& values,
                   std::vector<char>& active) const {
        ConstAccessor acc(tree());
        const int z = static_cast<int>(l);
        const std::size_t first = values.size();
        values.resize(first + static_cast<std::size_t>(i1 - i0 + 1));
        active.resize(values.size());
        // Right to left: a voxel in no leaf takes the sign of the next leaf voxel to its right.
        float carry = walk(acc, i1, j, z);
        for (int i = i1; i >= i0; --i) {
            const openvdb::Coord xyz(i, j, z);
            const auto k = first + static_cast<std::size_t>(i - i0);
            if (const Leaf* leaf = acc.probeConstLeaf(xyz)) {
                const openvdb::Index n = Leaf::coordToOffset(xyz);
                values[k] = leaf->getValue(n);
                active[k] = leaf->isValueOn(n) ? 1 : 0;
                carry = values[k] < 0.f ? -static_cast<float>(band_) : static_cast<float>(band_);
            } else {
                values[k] = carry;
                active[k] = 0;
            }
        }
    }

    /// Layer l as a standard z = 0 slab: the leaves where it has band voxels, its plane copied
    /// to z = 0 and its signs to z = 1..7, internal nodes flood filled (as write_vdb writes it).
    openvdb::FloatGrid::Ptr slab(std::size_t l) const {
        const auto bg = static_cast<float>(band_);
        auto grid = openvdb::FloatGrid::create(bg);
        try {
            grid->setTransform(openvdb::math::Transform::createLinearTransform(h_));
        } catch (const openvdb::ArithmeticError&) {
            throw InvalidInput("write_vdb: the voxel size " + format_number(h_) +
                               " is too small for an OpenVDB transform (its cube must be "
                               "well above 1e-8); scale the scene up");
        }
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
        grid->setName(layers_[l].name);
        const int z = static_cast<int>(l), row_z = row_origin_z(l);
        for (auto it = tree().cbeginLeaf(); it; ++it) {
            if (it->origin().z() != row_z || plane_active_count(*it, z) == 0) continue;
            auto* leaf = new Leaf(openvdb::Coord(it->origin().x(), it->origin().y(), 0), bg, false);
            for (int vx = 0; vx < kLeafDim; ++vx)
                for (int vy = 0; vy < kLeafDim; ++vy) {
                    const openvdb::Index n = voxel_offset(vx, vy, z);
                    const float v = it->getValue(n);
                    const float off = v < 0.f ? -bg : bg;
                    for (int vz = 0; vz < kLeafDim; ++vz) {
                        if (vz == 0 && it->isValueOn(n)) {
                            leaf->setValueOn(voxel_offset(vx, vy, 0), v);
                        } else {
                            leaf->setValueOff(voxel_offset(vx, vy, vz), vz == 0 ? v : off);
                        }
                    }
                }
            grid->tree().addLeaf(leaf);
        }
        openvdb::tools::signedFloodFill(grid->tree(), true, 1, 1);
        return grid;
    }

  private:
    /// One layer's 64 voxels of a leaf: values (index vx * 8 + vy), band voxels (bit vx * 8 + vy).
    struct Plane {
        std::array<float, kPlane> value{};
        std::uint64_t active = 0;
    };

    struct LayerData {
        explicit LayerData(double cell) : index(make_segment_index(cell)) {}
        std::string name;
        bool closed = false;
        SegmentStore store;
        SegmentIndex index;
    };

    // What refresh() computes for one leaf (in parallel), applied serially.
    struct Change {
        Plane plane;
        bool band = false;           // the layer has band voxels in the leaf
        bool exists = false;         // the leaf exists now
        bool keep = false;           // no band voxels, but another plane has some
        float off = 0.f;             // the layer's plane value when it has no band voxels
        std::vector<float> row_off;  // new leaf: every plane of the row without band voxels
    };

    static int row_origin_z(std::size_t l) { return static_cast<int>(l) / kLeafDim * kLeafDim; }

    std::size_t row_end(std::size_t l) const {
        return std::min(layers_.size(), static_cast<std::size_t>(row_origin_z(l) + kLeafDim));
    }

    void check_extent(const std::string& layer, const std::vector<Vec2>& points, std::size_t begin,
                      std::size_t end) const {
        for (std::size_t i = begin; i < end; ++i)
            if (const Vec2& p = points[i]; !(std::abs(p.x / h_) + band_ / h_ < 0.5 * kMaxIndex &&
                                             std::abs(p.y / h_) + band_ / h_ < 0.5 * kMaxIndex))
                throw InvalidInput("make_field: layer '" + shown_text(layer) +
                                   "' spans more than 2^29 "
                                   "voxels of size " +
                                   format_number(h_) + " (raise FieldParams::voxel_size)");
    }

    // The cell of x: lower corner (i0, j0) and position (fx, fy) in it; false beyond 2^30 voxels.
    bool cell_of(const Vec2& x, int& i0, int& j0, double& fx, double& fy) const {
        const double gx = x.x / h_, gy = x.y / h_;
        if (!(std::abs(gx) < kMaxIndex && std::abs(gy) < kMaxIndex)) return false;
        const double fx0 = std::floor(gx), fy0 = std::floor(gy);
        i0 = static_cast<int>(fx0);
        j0 = static_cast<int>(fy0);
        fx = gx - fx0;
        fy = gy - fy0;
        return true;
    }

    static void probe_corners(ConstAccessor& acc, int i0, int j0, int z, const Leaf* (&leaf)[4]) {
        for (int c = 0; c < 4; ++c)
            leaf[c] = acc.probeConstLeaf(openvdb::Coord(i0 + (c & 1), j0 + (c >> 1), z));
    }

    // Layer z's corner values (00, 10, 01, 11) from the corner leaves (nullptr: no leaf);
    // true when all four are band voxels.
    bool read_corners(ConstAccessor& acc, const Leaf* const (&leaf)[4], int i0, int j0, int z,
                      float (&v)[4]) const {
        bool on = true;
        for (int row = 0; row < 2; ++row) {
            const int c0 = 2 * row, c1 = 2 * row + 1, j = j0 + row;
            // Right corner first: a left corner in no leaf takes the sign of the right one.
            if (leaf[c1] != nullptr) {
                const openvdb::Index n = Leaf::coordToOffset(openvdb::Coord(i0 + 1, j, z));
                v[c1] = leaf[c1]->getValue(n);
                on = on && leaf[c1]->isValueOn(n);
            } else {
                v[c1] = walk(acc, i0 + 1, j, z);
                on = false;
            }
            if (leaf[c0] != nullptr) {
                const openvdb::Index n = Leaf::coordToOffset(openvdb::Coord(i0, j, z));
                v[c0] = leaf[c0]->getValue(n);
                on = on && leaf[c0]->isValueOn(n);
            } else {
                v[c0] = v[c1] < 0.f ? -static_cast<float>(band_) : static_cast<float>(band_);
                on = false;
            }
        }
        return on;
    }

    // Value of layer z at voxel (i, j), which is in no leaf: +-band with the sign of the first
    // leaf voxel of plane z to its right (row j), +band when there is none. Between the two
    // every voxel is in no leaf, so no layer of the row is in band there: a closed layer's
    // curve does not cross the row there (a crossing is within h/2 of a voxel centre), its
    // sign is the same. Tiles are skipped whole; the walk ends past the rightmost leaf.
    float walk(ConstAccessor& acc, int i, int j, int z) const {
        const auto bg = static_cast<float>(band_);
        long x = static_cast<long>(i) + 1, end = max_leaf_x_;
        if (limited_) {
            // Leaves exist only in the region's range: a walk from outside it, or one that
            // leaves it, could skip leaves a whole grid has.
            if (!in_region(floor_div(i, kLeafDim), floor_div(j, kLeafDim)))
                return exact_off_value(layers_[static_cast<std::size_t>(z)], i, j);
            end = std::min(end, (leaf_i1_ + 1) * kLeafDim - 1);
        }
        while (x <= end) {
            const openvdb::Coord xyz(static_cast<int>(x), j, z);
            if (const Leaf* leaf = acc.probeConstLeaf(xyz))
                return leaf->getValue(Leaf::coordToOffset(xyz)) < 0.f ? -bg : bg;
            const int depth = acc.getValueDepth(xyz);  // 2: leaf-sized tile, 1: N1, else N2
            const long span = depth == 2 ? static_cast<long>(Leaf::DIM)
                                         : static_cast<long>(depth == 1 ? N1::DIM : N2::DIM);
            x = (floor_div(x, span) + 1) * span;
        }
        return limited_ ? exact_off_value(layers_[static_cast<std::size_t>(z)], i, j) : bg;
    }

    // Layer d's value at voxel (i, j) out of its band: +-band with its exact sign for a closed
    // layer, +band for an open one.
    float exact_off_value(const LayerData& d, long i, long j) const {
        const auto bg = static_cast<float>(band_);
        if (!d.closed) return bg;
        const Vec2 p(static_cast<double>(i) * h_, static_cast<double>(j) * h_);
        Nearest best;
        nearest_slot(d.index, d.store, p, best);
        return d.store.evaluate(p, best).value < 0.0 ? -bg : bg;
    }

    // The leaf range [leaf_i0_, leaf_i1_] x [leaf_j0_, leaf_j1_] of `region` (FieldParams).
    void set_region(const Box2& region) {
        limited_ = !region.is_empty();
        if (!limited_) return;
        const Box2 r = region.inflated(band_);
        const auto index = [&](double v, double offset) {
            const double g = std::floor(v / h_) + offset;
            return static_cast<long>(std::clamp(g, -kMaxIndex, kMaxIndex));
        };
        leaf_i0_ = floor_div(index(r.min.x, -1.0), kLeafDim);
        leaf_i1_ = floor_div(index(r.max.x, 2.0), kLeafDim);
        leaf_j0_ = floor_div(index(r.min.y, -1.0), kLeafDim);
        leaf_j1_ = floor_div(index(r.max.y, 2.0), kLeafDim);
    }

    bool in_region(long li, long lj) const {
        return !limited_ || (li >= leaf_i0_ && li <= leaf_i1_ && lj >= leaf_j0_ && lj <= leaf_j1_);
    }

    // Clips the leaf range [li0, li1] x [lj0, lj1] to the region's.
    void clip_to_region(long& li0, long& li1, long& lj0, long& lj1) const {
        if (!limited_) return;
        li0 = std::max(li0, leaf_i0_);
        li1 = std::min(li1, leaf_i1_);
        lj0 = std::max(lj0, leaf_j0_);
        lj1 = std::min(lj1, leaf_j1_);
    }

    // Leaves of the layer's row holding a voxel centre (i h, j h) within the band of the
    // segment's bounding box.
    template <typename F>
    void for_leaves(const Segment& s, F&& f) const {
        const Box2 box = s.box().inflated(band_);
        const long i0 = static_cast<long>(std::ceil(box.min.x / h_));
        const long i1 = static_cast<long>(std::floor(box.max.x / h_));
        const long j0 = static_cast<long>(std::ceil(box.min.y / h_));
        const long j1 = static_cast<long>(std::floor(box.max.y / h_));
        if (i0 > i1 || j0 > j1) return;
        long li0 = floor_div(i0, kLeafDim), li1 = floor_div(i1, kLeafDim);
        long lj0 = floor_div(j0, kLeafDim), lj1 = floor_div(j1, kLeafDim);
        clip_to_region(li0, li1, lj0, lj1);
        for (long li = li0; li <= li1; ++li)
            for (long lj = lj0; lj <= lj1; ++lj) f(leaf_key(li, lj));
    }

    // Appends the keys of the existing leaves of row `row_z` that touch `box`.
    void leaves_touching(const Box2& box, int row_z, std::vector<std::uint64_t>& keys) const {
        long li0 = floor_div(static_cast<long>(std::floor(box.min.x / h_)), kLeafDim);
        long li1 = floor_div(static_cast<long>(std::ceil(box.max.x / h_)), kLeafDim);
        long lj0 = floor_div(static_cast<long>(std::floor(box.min.y / h_)), kLeafDim);
        long lj1 = floor_div(static_cast<long>(std::ceil(box.max.y / h_)), kLeafDim);
        clip_to_region(li0, li1, lj0, lj1);
        if (li0 > li1 || lj0 > lj1) return;
        const auto positions =
            static_cast<double>(li1 - li0 + 1) * static_cast<double>(lj1 - lj0 + 1);
        if (positions <= 4.0 * static_cast<double>(leaf_count_)) {
            for (long li = li0; li <= li1; ++li)
                for (long lj = lj0; lj <= lj1; ++lj)
                    if (tree().probeConstLeaf(leaf_origin(leaf_key(li, lj), row_z)) != nullptr)
                        keys.push_back(leaf_key(li, lj));
            return;
        }
        for (auto it = tree().cbeginLeaf(); it; ++it) {
            const long li = it->origin().x() / kLeafDim, lj = it->origin().y() / kLeafDim;
            if (it->origin().z() == row_z && li >= li0 && li <= li1 && lj >= lj0 && lj <= lj1)
                keys.push_back(leaf_key(li, lj));
        }
    }

    static openvdb::Coord leaf_origin(std::uint64_t key, int row_z) {
        return openvdb::Coord(static_cast<int>(key_i(key) * kLeafDim),
                              static_cast<int>(key_j(key) * kLeafDim), row_z);
    }

    // Layer d's band voxels in leaf `key`: exact values, and the other voxels' signs spread from
    // their 4-neighbours inside the leaf (a sign change between neighbours puts both within
    // h <= band of the curve, so both are band voxels). False when it has none.
    bool band_plane(const LayerData& d, std::uint64_t key, Plane& plane,
                    std::vector<std::uint32_t>& ids) const {
        const long oi = key_i(key) * kLeafDim, oj = key_j(key) * kLeafDim;
        Box2 box;
        box.extend(Vec2(static_cast<double>(oi) * h_, static_cast<double>(oj) * h_));
        box.extend(Vec2(static_cast<double>(oi + kLeafDim - 1) * h_,
                        static_cast<double>(oj + kLeafDim - 1) * h_));
        // Every segment within band of a voxel centre has a point in the box inflated by the
        // band (one more voxel against rounding), so it is listed in a bucket the box touches.
        slot_candidates(d.index, box.inflated(band_ + h_), ids);
        // Only those whose box inflated by the band reaches a voxel centre (a margin against
        // rounding): the offers below dominate the build.
        const double reach = band_ + 1e-3 * h_;
        ids.erase(
            std::remove_if(ids.begin(), ids.end(),
                           [&](std::uint32_t s) {
                               return !d.store.segments()[s].box().inflated(reach).overlaps(box);
                           }),
            ids.end());
        if (ids.empty()) return false;
        std::array<int, kPlane> sign{};
        const double band2 = band_ * band_;
        plane.active = 0;
        for (int vx = 0; vx < kLeafDim; ++vx)
            for (int vy = 0; vy < kLeafDim; ++vy) {
                const int k = vx * kLeafDim + vy;
                const Vec2 p(static_cast<double>(oi + vx) * h_, static_cast<double>(oj + vy) * h_);
                Nearest best;
                for (std::uint32_t s : ids) d.store.offer(p, s, best);
                if (best.found() && best.dist2 <= band2) {
                    const double v = d.store.evaluate(p, best).value;
                    plane.value[static_cast<std::size_t>(k)] = static_cast<float>(v);
                    sign[static_cast<std::size_t>(k)] = v < 0.0 ? -1 : 1;
                    plane.active |= std::uint64_t{1} << k;
                }
            }
        if (plane.active == 0) return false;
        for (bool changed = true; changed;) {
            changed = false;
            for (int vx = 0; vx < kLeafDim; ++vx)
                for (int vy = 0; vy < kLeafDim; ++vy) {
                    auto& sg = sign[static_cast<std::size_t>(vx * kLeafDim + vy)];
                    if (sg != 0) continue;
                    const int nb[4][2] = {{vx - 1, vy}, {vx + 1, vy}, {vx, vy - 1}, {vx, vy + 1}};
                    for (const auto& q : nb) {
                        if (q[0] < 0 || q[0] >= kLeafDim || q[1] < 0 || q[1] >= kLeafDim) continue;
                        const int s = sign[static_cast<std::size_t>(q[0] * kLeafDim + q[1])];
                        if (s != 0) {
                            sg = s;
                            changed = true;
                            break;
                        }
                    }
                }
        }
        const auto bg = static_cast<float>(band_);
        for (std::size_t k = 0; k < static_cast<std::size_t>(kPlane); ++k)
            if ((plane.active >> k & 1u) == 0) plane.value[k] = sign[k] < 0 ? -bg : bg;
        return true;
    }

    // Layer d's value in a leaf where it has no band voxel: +-band with its exact sign at the
    // leaf's origin voxel for a closed layer (the sign is the same over the leaf: the curve
    // keeps more than band - h / sqrt 2 > 0 away from every point between its voxel centres);
    // +band for an open layer, whose sign out of the band is not meaningful (and could change
    // far from an edit of an end segment).
    float off_plane_value(const LayerData& d, std::uint64_t key) const {
        return exact_off_value(d, key_i(key) * kLeafDim, key_j(key) * kLeafDim);
    }

    static void write_plane(Leaf& leaf, int z, const Plane& plane) {
        for (int vx = 0; vx < kLeafDim; ++vx)
            for (int vy = 0; vy < kLeafDim; ++vy) {
                const int k = vx * kLeafDim + vy;
                const openvdb::Index n = voxel_offset(vx, vy, z);
                if ((plane.active >> k & 1u) != 0) {
                    leaf.setValueOn(n, plane.value[static_cast<std::size_t>(k)]);
                } else {
                    leaf.setValueOff(n, plane.value[static_cast<std::size_t>(k)]);
                }
            }
    }

    static void write_uniform(Leaf& leaf, int z, float value) {
        for (int vx = 0; vx < kLeafDim; ++vx)
            for (int vy = 0; vy < kLeafDim; ++vy) leaf.setValueOff(voxel_offset(vx, vy, z), value);
    }

    void add_leaf(Tree& tree, Leaf* leaf) {
        tree.addLeaf(leaf);
        ++leaf_count_;
        max_leaf_x_ = std::max(max_leaf_x_, static_cast<long>(leaf->origin().x()) + kLeafDim - 1);
    }

    // Full build: per row, the leaves any of its layers reaches, computed in parallel (one task
    // per leaf), inserted serially.
    void build() {
        auto grid = StackGrid::create(static_cast<float>(band_));
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
        grid->setName("strata_layers");
        grid_ = grid;
        leaf_count_ = 0;
        max_leaf_x_ = std::numeric_limits<long>::min();
        for (std::size_t first = 0; first < layers_.size(); first += kLeafDim) {
            const std::size_t last = row_end(first);
            std::vector<std::pair<std::uint64_t, std::uint32_t>> reach;  // (leaf key, layer)
            for (std::size_t l = first; l < last; ++l) {
                std::vector<std::uint64_t> keys;
                for (const Segment& s : layers_[l].store.segments())
                    if (s.live) for_leaves(s, [&](std::uint64_t k) { keys.push_back(k); });
                std::sort(keys.begin(), keys.end());
                keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
                for (std::uint64_t k : keys) reach.emplace_back(k, static_cast<std::uint32_t>(l));
            }
            std::sort(reach.begin(), reach.end());
            std::vector<std::size_t> starts;  // groups of one leaf key
            for (std::size_t k = 0; k < reach.size(); ++k)
                if (k == 0 || reach[k].first != reach[k - 1].first) starts.push_back(k);
            starts.push_back(reach.size());
            const int row_z = row_origin_z(first);
            std::vector<Leaf*> leaves(starts.size() - 1, nullptr);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size(), 16),
                              [&](const tbb::blocked_range<std::size_t>& r) {
                                  std::vector<std::uint32_t> ids;
                                  Plane plane;
                                  for (std::size_t g = r.begin(); g != r.end(); ++g) {
                                      const std::uint64_t key = reach[starts[g]].first;
                                      Leaf* leaf = nullptr;
                                      std::uint32_t has = 0;  // planes of the row with band voxels
                                      for (std::size_t k = starts[g]; k < starts[g + 1]; ++k) {
                                          const std::uint32_t l = reach[k].second;
                                          if (!band_plane(layers_[l], key, plane, ids)) continue;
                                          if (leaf == nullptr)
                                              leaf = new Leaf(leaf_origin(key, row_z),
                                                              static_cast<float>(band_), false);
                                          write_plane(*leaf, static_cast<int>(l), plane);
                                          has |= 1u << (l - first);
                                      }
                                      if (leaf == nullptr) continue;
                                      for (std::size_t l = first; l < last; ++l)
                                          if ((has >> (l - first) & 1u) == 0)
                                              write_uniform(*leaf, static_cast<int>(l),
                                                            off_plane_value(layers_[l], key));
                                      leaves[g] = leaf;
                                  }
                              });
            for (Leaf* leaf : leaves)
                if (leaf != nullptr) add_leaf(grid_->tree(), leaf);
        }
    }

    // Recomputes layer l's plane in the leaves `keys` (its row), creating the leaves it now
    // reaches and removing those no plane needs any more; then internal nodes left without
    // children become tiles, as in a fresh build.
    void refresh(std::size_t l, std::vector<std::uint64_t> keys) {
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        const LayerData& d = layers_[l];
        const int z = static_cast<int>(l), row_z = row_origin_z(l);
        const std::size_t first = static_cast<std::size_t>(row_z), last = row_end(l);
        std::vector<Change> changes(keys.size());
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, keys.size(), 4),
            [&](const tbb::blocked_range<std::size_t>& r) {
                std::vector<std::uint32_t> ids;
                for (std::size_t k = r.begin(); k != r.end(); ++k) {
                    Change& c = changes[k];
                    const Leaf* leaf = tree().probeConstLeaf(leaf_origin(keys[k], row_z));
                    c.exists = leaf != nullptr;
                    c.band = band_plane(d, keys[k], c.plane, ids);
                    if (c.band && !c.exists) {
                        for (std::size_t o = first; o < last; ++o)
                            c.row_off.push_back(o == l ? static_cast<float>(band_)
                                                       : off_plane_value(layers_[o], keys[k]));
                    } else if (!c.band && c.exists) {
                        c.keep = other_planes_active(*leaf, z);
                        if (c.keep) c.off = off_plane_value(d, keys[k]);
                    }
                }
            });
        Tree& tree = grid_->tree();
        const auto bg = static_cast<float>(band_);
        std::vector<openvdb::Coord> removed;
        for (std::size_t k = 0; k < keys.size(); ++k) {
            const Change& c = changes[k];
            const openvdb::Coord origin = leaf_origin(keys[k], row_z);
            if (c.band) {
                Leaf* leaf = tree.probeLeaf(origin);
                if (leaf == nullptr) {
                    leaf = new Leaf(origin, bg, false);
                    for (std::size_t o = first; o < last; ++o)
                        write_uniform(*leaf, static_cast<int>(o), c.row_off[o - first]);
                    add_leaf(tree, leaf);
                }
                write_plane(*leaf, z, c.plane);
            } else if (c.exists && c.keep) {
                write_uniform(*tree.probeLeaf(origin), z, c.off);
            } else if (c.exists) {
                tree.addTile(1, origin, bg, false);
                --leaf_count_;
                removed.push_back(origin);
            }
        }
        bool root_tiles = false;
        for (const openvdb::Coord& origin : removed) {
            if (const N1* n1 = tree.probeConstNode<N1>(origin);
                n1 != nullptr && n1->getChildMask().isOff())
                tree.addTile(2, origin, bg, false);
            if (const N2* n2 = tree.probeConstNode<N2>(origin);
                n2 != nullptr && n2->getChildMask().isOff()) {
                tree.addTile(3, origin, bg, false);
                root_tiles = true;
            }
        }
        // A fresh build has no root tiles; rare (a 1024-voxel node emptied), O(root children).
        if (root_tiles) tree.root().eraseBackgroundTiles();
    }

    double h_ = 1.0;
    double band_ = 1.0;
    std::vector<LayerData> layers_;
    StackGrid::Ptr grid_;
    std::size_t leaf_count_ = 0;
    long max_leaf_x_ = std::numeric_limits<long>::min();  // >= every leaf's last voxel x
    bool limited_ = false;  // FieldParams::region given: leaves only in the range below
    long leaf_i0_ = 0, leaf_i1_ = -1, leaf_j0_ = 0, leaf_j1_ = -1;
};

namespace {

/// Layer `layer_` of a GridStack (shared with the other layers of its SceneFields).
class GridField final : public LayerField {
  public:
    GridField(std::shared_ptr<GridStack> stack, std::size_t layer)
        : LayerField(stack->name(layer), stack->is_closed(layer), stack->outside_sign(layer)),
          stack_(std::move(stack)),
          layer_(layer) {}

    FieldSample sample(const Vec2& x) const override { return stack_->sample(layer_, x); }
    FieldSample sample_in_band(const Vec2& x) const override {
        return stack_->sample_in_band(layer_, x);
    }
    void update(const std::vector<Vec2>& points, const PolylineEdit& edit) override {
        stack_->update(layer_, points, edit);
        set_outside_sign(stack_->outside_sign(layer_));
    }
    FieldStats stats() const override { return stack_->stats(layer_); }

    const GridStack& stack() const { return *stack_; }
    std::size_t layer() const { return layer_; }

  private:
    std::shared_ptr<GridStack> stack_;
    std::size_t layer_ = 0;
};

std::string coord_text(const openvdb::Coord& c) {
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " +
           std::to_string(c.z()) + ")";
}

const GridField& as_grid(const LayerField& field, const char* where) {
    const auto* g = dynamic_cast<const GridField*>(&field);
    if (g == nullptr)
        throw InvalidInput(std::string(where) + ": layer '" + shown_text(field.name()) +
                           "' does not use the Grid backend");
    return *g;
}

bool same_bits(float a, float b) {
    return std::memcmp(&a, &b, sizeof(float)) == 0;
}

// Internal node a against b: masks and tile values bit for bit; children compared by the caller.
template <typename Node>
bool same_node(const Node& a, const Node& b) {
    if (a.getChildMask() != b.getChildMask() || a.getValueMask() != b.getValueMask()) return false;
    for (auto it = a.cbeginValueAll(); it; ++it)
        if (!same_bits(*it, b.getValue(it.getCoord()))) return false;
    return true;
}

}  // namespace

GridFields make_grid_fields(const std::vector<const Layer*>& layers,
                            const std::vector<int>& outside_signs,
                            const ResolvedFieldParams& params) {
    auto stack = std::make_shared<GridStack>(layers, outside_signs, params);
    GridFields out;
    out.stack = stack;
    for (std::size_t l = 0; l < layers.size(); ++l)
        out.fields.push_back(std::make_unique<GridField>(stack, l));
    return out;
}

std::unique_ptr<LayerField> make_grid_field(const Layer& layer, int outside_sign,
                                            const ResolvedFieldParams& params) {
    return std::move(make_grid_fields({&layer}, {outside_sign}, params).fields.front());
}

void grid_sample_all(const GridStack& stack, const Vec2& x, std::vector<FieldSample>& out) {
    stack.sample_all(x, out);
}

FieldStats grid_total_stats(const GridStack& stack) {
    return stack.total_stats();
}

bool grids_identical(const LayerField& fa, const LayerField& fb, std::string* why) {
    const auto fail = [&](const std::string& msg) {
        if (why != nullptr) *why = msg;
        return false;
    };
    const GridField& ga = as_grid(fa, "grids_identical");
    const GridField& gb = as_grid(fb, "grids_identical");
    if (ga.layer() != gb.layer() || ga.stack().size() != gb.stack().size())
        return fail("layer " + std::to_string(ga.layer()) + " of " +
                    std::to_string(ga.stack().size()) + " vs layer " + std::to_string(gb.layer()) +
                    " of " + std::to_string(gb.stack().size()));
    const Tree& a = ga.stack().tree();
    const Tree& b = gb.stack().tree();
    if (!same_bits(a.background(), b.background())) return fail("backgrounds differ");
    if (a.root().getTableSize() != b.root().getTableSize())
        return fail("root tables of " + std::to_string(a.root().getTableSize()) + " vs " +
                    std::to_string(b.root().getTableSize()) + " entries");
    for (auto it = a.root().cbeginChildOn(); it; ++it) {
        const N2* other = b.root().probeConstNode<N2>(it->origin());
        if (other == nullptr || other->origin() != it->origin() || !same_node(*it, *other))
            return fail("internal node " + coord_text(it->origin()) + " differs");
        for (auto n1 = it->cbeginChildOn(); n1; ++n1)
            if (!same_node(*n1, *other->probeConstNode<N1>(n1->origin())))
                return fail("internal node " + coord_text(n1->origin()) + " differs");
    }
    if (a.leafCount() != b.leafCount())
        return fail("leaf counts " + std::to_string(a.leafCount()) + " vs " +
                    std::to_string(b.leafCount()));
    for (auto it = a.cbeginLeaf(); it; ++it) {
        const Leaf* other = b.probeConstLeaf(it->origin());
        if (other == nullptr) return fail("leaf " + coord_text(it->origin()) + " missing");
        if (it->getValueMask() != other->getValueMask())
            return fail("value masks of leaf " + coord_text(it->origin()) + " differ");
        if (std::memcmp(it->buffer().data(), other->buffer().data(), sizeof(float) * Leaf::SIZE) !=
            0)
            return fail("values of leaf " + coord_text(it->origin()) + " differ");
    }
    // The layer's plane as sample() reads it, leaves and walked voxels.
    openvdb::CoordBBox bb, bb_b;
    a.evalLeafBoundingBox(bb);
    b.evalLeafBoundingBox(bb_b);
    bb.expand(bb_b);
    if (bb.empty()) return true;
    bb.expand(256);
    std::vector<float> va, vb;
    std::vector<char> ona, onb;
    for (int j = bb.min().y(); j <= bb.max().y(); ++j) {
        va.clear();
        vb.clear();
        ona.clear();
        onb.clear();
        ga.stack().plane_row(ga.layer(), bb.min().x(), bb.max().x(), j, va, ona);
        gb.stack().plane_row(gb.layer(), bb.min().x(), bb.max().x(), j, vb, onb);
        for (std::size_t k = 0; k < va.size(); ++k)
            if (!same_bits(va[k], vb[k]) || ona[k] != onb[k])
                return fail("voxel (" + std::to_string(bb.min().x() + static_cast<int>(k)) + ", " +
                            std::to_string(j) + ") of layer " + std::to_string(ga.layer()) + ": " +
                            std::to_string(va[k]) + " vs " + std::to_string(vb[k]));
    }
    return true;
}

double max_box_sampler_difference(const LayerField& field, const std::vector<Vec2>& points) {
    const GridField& g = as_grid(field, "max_box_sampler_difference");
    const openvdb::FloatGrid::Ptr slab = g.stack().slab(g.layer());
    const openvdb::FloatGrid::ConstAccessor acc = slab->getConstAccessor();
    const double h = g.stack().voxel_size();
    double worst = 0.0;
    for (const Vec2& p : points) {
        const openvdb::Vec3R ijk(p.x / h, p.y / h, 0.0);
        const double box = static_cast<double>(openvdb::tools::BoxSampler::sample(acc, ijk));
        worst = std::max(worst, std::abs(box - field.sample(p).value));
    }
    return worst;
}

void voxel_signs(const LayerField& field, int i0, int i1, int j0, int j1, std::vector<int>& signs,
                 std::vector<char>& active) {
    const GridField& g = as_grid(field, "voxel_signs");
    std::vector<float> values;
    active.clear();
    for (int j = j0; j <= j1; ++j) g.stack().plane_row(g.layer(), i0, i1, j, values, active);
    signs.clear();
    for (const float v : values) signs.push_back(v < 0.f ? -1 : (v > 0.f ? 1 : 0));
}

std::size_t shared_leaf_count(const LayerField& a, const LayerField& b) {
    const GridField& ga = as_grid(a, "shared_leaf_count");
    const GridField& gb = as_grid(b, "shared_leaf_count");
    if (&ga.stack() != &gb.stack()) return 0;
    const int za = static_cast<int>(ga.layer()), zb = static_cast<int>(gb.layer());
    std::size_t count = 0;
    for (auto it = ga.stack().tree().cbeginLeaf(); it; ++it)
        if (it->origin().z() == za / kLeafDim * kLeafDim &&
            it->origin().z() == zb / kLeafDim * kLeafDim && plane_active_count(*it, za) > 0 &&
            plane_active_count(*it, zb) > 0)
            ++count;
    return count;
}

}  // namespace strata::detail

namespace strata {

void write_vdb(const Scene& scene, const SceneFields& fields, const std::filesystem::path& path) {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    if (fields.size() != scene.size())
        throw InvalidInput("write_vdb: " + std::to_string(fields.size()) + " fields for " +
                           std::to_string(scene.size()) + " layers");
    openvdb::GridPtrVec grids;
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const auto& g = detail::as_grid(fields.field(i), "write_vdb");
        const Layer& layer = scene.layer(i);
        openvdb::FloatGrid::Ptr slab = g.stack().slab(g.layer());
        slab->setName(layer.name);
        slab->insertMeta("strata_voxel_size", openvdb::DoubleMetadata(fields.params().voxel_size));
        slab->insertMeta("strata_band_width", openvdb::DoubleMetadata(fields.params().band_width));
        slab->insertMeta("strata_units", openvdb::StringMetadata(scene.units()));
        slab->insertMeta("strata_closed", openvdb::BoolMetadata(layer.closed));
        slab->insertMeta("strata_outside_sign",
                         openvdb::Int32Metadata(fields.field(i).outside_sign()));
        slab->insertMeta("strata_thickness", openvdb::DoubleMetadata(layer.thickness));
        slab->insertMeta("strata_weight", openvdb::DoubleMetadata(layer.weight));
        grids.push_back(slab);
    }
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    try {
        openvdb::io::File file(tmp.string());
        file.write(grids);
        file.close();
    } catch (const openvdb::Exception& e) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw IoError("write_vdb: cannot write '" + path.string() + "': " + e.what());
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw IoError("write_vdb: cannot rename to '" + path.string() + "': " + ec.message());
    }
}

}  // namespace strata

// The module's entry point (grid_module.h): grid_loader.cpp in the field module finds it with
// dlsym() and calls the functions above through this table.
extern "C" __attribute__((visibility("default"))) const strata::detail::GridModule*
strata_grid_module_v1() {
    static const strata::detail::GridModule table = [] {
        namespace d = strata::detail;
        d::GridModule m;
        m.version = STRATA_GRID_MODULE_VERSION;
        m.make_grid_fields = &d::make_grid_fields;
        m.make_grid_field = &d::make_grid_field;
        m.grid_sample_all = &d::grid_sample_all;
        m.grid_total_stats = &d::grid_total_stats;
        m.grids_identical = &d::grids_identical;
        m.max_box_sampler_difference = &d::max_box_sampler_difference;
        m.voxel_signs = &d::voxel_signs;
        m.shared_leaf_count = &d::shared_leaf_count;
        m.write_vdb = &strata::write_vdb;
        return m;
    }();
    return &table;
}
