// Grid backend: one OpenVDB FloatGrid per layer, a 2D slab at index z = 0 with the transform
// createLinearTransform(h), band voxels holding the exact signed values, inactive voxels the
// band width with the right sign. The only translation unit of the field module that includes
// OpenVDB (it also writes .vdb files).

#include "field/detail/backends.h"
#include "field/detail/grid_inspect.h"
#include "field/detail/segment_store.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/field/vdb_io.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <system_error>
#include <unordered_map>

namespace strata::detail {

namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
using ConstAccessor = openvdb::tree::ValueAccessor<const Tree, false>;
using N2 = Tree::RootNodeType::ChildNodeType;  // 4096^3 voxels
using N1 = N2::ChildNodeType;                  // 128^3 voxels

constexpr int kLeafDim = 8;                 // voxels per leaf side
constexpr double kMaxIndex = 1073741824.0;  // 2^30: voxel coordinates stay in int32

long floor_div8(long v) {
    return v >= 0 ? v / kLeafDim : -((-v + kLeafDim - 1) / kLeafDim);
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

class GridField final : public LayerField {
  public:
    GridField(const Layer& layer, int outside_sign, const ResolvedFieldParams& params)
        : LayerField(layer.name, layer.closed, outside_sign),
          h_(params.voxel_size),
          band_(params.band_width) {
        check_points(layer.points, layer.closed, "make_field");
        check_extent(layer.points, 0, layer.points.size());
        store_.build(layer.points, layer.closed, outside_sign);
        set_outside_sign(store_.outside_sign());
        rebuild();
    }

    FieldSample sample(const Vec2& x) const override {
        FieldSample out;
        out.border = store_.border(x);
        const double gx = x.x / h_, gy = x.y / h_;
        if (!(std::abs(gx) < kMaxIndex && std::abs(gy) < kMaxIndex)) {
            out.value = static_cast<double>(grid_->tree().background());
            return out;
        }
        const double fx0 = std::floor(gx), fy0 = std::floor(gy);
        const int i0 = static_cast<int>(fx0), j0 = static_cast<int>(fy0);
        const double fx = gx - fx0, fy = gy - fy0;
        ConstAccessor acc(grid_->tree());
        float v00 = 0.f, v10 = 0.f, v01 = 0.f, v11 = 0.f;
        const bool a00 = acc.probeValue(openvdb::Coord(i0, j0, 0), v00);
        const bool a10 = acc.probeValue(openvdb::Coord(i0 + 1, j0, 0), v10);
        const bool a01 = acc.probeValue(openvdb::Coord(i0, j0 + 1, 0), v01);
        const bool a11 = acc.probeValue(openvdb::Coord(i0 + 1, j0 + 1, 0), v11);
        const double d00 = v00, d10 = v10, d01 = v01, d11 = v11;
        out.value = (1.0 - fy) * ((1.0 - fx) * d00 + fx * d10) + fy * ((1.0 - fx) * d01 + fx * d11);
        out.gradient = Vec2(((1.0 - fy) * (d10 - d00) + fy * (d11 - d01)) / h_,
                            ((1.0 - fx) * (d01 - d00) + fx * (d11 - d10)) / h_);
        out.in_band = a00 && a10 && a01 && a11;
        return out;
    }

    void update(const std::vector<Vec2>& points, const PolylineEdit& edit) override {
        if (edit.first + edit.inserted <= points.size())
            check_extent(points, edit.first, edit.first + edit.inserted);
        std::vector<std::uint32_t> removed, added;
        if (!store_.splice(points, edit, removed, added)) {
            set_outside_sign(store_.outside_sign());
            rebuild();
            return;
        }
        if (removed.empty() && added.empty()) return;
        std::vector<std::uint64_t> keys;
        for (std::uint32_t s : removed) {
            for_leaves(store_.segments()[s], [&](std::uint64_t k) {
                keys.push_back(k);
                const auto it = buckets_.find(k);
                if (it == buckets_.end()) return;
                auto& ids = it->second;
                ids.erase(std::remove(ids.begin(), ids.end(), s), ids.end());
                if (ids.empty()) buckets_.erase(it);
            });
        }
        for (std::uint32_t s : added) {
            for_leaves(store_.segments()[s], [&](std::uint64_t k) {
                keys.push_back(k);
                buckets_[k].push_back(s);
            });
        }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        const std::vector<Leaf*> leaves = compute_leaves(keys);
        Tree& tree = grid_->tree();
        const float bg = static_cast<float>(band_);
        for (std::size_t k = 0; k < keys.size(); ++k) {
            const openvdb::Coord origin = leaf_origin(keys[k]);
            if (leaves[k] != nullptr) {
                tree.addLeaf(leaves[k]);
            } else if (tree.probeConstLeaf(origin) != nullptr) {
                tree.addTile(1, origin, bg, false);
            }
        }
        // What finish_tree() does, restricted to the internal nodes above the swapped leaves:
        // nodes left without children become background tiles (as pruneInactive does), then
        // the touched nodes are flood filled bottom-up. The other nodes are unchanged, so the
        // tree equals a full rebuild.
        std::vector<openvdb::Coord> n1_origins, n2_origins;
        for (std::uint64_t key : keys) {
            const openvdb::Coord origin = leaf_origin(key);
            if (N1* n1 = tree.probeNode<N1>(origin)) {
                if (n1->getChildMask().isOff()) {
                    tree.addTile(2, origin, bg, false);
                } else {
                    n1_origins.push_back(n1->origin());
                }
            }
            if (N2* n2 = tree.probeNode<N2>(origin)) {
                if (n2->getChildMask().isOff()) {
                    tree.addTile(3, origin, bg, false);
                } else {
                    n2_origins.push_back(n2->origin());
                }
            }
        }
        const auto unique = [](std::vector<openvdb::Coord>& v) {
            std::sort(v.begin(), v.end());
            v.erase(std::unique(v.begin(), v.end()), v.end());
        };
        unique(n1_origins);
        unique(n2_origins);
        const openvdb::tools::SignedFloodFillOp<Tree> fill(tree, 1);
        for (const openvdb::Coord& o : n1_origins)
            if (N1* n1 = tree.probeNode<N1>(o)) fill(*n1);
        for (const openvdb::Coord& o : n2_origins)
            if (N2* n2 = tree.probeNode<N2>(o)) fill(*n2);
        // The root is not filled again: its step only adds inside tiles between two children of
        // the same z column, and every child of a z = 0 slab lies in the z = 0 row, so it adds
        // nothing (the full rebuild's root step adds nothing either). It would cost a sorted
        // copy of all root children, which grows with the layer (~13 % of an update at 1M).
    }

    FieldStats stats() const override {
        FieldStats st;
        st.segments = store_.segment_count();
        st.memory_bytes = static_cast<std::size_t>(grid_->memUsage()) + store_.memory_bytes();
        for (const auto& [key, ids] : buckets_)
            st.memory_bytes += sizeof(key) + sizeof(ids) + ids.capacity() * sizeof(std::uint32_t);
        st.active_voxels = static_cast<std::size_t>(grid_->activeVoxelCount());
        st.leaves = static_cast<std::size_t>(grid_->tree().leafCount());
        const openvdb::CoordBBox bb = grid_->evalActiveVoxelBoundingBox();
        if (!bb.empty()) {
            st.bounds.extend(Vec2(bb.min().x(), bb.min().y()) * h_);
            st.bounds.extend(Vec2(bb.max().x(), bb.max().y()) * h_);
        }
        st.voxel_size = h_;
        st.band_width = band_;
        return st;
    }

    const openvdb::FloatGrid& grid() const { return *grid_; }
    double voxel_size() const { return h_; }

  private:
    void check_extent(const std::vector<Vec2>& points, std::size_t begin, std::size_t end) const {
        for (std::size_t i = begin; i < end; ++i)
            if (const Vec2& p = points[i]; !(std::abs(p.x / h_) + band_ / h_ < 0.5 * kMaxIndex &&
                                             std::abs(p.y / h_) + band_ / h_ < 0.5 * kMaxIndex))
                throw InvalidInput("make_field: layer '" + name() +
                                   "' spans more than 2^29 "
                                   "voxels of size " +
                                   format_number(h_) + " (raise FieldParams::voxel_size)");
    }

    static openvdb::Coord leaf_origin(std::uint64_t key) {
        return openvdb::Coord(static_cast<int>(key_i(key) * kLeafDim),
                              static_cast<int>(key_j(key) * kLeafDim), 0);
    }

    // Leaves holding a voxel centre (i h, j h) within the band of the segment's bounding box.
    template <typename F>
    void for_leaves(const Segment& s, F&& f) const {
        const Box2 box = s.box().inflated(band_);
        const long i0 = static_cast<long>(std::ceil(box.min.x / h_));
        const long i1 = static_cast<long>(std::floor(box.max.x / h_));
        const long j0 = static_cast<long>(std::ceil(box.min.y / h_));
        const long j1 = static_cast<long>(std::floor(box.max.y / h_));
        if (i0 > i1 || j0 > j1) return;
        for (long li = floor_div8(i0); li <= floor_div8(i1); ++li)
            for (long lj = floor_div8(j0); lj <= floor_div8(j1); ++lj) f(leaf_key(li, lj));
    }

    // One leaf: exact values on its 8 x 8 voxels of z = 0, signs of inactive voxels spread
    // from their 4-neighbours (a sign change between neighbours puts both within h <= band of
    // the curve, so both are active), the 7 slabs above copy the z = 0 signs so that the
    // flood fill of the internal nodes (which reads each leaf's first and last values) sees
    // the z = 0 signs. nullptr when no voxel is in the band.
    Leaf* compute_leaf(std::uint64_t key) const {
        const auto it = buckets_.find(key);
        if (it == buckets_.end()) return nullptr;
        const std::vector<std::uint32_t>& ids = it->second;
        const long oi = key_i(key) * kLeafDim, oj = key_j(key) * kLeafDim;
        std::array<float, 64> value{};
        std::array<int, 64> sign{};
        std::array<bool, 64> active{};
        const double band2 = band_ * band_;
        bool any = false;
        for (int vx = 0; vx < kLeafDim; ++vx)
            for (int vy = 0; vy < kLeafDim; ++vy) {
                const int k = vx * kLeafDim + vy;
                const Vec2 p(static_cast<double>(oi + vx) * h_, static_cast<double>(oj + vy) * h_);
                Nearest best;
                for (std::uint32_t s : ids) store_.offer(p, s, best);
                if (best.found() && best.dist2 <= band2) {
                    const double v = store_.evaluate(p, best).value;
                    value[static_cast<std::size_t>(k)] = static_cast<float>(v);
                    sign[static_cast<std::size_t>(k)] = v < 0.0 ? -1 : 1;
                    active[static_cast<std::size_t>(k)] = true;
                    any = true;
                }
            }
        if (!any) return nullptr;
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
        const float bg = static_cast<float>(band_);
        auto* leaf =
            new Leaf(openvdb::Coord(static_cast<int>(oi), static_cast<int>(oj), 0), bg, false);
        for (int vx = 0; vx < kLeafDim; ++vx)
            for (int vy = 0; vy < kLeafDim; ++vy) {
                const auto k = static_cast<std::size_t>(vx * kLeafDim + vy);
                const float off_value = sign[k] < 0 ? -bg : bg;
                for (int vz = 0; vz < kLeafDim; ++vz) {
                    const openvdb::Index n = Leaf::coordToOffset(openvdb::Coord(vx, vy, vz));
                    if (vz == 0 && active[k]) {
                        leaf->setValueOn(n, value[k]);
                    } else {
                        leaf->setValueOff(n, off_value);
                    }
                }
            }
        return leaf;
    }

    std::vector<Leaf*> compute_leaves(const std::vector<std::uint64_t>& keys) const {
        std::vector<Leaf*> leaves(keys.size(), nullptr);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t k = r.begin(); k != r.end(); ++k)
                                  leaves[k] = compute_leaf(keys[k]);
                          });
        return leaves;
    }

    // Removes internal nodes left without active voxels, then gives every tile of the
    // internal nodes the sign of its neighbours (leaves are already signed: minLevel 1).
    void finish_tree(Tree& tree) const {
        openvdb::tools::pruneInactive(tree, true, 1);
        openvdb::tools::signedFloodFill(tree, true, 1, 1);
    }

    void rebuild() {
        buckets_.clear();
        const auto& segs = store_.segments();
        for (std::uint32_t s = 0; s < segs.size(); ++s)
            if (segs[s].live)
                for_leaves(segs[s], [&](std::uint64_t k) { buckets_[k].push_back(s); });
        std::vector<std::uint64_t> keys;
        keys.reserve(buckets_.size());
        for (const auto& entry : buckets_) keys.push_back(entry.first);
        std::sort(keys.begin(), keys.end());
        const std::vector<Leaf*> leaves = compute_leaves(keys);
        auto grid = openvdb::FloatGrid::create(static_cast<float>(band_));
        grid->setTransform(openvdb::math::Transform::createLinearTransform(h_));
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
        grid->setName(name());
        for (Leaf* leaf : leaves)
            if (leaf != nullptr) grid->tree().addLeaf(leaf);
        finish_tree(grid->tree());
        grid_ = grid;
    }

    double h_ = 1.0;
    double band_ = 1.0;
    SegmentStore store_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets_;
    openvdb::FloatGrid::Ptr grid_;
};

std::string coord_text(const openvdb::Coord& c) {
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " +
           std::to_string(c.z()) + ")";
}

const GridField& as_grid(const LayerField& field, const char* where) {
    const auto* g = dynamic_cast<const GridField*>(&field);
    if (g == nullptr)
        throw InvalidInput(std::string(where) + ": layer '" + field.name() +
                           "' does not use the Grid backend");
    return *g;
}

}  // namespace

std::unique_ptr<LayerField> make_grid_field(const Layer& layer, int outside_sign,
                                            const ResolvedFieldParams& params) {
    return std::make_unique<GridField>(layer, outside_sign, params);
}

bool grids_identical(const LayerField& fa, const LayerField& fb, std::string* why) {
    const auto fail = [&](const std::string& msg) {
        if (why != nullptr) *why = msg;
        return false;
    };
    const Tree& a = as_grid(fa, "grids_identical").grid().tree();
    const Tree& b = as_grid(fb, "grids_identical").grid().tree();
    if (a.leafCount() != b.leafCount())
        return fail("leaf counts " + std::to_string(a.leafCount()) + " vs " +
                    std::to_string(b.leafCount()));
    if (a.background() != b.background()) return fail("backgrounds differ");
    for (auto it = a.cbeginLeaf(); it; ++it) {
        const Leaf* other = b.probeConstLeaf(it->origin());
        if (other == nullptr) return fail("leaf " + coord_text(it->origin()) + " missing");
        if (it->getValueMask() != other->getValueMask())
            return fail("value masks of leaf " + coord_text(it->origin()) + " differ");
        if (std::memcmp(it->buffer().data(), other->buffer().data(), sizeof(float) * Leaf::SIZE) !=
            0)
            return fail("values of leaf " + coord_text(it->origin()) + " differ");
    }
    openvdb::CoordBBox bb, bb_b;
    a.evalLeafBoundingBox(bb);
    b.evalLeafBoundingBox(bb_b);
    bb.expand(bb_b);
    if (bb.empty()) return true;
    bb.expand(256);
    ConstAccessor aa(a), ab(b);
    for (int i = bb.min().x(); i <= bb.max().x(); ++i)
        for (int j = bb.min().y(); j <= bb.max().y(); ++j) {
            const openvdb::Coord c(i, j, 0);
            const float va = aa.getValue(c), vb = ab.getValue(c);
            if (std::memcmp(&va, &vb, sizeof(float)) != 0 || aa.isValueOn(c) != ab.isValueOn(c))
                return fail("voxel " + coord_text(c) + ": " + std::to_string(va) + " vs " +
                            std::to_string(vb));
        }
    return true;
}

double max_box_sampler_difference(const LayerField& field, const std::vector<Vec2>& points) {
    const GridField& g = as_grid(field, "max_box_sampler_difference");
    ConstAccessor acc(g.grid().tree());
    double worst = 0.0;
    for (const Vec2& p : points) {
        const openvdb::Vec3R ijk(p.x / g.voxel_size(), p.y / g.voxel_size(), 0.0);
        const double box = static_cast<double>(openvdb::tools::BoxSampler::sample(acc, ijk));
        worst = std::max(worst, std::abs(box - field.sample(p).value));
    }
    return worst;
}

void voxel_signs(const LayerField& field, int i0, int i1, int j0, int j1, std::vector<int>& signs,
                 std::vector<char>& active) {
    const GridField& g = as_grid(field, "voxel_signs");
    ConstAccessor acc(g.grid().tree());
    signs.clear();
    active.clear();
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            float v = 0.f;
            const bool on = acc.probeValue(openvdb::Coord(i, j, 0), v);
            signs.push_back(v < 0.f ? -1 : (v > 0.f ? 1 : 0));
            active.push_back(on ? 1 : 0);
        }
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
        openvdb::FloatGrid::Ptr copy = g.grid().deepCopy();
        copy->setName(layer.name);
        copy->insertMeta("strata_voxel_size", openvdb::DoubleMetadata(fields.params().voxel_size));
        copy->insertMeta("strata_band_width", openvdb::DoubleMetadata(fields.params().band_width));
        copy->insertMeta("strata_units", openvdb::StringMetadata(scene.units()));
        copy->insertMeta("strata_closed", openvdb::BoolMetadata(layer.closed));
        copy->insertMeta("strata_outside_sign",
                         openvdb::Int32Metadata(fields.field(i).outside_sign()));
        copy->insertMeta("strata_thickness", openvdb::DoubleMetadata(layer.thickness));
        copy->insertMeta("strata_weight", openvdb::DoubleMetadata(layer.weight));
        grids.push_back(copy);
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
