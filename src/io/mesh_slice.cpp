// Mesh slicing and nesting inference. The only strata source that includes OpenMesh.
#include "strata/io/mesh_slice.h"

#include "io/detail/mesh_text.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"

// GCC 12 at -O3 reports a false -Wmaybe-uninitialized inside OpenMesh's property containers
// (std::vector<VectorT>::push_back of a default-constructed value), at instantiations that are
// emitted at the end of this file, so the suppression has to cover the whole file.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// MeshIO.hh must come before the mesh kernel headers (OpenMesh registers its readers there).
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace strata {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

int axis_index(Axis axis) {
    switch (axis) {
        case Axis::X:
            return 0;
        case Axis::Y:
            return 1;
        case Axis::Z:
            return 2;
    }
    return 1;
}

double cross(const Vec2& a, const Vec2& b) {
    return a.x * b.y - a.y * b.x;
}

int sign_of(double v) {
    return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0);
}

// ---------------------------------------------------------------------------------------------
// Reading through OpenMesh.

struct DoubleTraits : public OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
};
using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

std::mutex& openmesh_mutex() {
    static std::mutex mutex;
    return mutex;
}

// While alive, OpenMesh's omlog / omout / omerr write into a string instead of the standard
// streams (they are process-wide, hence the lock). The previous connections are restored.
class OpenMeshCapture {
  public:
    OpenMeshCapture() : lock_(openmesh_mutex()) {
        streams_ = {&omlog(), &omout(), &omerr()};
        targets_ = {&std::clog, &std::cout, &std::cerr};
        for (std::size_t s = 0; s < streams_.size(); ++s) {
            for (std::size_t t = 0; t < targets_.size(); ++t)
                was_connected_[s][t] = streams_[s]->disconnect(*targets_[t]);
            streams_[s]->connect(buffer_);
        }
    }
    ~OpenMeshCapture() {
        for (std::size_t s = 0; s < streams_.size(); ++s) {
            streams_[s]->flush();
            streams_[s]->disconnect(buffer_);
            for (std::size_t t = 0; t < targets_.size(); ++t)
                if (was_connected_[s][t]) streams_[s]->connect(*targets_[t]);
        }
    }
    OpenMeshCapture(const OpenMeshCapture&) = delete;
    OpenMeshCapture& operator=(const OpenMeshCapture&) = delete;

    std::vector<std::string> lines() {
        for (OpenMesh::mostream* s : streams_) s->flush();
        std::vector<std::string> out;
        std::istringstream in(buffer_.str());
        for (std::string line; std::getline(in, line);)
            if (!line.empty()) out.push_back(line);
        return out;
    }

  private:
    std::lock_guard<std::mutex> lock_;
    std::array<OpenMesh::mostream*, 3> streams_{};
    std::array<std::ostream*, 3> targets_{};
    std::array<std::array<bool, 3>, 3> was_connected_{};
    std::ostringstream buffer_;
};

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool contains(const std::string& haystack, const char* needle) {
    return haystack.find(needle) != std::string::npos;
}

// ---------------------------------------------------------------------------------------------
// Nesting geometry: per-layer segment grid, nearest queries, point in polygon.

struct Nearest {
    double distance = std::numeric_limits<double>::infinity();
    std::size_t segment = 0;
    double t = 0.0;  // position of the closest point on the segment, [0, 1]
};

class LayerIndex {
  public:
    LayerIndex(const Layer& layer, double cell_hint) : layer_(&layer) {
        const std::size_t n = layer.segment_count();
        box_ = layer.bounds();
        double mean = n > 0 ? layer.length() / static_cast<double>(n) : 0.0;
        cell_ =
            std::max({cell_hint, mean, 1e-12 * (1.0 + std::hypot(box_.size().x, box_.size().y))});
        auto dims = [&]() {
            nx_ = static_cast<std::size_t>(box_.size().x / cell_) + 1;
            ny_ = static_cast<std::size_t>(box_.size().y / cell_) + 1;
        };
        dims();
        while (nx_ * ny_ > 4 * n + 64) {
            cell_ *= 2.0;
            dims();
        }
        std::vector<std::size_t> count(nx_ * ny_ + 1, 0);
        auto for_cells = [&](std::size_t s, auto&& f) {
            const Vec2 a = layer.segment_start(s), b = layer.segment_end(s);
            const auto [x0, y0] = cell_of(glm::min(a, b));
            const auto [x1, y1] = cell_of(glm::max(a, b));
            for (std::size_t y = y0; y <= y1; ++y)
                for (std::size_t x = x0; x <= x1; ++x) f(y * nx_ + x);
        };
        for (std::size_t s = 0; s < n; ++s) for_cells(s, [&](std::size_t c) { ++count[c + 1]; });
        std::partial_sum(count.begin(), count.end(), count.begin());
        offsets_ = count;
        items_.resize(offsets_.back());
        for (std::size_t s = 0; s < n; ++s)
            for_cells(s, [&](std::size_t c) { items_[count[c]++] = s; });
        // Horizontal strips for point-in-polygon ray casts.
        strips_ = std::max<std::size_t>(1, std::min<std::size_t>(n / 4 + 1, 4096));
        std::vector<std::size_t> scount(strips_ + 1, 0);
        auto for_strips = [&](std::size_t s, auto&& f) {
            const Vec2 a = layer.segment_start(s), b = layer.segment_end(s);
            const std::size_t lo = strip_of(std::min(a.y, b.y)), hi = strip_of(std::max(a.y, b.y));
            for (std::size_t k = lo; k <= hi; ++k) f(k);
        };
        for (std::size_t s = 0; s < n; ++s) for_strips(s, [&](std::size_t k) { ++scount[k + 1]; });
        std::partial_sum(scount.begin(), scount.end(), scount.begin());
        strip_offsets_ = scount;
        strip_items_.resize(strip_offsets_.back());
        for (std::size_t s = 0; s < n; ++s)
            for_strips(s, [&](std::size_t k) { strip_items_[scount[k]++] = s; });
    }

    const Layer& layer() const { return *layer_; }
    const Box2& box() const { return box_; }

    /// Closest point of the layer to p, if within `radius`.
    std::optional<Nearest> nearest(const Vec2& p, double radius) const {
        if (!box_.inflated(radius).contains(p)) return std::nullopt;
        const auto [x0, y0] = cell_of(p - Vec2(radius));
        const auto [x1, y1] = cell_of(p + Vec2(radius));
        Nearest best;
        for (std::size_t y = y0; y <= y1; ++y)
            for (std::size_t x = x0; x <= x1; ++x) {
                const std::size_t c = y * nx_ + x;
                for (std::size_t k = offsets_[c]; k < offsets_[c + 1]; ++k) {
                    const std::size_t s = items_[k];
                    const Vec2 a = layer_->segment_start(s), d = layer_->segment_end(s) - a;
                    const double len2 = glm::dot(d, d);
                    const double t =
                        len2 > 0.0 ? std::clamp(glm::dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
                    const double dist = glm::length(p - (a + t * d));
                    if (dist < best.distance) best = {dist, s, t};
                }
            }
        if (best.distance > radius) return std::nullopt;
        return best;
    }

    /// True when the closest point is an end point of an open layer.
    bool at_open_end(const Nearest& n) const {
        if (layer_->closed) return false;
        return (n.segment == 0 && n.t <= 0.0) ||
               (n.segment + 1 == layer_->segment_count() && n.t >= 1.0);
    }

    /// +1 when p is on the left of the layer's direction of travel at its closest point,
    /// -1 on the right, 0 on it. At a vertex, the mean of the two unit tangents decides.
    int side(const Vec2& p, const Nearest& n) const {
        const std::size_t segs = layer_->segment_count();
        auto tangent = [&](std::size_t s) {
            const Vec2 d = layer_->segment_end(s) - layer_->segment_start(s);
            const double l = glm::length(d);
            return l > 0.0 ? d / l : Vec2(0.0);
        };
        Vec2 tan = tangent(n.segment);
        Vec2 at = layer_->segment_start(n.segment) +
                  n.t * (layer_->segment_end(n.segment) - layer_->segment_start(n.segment));
        if (n.t <= 0.0 && (layer_->closed || n.segment > 0)) {
            tan += tangent((n.segment + segs - 1) % segs);
            at = layer_->segment_start(n.segment);
        } else if (n.t >= 1.0 && (layer_->closed || n.segment + 1 < segs)) {
            tan += tangent((n.segment + 1) % segs);
            at = layer_->segment_end(n.segment);
        }
        return sign_of(cross(tan, p - at));
    }

    /// Crossing-number test against the closed polygon of the layer's points.
    bool inside(const Vec2& p) const {
        if (!box_.contains(p)) return false;
        const std::size_t k = strip_of(p.y);
        bool in = false;
        for (std::size_t i = strip_offsets_[k]; i < strip_offsets_[k + 1]; ++i) {
            const std::size_t s = strip_items_[i];
            const Vec2 a = layer_->segment_start(s), b = layer_->segment_end(s);
            if ((a.y > p.y) != (b.y > p.y)) {
                const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if (x > p.x) in = !in;
            }
        }
        return in;
    }

  private:
    std::pair<std::size_t, std::size_t> cell_of(const Vec2& p) const {
        auto clampi = [](double v, std::size_t n) {
            if (!(v > 0.0)) return std::size_t{0};
            const auto i = static_cast<std::size_t>(v);
            return std::min(i, n - 1);
        };
        return {clampi((p.x - box_.min.x) / cell_, nx_), clampi((p.y - box_.min.y) / cell_, ny_)};
    }
    std::size_t strip_of(double y) const {
        const double h = box_.size().y;
        if (!(h > 0.0)) return 0;
        const double v = (y - box_.min.y) / h * static_cast<double>(strips_);
        if (!(v > 0.0)) return 0;
        return std::min(static_cast<std::size_t>(v), strips_ - 1);
    }

    const Layer* layer_;
    Box2 box_;
    double cell_ = 1.0;
    std::size_t nx_ = 1, ny_ = 1, strips_ = 1;
    std::vector<std::size_t> offsets_, items_, strip_offsets_, strip_items_;
};

// Per-vertex length weights: half of each adjacent segment.
std::vector<double> vertex_weights(const Layer& layer) {
    const std::size_t n = layer.points.size();
    std::vector<double> w(n, 0.0);
    for (std::size_t s = 0; s < layer.segment_count(); ++s) {
        const double l = glm::length(layer.segment_end(s) - layer.segment_start(s)) / 2.0;
        w[s] += l;
        w[(s + 1) % n] += l;
    }
    const double total = std::accumulate(w.begin(), w.end(), 0.0);
    if (!(total > 0.0)) std::fill(w.begin(), w.end(), 1.0);
    return w;
}

// Signed area of the polygon of the points (open layers: closed by the chord).
double signed_area(const std::vector<Vec2>& p) {
    double a = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) a += cross(p[i], p[(i + 1) % p.size()]);
    return a / 2.0;
}

// How the vertices of layer a sit with respect to layer b.
struct OneWay {
    double near = 0.0;  // share of a's length within D of b
    double near_length = 0.0;
    double side = 0.0;  // sum of weight * side over a's near vertices (closest not at b's end)
    double side_weight = 0.0;  // sum of weight over the vertices that voted (side != 0)
    double inside = 0.0;       // share of a's length inside b (b closed)
};

OneWay measure(const Layer& a, const std::vector<double>& wa, const LayerIndex& b, double d) {
    OneWay r;
    double total = 0.0;
    for (std::size_t i = 0; i < a.points.size(); ++i) {
        const Vec2& p = a.points[i];
        total += wa[i];
        if (b.layer().closed && b.inside(p)) r.inside += wa[i];
        if (auto n = b.nearest(p, d)) {
            r.near_length += wa[i];
            if (!b.at_open_end(*n)) {
                const int s = b.side(p, *n);
                r.side += wa[i] * s;
                if (s != 0) r.side_weight += wa[i];
            }
        }
    }
    r.near = r.near_length / total;
    r.inside /= total;
    return r;
}

struct Candidate {
    std::size_t under = 0, over = 0;
    double strength = 0.0;
};

bool reaches(const std::vector<std::vector<std::size_t>>& out, std::size_t from, std::size_t to,
             std::size_t skip_from = kNone, std::size_t skip_to = kNone) {
    std::vector<char> seen(out.size(), 0);
    std::vector<std::size_t> stack{from};
    seen[from] = 1;
    while (!stack.empty()) {
        const std::size_t u = stack.back();
        stack.pop_back();
        for (std::size_t v : out[u]) {
            if (u == skip_from && v == skip_to) continue;
            if (v == to) return true;
            if (!seen[v]) {
                seen[v] = 1;
                stack.push_back(v);
            }
        }
    }
    return false;
}

}  // namespace

// -------------------------------------------------------------------------------------------------
// Axes.

const char* axis_name(Axis axis) {
    switch (axis) {
        case Axis::X:
            return "x";
        case Axis::Y:
            return "y";
        case Axis::Z:
            return "z";
    }
    return "?";
}

Axis parse_axis(std::string_view text) {
    const std::string t = lower(std::string(text));
    if (t == "x") return Axis::X;
    if (t == "y") return Axis::Y;
    if (t == "z") return Axis::Z;
    throw InvalidInput("slice: axis must be x, y or z (got '" + std::string(text) + "')");
}

Vec2 plane_coordinates(const glm::dvec3& p, Axis axis) {
    switch (axis) {
        case Axis::X:
            return {p.y, p.z};
        case Axis::Y:
            return {p.x, p.z};
        case Axis::Z:
            return {p.x, p.y};
    }
    return {p.x, p.z};
}

std::array<const char*, 2> plane_coordinate_names(Axis axis) {
    switch (axis) {
        case Axis::X:
            return {"y", "z"};
        case Axis::Y:
            return {"x", "z"};
        case Axis::Z:
            return {"x", "y"};
    }
    return {"x", "z"};
}

// -------------------------------------------------------------------------------------------------
// Meshes.

std::array<glm::dvec3, 2> SliceMesh::bounds() const {
    if (vertices.empty()) return {glm::dvec3(0.0), glm::dvec3(0.0)};
    glm::dvec3 lo = vertices.front(), hi = vertices.front();
    for (const glm::dvec3& v : vertices) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
    }
    return {lo, hi};
}

SliceMesh make_slice_mesh(std::string name, std::vector<glm::dvec3> vertices,
                          const std::vector<std::vector<std::uint32_t>>& polygons) {
    SliceMesh mesh;
    mesh.name = std::move(name);
    const std::size_t n = vertices.size();
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(vertices[i][c]))
                throw InvalidInput("mesh '" + shown_text(mesh.name) + "': vertex " +
                                   std::to_string(i) + " has a non-finite coordinate (" +
                                   format_number(vertices[i][c]) + ")");
    mesh.vertices = std::move(vertices);
    for (std::size_t f = 0; f < polygons.size(); ++f) {
        const auto& poly = polygons[f];
        for (std::uint32_t v : poly)
            if (v >= n)
                throw InvalidInput("mesh '" + shown_text(mesh.name) + "': face " +
                                   std::to_string(f) + " uses vertex " + std::to_string(v) +
                                   " of " + std::to_string(n));
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
            const std::array<std::uint32_t, 3> t{poly[0], poly[k], poly[k + 1]};
            if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
                ++mesh.read_report.degenerate_triangles;
                continue;
            }
            mesh.triangles.push_back(t);
        }
    }
    // Connected components (union-find on vertices), numbered by decreasing size.
    std::vector<std::uint32_t> parent(mesh.vertices.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const auto& t : mesh.triangles)
        for (int k = 1; k < 3; ++k) {
            const std::uint32_t a = find(t[0]), b = find(t[static_cast<std::size_t>(k)]);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    struct Stats {
        std::size_t vertices = 0, triangles = 0, first = 0;
    };
    std::map<std::uint32_t, Stats> roots;
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
        auto [it, fresh] = roots.try_emplace(find(mesh.triangles[f][0]), Stats{0, 0, f});
        ++it->second.triangles;
    }
    std::vector<char> used(mesh.vertices.size(), 0);
    for (const auto& t : mesh.triangles)
        for (std::uint32_t v : t)
            if (!used[v]) {
                used[v] = 1;
                ++roots[find(v)].vertices;
            }
    std::vector<std::pair<std::uint32_t, Stats>> ranked(roots.begin(), roots.end());
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
        return std::make_tuple(b.second.vertices, b.second.triangles, a.second.first) <
               std::make_tuple(a.second.vertices, a.second.triangles, b.second.first);
    });
    std::map<std::uint32_t, std::uint32_t> label;
    for (std::size_t k = 0; k < ranked.size(); ++k)
        label[ranked[k].first] = static_cast<std::uint32_t>(k);
    mesh.component.resize(mesh.triangles.size());
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
        mesh.component[f] = label[find(mesh.triangles[f][0])];
    mesh.component_count = ranked.size();
    return mesh;
}

SliceMesh read_slice_mesh(const std::filesystem::path& path, const std::string& name) {
    const std::string ext = lower(path.extension().string());
    if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl")
        throw InvalidInput(path.string() + ": unsupported mesh format '" +
                           path.extension().string() + "' (expected .obj, .off, .ply or .stl)");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw IoError(path.string() + ": cannot open mesh (no such file)");

    if (ext == ".off") {
        detail::OffMesh off = detail::read_off_text(path);
        const std::size_t faces = off.polygons.size(), count = off.vertices.size();
        SliceMesh mesh = make_slice_mesh(name.empty() ? path.stem().string() : name,
                                         std::move(off.vertices), off.polygons);
        if (mesh.triangles.empty()) throw InvalidInput(path.string() + ": the mesh has no faces");
        mesh.read_report.file_vertices = count;
        mesh.read_report.file_faces = faces;
        mesh.read_report.double_precision = true;
        return mesh;
    }
    detail::validate_mesh_text(path, ext);
    OmMesh om;
    om.request_face_status();
    om.request_edge_status();
    om.request_vertex_status();
    std::vector<std::string> messages;
    bool ok = false;
    {
        OpenMeshCapture capture;
        OpenMesh::IO::Options options;
        ok = OpenMesh::IO::read_mesh(om, path.string(), options);
        messages = capture.lines();
    }
    if (!ok) {
        std::string why =
            messages.empty() ? "OpenMesh could not read it" : "OpenMesh: " + messages.back();
        throw IoError(path.string() + ": cannot read mesh (" + why + ")");
    }
    // OpenMesh re-adds a face it cannot connect with fresh copies of its vertices (flagged
    // fixed_nonmanifold); map each copy back to the first original at the same position.
    std::vector<glm::dvec3> vertices;
    vertices.reserve(om.n_vertices());
    std::vector<std::uint32_t> alias(om.n_vertices());
    std::map<std::tuple<double, double, double>, std::uint32_t> originals;
    std::size_t reconnected = 0, leading = 0;
    bool in_lead = true;
    for (const auto vh : om.vertices()) {
        const auto& p = om.point(vh);
        const auto i = static_cast<std::uint32_t>(vh.idx());
        vertices.emplace_back(p[0], p[1], p[2]);
        alias[i] = i;
        const auto key = std::make_tuple(p[0], p[1], p[2]);
        if (om.status(vh).fixed_nonmanifold()) {
            in_lead = false;
            auto it = originals.find(key);
            if (it != originals.end()) {
                alias[i] = it->second;
                ++reconnected;
            }
        } else {
            originals.emplace(key, i);
            if (in_lead) ++leading;
        }
    }
    // Double precision: re-read the coordinates of the file's own vertices from the text.
    bool refined = false;
    if (auto exact = detail::read_ascii_vertices(path, ext); exact && exact->size() == leading) {
        std::copy(exact->begin(), exact->end(), vertices.begin());
        for (std::size_t i = leading; i < vertices.size(); ++i) vertices[i] = vertices[alias[i]];
        refined = true;
    }
    std::vector<std::vector<std::uint32_t>> polygons;
    polygons.reserve(om.n_faces());
    std::size_t complex = 0;
    for (const auto fh : om.faces()) {
        if (om.status(fh).fixed_nonmanifold()) ++complex;
        std::vector<std::uint32_t> poly;
        for (const auto vh : om.fv_range(fh))
            poly.push_back(alias[static_cast<std::size_t>(vh.idx())]);
        polygons.push_back(std::move(poly));
    }
    SliceMesh mesh =
        make_slice_mesh(name.empty() ? path.stem().string() : name, std::move(vertices), polygons);
    if (mesh.triangles.empty()) throw InvalidInput(path.string() + ": the mesh has no faces");
    MeshReadReport& r = mesh.read_report;
    r.file_vertices = om.n_vertices();
    r.file_faces = om.n_faces();
    r.complex_faces = complex;
    r.reconnected_vertices = reconnected;
    r.double_precision = refined;
    for (const std::string& m : messages)
        if (contains(m, "equal vertices") || contains(m, "invalid vertex index")) ++r.dropped_faces;
    r.messages = std::move(messages);
    return mesh;
}

// -------------------------------------------------------------------------------------------------
// Plane sections.

MeshSection section_mesh(const SliceMesh& mesh, Axis axis, double height) {
    if (!std::isfinite(height))
        throw InvalidInput("section_mesh: height must be finite (got " + format_number(height) +
                           ")");
    const int ax = axis_index(axis);
    MeshSection out;
    // A vertex on the plane counts as above it (symbolic perturbation).
    auto above = [&](std::uint32_t v) { return mesh.vertices[v][ax] >= height; };

    std::unordered_map<std::uint64_t, std::uint32_t> node_of_edge;
    std::vector<Vec2> node_point;
    auto node = [&](std::uint32_t a, std::uint32_t b) {
        const std::uint64_t k = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
        auto [it, fresh] =
            node_of_edge.try_emplace(k, static_cast<std::uint32_t>(node_point.size()));
        if (fresh) {
            const std::uint32_t lo = above(a) ? b : a, hi = above(a) ? a : b;
            const glm::dvec3 &pl = mesh.vertices[lo], &ph = mesh.vertices[hi];
            const double sl = pl[ax] - height, sh = ph[ax] - height;
            glm::dvec3 p = ph;
            if (sh != 0.0) {
                p = pl + (ph - pl) * (sl / (sl - sh));
                p[ax] = height;
            }
            node_point.push_back(plane_coordinates(p, axis));
        }
        return it->second;
    };
    std::vector<std::array<std::uint32_t, 2>> seg;
    std::vector<std::uint32_t> seg_triangle;
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
        const auto& t = mesh.triangles[f];
        const bool u0 = above(t[0]), u1 = above(t[1]), u2 = above(t[2]);
        if (u0 == u1 && u1 == u2) continue;
        // The vertex alone on its side is `solo`; its two edges cross the plane.
        const std::size_t solo = (u0 == u1) ? 2 : (u0 == u2 ? 1 : 0);
        const std::uint32_t s = t[solo], p = t[(solo + 1) % 3], q = t[(solo + 2) % 3];
        seg.push_back({node(s, p), node(s, q)});
        seg_triangle.push_back(static_cast<std::uint32_t>(f));
        ++out.crossed_triangles;
    }
    if (seg.empty()) return out;

    // Incidence (CSR) of segment ends at nodes; end e of segment s is s * 2 + e.
    const std::size_t nodes = node_point.size();
    std::vector<std::size_t> off(nodes + 1, 0);
    for (const auto& s : seg) {
        ++off[s[0] + 1];
        ++off[s[1] + 1];
    }
    std::partial_sum(off.begin(), off.end(), off.begin());
    std::vector<std::size_t> ends(off.back());
    {
        std::vector<std::size_t> fill(off.begin(), off.end() - 1);
        for (std::size_t s = 0; s < seg.size(); ++s)
            for (std::size_t e = 0; e < 2; ++e) ends[fill[seg[s][e]]++] = s * 2 + e;
    }
    constexpr std::size_t kUnpaired = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> partner(seg.size() * 2, kUnpaired);
    for (std::size_t v = 0; v < nodes; ++v) {
        const std::size_t k = off[v + 1] - off[v];
        const std::size_t* e = ends.data() + off[v];
        if (k == 2) {
            partner[e[0]] = e[1];
            partner[e[1]] = e[0];
        } else if (k > 2) {
            // Non-manifold edge: pair the straightest continuations first.
            ++out.branch_points;
            std::vector<Vec2> dir(k);
            for (std::size_t i = 0; i < k; ++i) {
                const std::size_t s = e[i] / 2, other = 1 - e[i] % 2;
                const Vec2 d = node_point[seg[s][other]] - node_point[v];
                const double l = glm::length(d);
                dir[i] = l > 0.0 ? d / l : Vec2(0.0);
            }
            std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
            for (std::size_t i = 0; i < k; ++i)
                for (std::size_t j = i + 1; j < k; ++j)
                    pairs.emplace_back(glm::dot(dir[i], dir[j]), i, j);
            std::sort(pairs.begin(), pairs.end());
            std::vector<char> used(k, 0);
            for (const auto& [score, i, j] : pairs) {
                if (used[i] || used[j]) continue;
                used[i] = used[j] = 1;
                partner[e[i]] = e[j];
                partner[e[j]] = e[i];
            }
        }
    }

    std::vector<char> visited(seg.size(), 0);
    auto walk = [&](std::size_t start_end) {
        SectionPiece piece;
        piece.component = mesh.component[seg_triangle[start_end / 2]];
        std::vector<Vec2> raw{node_point[seg[start_end / 2][start_end % 2]]};
        std::size_t at = start_end;
        for (;;) {
            const std::size_t s = at / 2, other = s * 2 + (1 - at % 2);
            visited[s] = 1;
            const std::size_t next = partner[other];
            if (next == kUnpaired) {
                raw.push_back(node_point[seg[s][1 - at % 2]]);
                break;
            }
            if (next == start_end) {
                piece.closed = true;
                break;
            }
            raw.push_back(node_point[seg[s][1 - at % 2]]);
            at = next;
        }
        // Merge coincident consecutive points and exact fold-backs (a, b, a).
        std::vector<Vec2>& p = piece.points;
        for (const Vec2& q : raw) {
            if (!p.empty() && p.back() == q) {
                ++out.merged_points;
            } else if (p.size() >= 2 && p[p.size() - 2] == q) {
                p.pop_back();
                out.merged_points += 2;
            } else {
                p.push_back(q);
            }
        }
        if (piece.closed) {
            for (bool changed = true; changed && p.size() >= 2;) {
                changed = false;
                if (p.back() == p.front()) {
                    p.pop_back();
                    ++out.merged_points;
                    changed = true;
                } else if (p.size() >= 3 && p[p.size() - 2] == p.front()) {
                    p.pop_back();
                    p.pop_back();
                    out.merged_points += 2;
                    changed = true;
                } else if (p.size() >= 3 && p.back() == p[1]) {
                    p.erase(p.begin());
                    p.pop_back();
                    out.merged_points += 2;
                    changed = true;
                }
            }
        }
        if (p.size() < (piece.closed ? 3u : 2u))
            ++out.dropped_pieces;
        else
            out.pieces.push_back(std::move(piece));
    };
    for (std::size_t s = 0; s < seg.size(); ++s)
        for (std::size_t e = 0; e < 2; ++e)
            if (!visited[s] && partner[s * 2 + e] == kUnpaired) walk(s * 2 + e);
    for (std::size_t s = 0; s < seg.size(); ++s)
        if (!visited[s]) walk(s * 2);
    return out;
}

// -------------------------------------------------------------------------------------------------
// Welding the open pieces of one mesh at its seams.

void validate(const WeldParams& params) {
    if (!(std::isfinite(params.tolerance) && params.tolerance >= 0.0))
        throw InvalidInput("weld: params.tolerance must be finite and >= 0 (got " +
                           format_number(params.tolerance) + ")");
    if (params.overlap_segments < 0)
        throw InvalidInput("weld: params.overlap_segments must be >= 0 (got " +
                           std::to_string(params.overlap_segments) + ")");
}

double median_edge_length(const SliceMesh& mesh) {
    std::vector<double> lengths;
    lengths.reserve(mesh.triangles.size() * 3);
    for (const auto& t : mesh.triangles)
        for (std::size_t k = 0; k < 3; ++k)
            lengths.push_back(glm::distance(mesh.vertices[t[k]], mesh.vertices[t[(k + 1) % 3]]));
    if (lengths.empty()) return 0.0;
    auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
    std::nth_element(lengths.begin(), mid, lengths.end());
    return *mid;
}

namespace {

// End `side` (0 front, 1 back) of an open piece; segment k counted from that end.
struct WeldEnd {
    std::size_t piece = 0;
    int side = 0;
};

std::pair<Vec2, Vec2> end_segment(const std::vector<Vec2>& p, int side, std::size_t k) {
    if (side == 0) return {p[k], p[k + 1]};
    return {p[p.size() - 1 - k], p[p.size() - 2 - k]};
}

struct WeldCandidate {
    int kind = 0;  // 0: the ends meet, 1: they overlap (cut at the crossing)
    double cost = 0.0;
    WeldEnd a, b;
    std::size_t ka = 0, kb = 0;  // overlap: crossing segments, counted from each end
    Vec2 at{};                   // overlap: the crossing point
};

}  // namespace

WeldReport weld_section(MeshSection& section, double mesh_edge, const WeldParams& params) {
    validate(params);
    WeldReport report;
    report.tolerance = params.tolerance > 0.0 ? params.tolerance : kAutoWeldFraction * mesh_edge;
    if (!params.enabled) return report;
    std::vector<std::size_t> open;
    for (std::size_t i = 0; i < section.pieces.size(); ++i)
        if (!section.pieces[i].closed) open.push_back(i);
    if (open.empty()) return report;
    const double tol = report.tolerance;
    const auto window = static_cast<std::size_t>(params.overlap_segments);
    auto pts = [&](const WeldEnd& e) -> const std::vector<Vec2>& {
        return section.pieces[open[e.piece]].points;
    };
    auto point = [&](const WeldEnd& e) { return e.side == 0 ? pts(e).front() : pts(e).back(); };

    std::vector<WeldEnd> ends;
    for (std::size_t i = 0; i < open.size(); ++i)
        for (int side = 0; side < 2; ++side) ends.push_back({i, side});
    std::vector<WeldCandidate> candidates;
    for (std::size_t i = 0; i < ends.size(); ++i)
        for (std::size_t j = i + 1; j < ends.size(); ++j) {
            const WeldEnd &a = ends[i], &b = ends[j];
            const bool same = a.piece == b.piece;
            const std::size_t segs = pts(a).size() - 1;
            if (same && segs < 2) continue;  // a loop needs 3 points
            const double d = glm::distance(point(a), point(b));
            if (d <= tol) {
                candidates.push_back({0, d, a, b, 0, 0, {}});
                continue;
            }
            // Overlap: look for a proper crossing among the end windows, nearest the ends.
            const std::size_t wa = std::min(window, pts(a).size() - 1),
                              wb = std::min(window, pts(b).size() - 1);
            if (same && segs < wa + wb + 1) continue;  // the windows must not share a segment
            bool found = false;
            for (std::size_t sum = 0; sum + 1 < wa + wb && !found; ++sum)
                for (std::size_t ka = 0; ka <= sum && !found; ++ka) {
                    const std::size_t kb = sum - ka;
                    if (ka >= wa || kb >= wb) continue;
                    const auto [p0, p1] = end_segment(pts(a), a.side, ka);
                    const auto [q0, q1] = end_segment(pts(b), b.side, kb);
                    if (segment_contact(p0, p1, q0, q1) != SegmentContact::Proper) continue;
                    candidates.push_back({1, static_cast<double>(sum), a, b, ka, kb,
                                          crossing_point(p0, p1, q0, q1)});
                    found = true;
                }
        }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const WeldCandidate& x, const WeldCandidate& y) {
                         return std::tie(x.kind, x.cost) < std::tie(y.kind, y.cost);
                     });
    // partner[piece * 2 + side] = the end it is joined to.
    constexpr std::size_t kFree = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> partner(open.size() * 2, kFree);
    std::vector<char> is_overlap(open.size() * 2, 0);
    struct Cut {
        std::size_t k;
        Vec2 at;
    };
    std::vector<std::optional<Cut>> cut(open.size() * 2);
    for (const WeldCandidate& c : candidates) {
        const std::size_t ea = c.a.piece * 2 + static_cast<std::size_t>(c.a.side),
                          eb = c.b.piece * 2 + static_cast<std::size_t>(c.b.side);
        if (partner[ea] != kFree || partner[eb] != kFree) continue;
        if (c.kind == 1) {
            // Both ends of one piece cut: the cuts must leave a segment between them.
            const std::size_t oa = c.a.piece * 2 + 1 - static_cast<std::size_t>(c.a.side),
                              ob = c.b.piece * 2 + 1 - static_cast<std::size_t>(c.b.side);
            const std::size_t na = pts(c.a).size() - 1, nb = pts(c.b).size() - 1;
            if (cut[oa] && cut[oa]->k + c.ka + 2 > na) continue;
            if (cut[ob] && cut[ob]->k + c.kb + 2 > nb) continue;
            cut[ea] = Cut{c.ka, c.at};
            cut[eb] = Cut{c.kb, c.at};
            is_overlap[ea] = is_overlap[eb] = 1;
            ++report.overlaps;
        }
        partner[ea] = eb;
        partner[eb] = ea;
        ++report.joins;
    }
    if (report.joins == 0) return report;

    // Cut the overlapping ends at their crossing (back first: the front cut shifts indices).
    for (std::size_t i = 0; i < open.size(); ++i) {
        std::vector<Vec2>& p = section.pieces[open[i]].points;
        if (const auto& back = cut[i * 2 + 1]) {
            p.resize(p.size() - 1 - back->k);
            p.push_back(back->at);
        }
        if (const auto& front = cut[i * 2]) {
            p.erase(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(front->k + 1));
            p.insert(p.begin(), front->at);
        }
    }

    // Chain: from every free end first (open chains), then around the remaining cycles.
    std::vector<char> used(open.size(), 0);
    std::vector<SectionPiece> chained;
    auto append = [](std::vector<Vec2>& out, const std::vector<Vec2>& p, bool reversed) {
        std::vector<Vec2> q = p;
        if (reversed) std::reverse(q.begin(), q.end());
        if (!out.empty()) {
            // The junction: both ends become their midpoint.
            out.back() = 0.5 * (out.back() + q.front());
            out.insert(out.end(), q.begin() + 1, q.end());
        } else {
            out = std::move(q);
        }
    };
    auto walk = [&](std::size_t start_piece, int start_side) {
        SectionPiece piece;
        piece.component = section.pieces[open[start_piece]].component;
        std::set<std::uint32_t> components;
        std::size_t at = start_piece * 2 + static_cast<std::size_t>(start_side), count = 0,
                    overlaps = 0;
        for (;;) {
            const std::size_t i = at / 2;
            used[i] = 1;
            ++count;
            components.insert(section.pieces[open[i]].component);
            append(piece.points, section.pieces[open[i]].points, at % 2 == 1);
            const std::size_t exit = i * 2 + 1 - at % 2;
            const std::size_t next = partner[exit];
            if (next == kFree) break;
            if (is_overlap[exit]) ++overlaps;
            if (next / 2 == start_piece && next % 2 == static_cast<std::size_t>(start_side)) {
                piece.closed = true;
                piece.points.front() = 0.5 * (piece.points.front() + piece.points.back());
                piece.points.pop_back();
                break;
            }
            at = next;
        }
        std::vector<Vec2>& p = piece.points;
        p.erase(std::unique(p.begin(), p.end()), p.end());
        while (piece.closed && p.size() >= 2 && p.back() == p.front()) p.pop_back();
        if (piece.closed && p.size() < 3) piece.closed = false;
        if (count > 1 || piece.closed) {
            piece.welded_components.assign(components.begin(), components.end());
            piece.welded_pieces = count;
            piece.welded_overlaps = overlaps;
            if (piece.closed) ++report.closed;
        }
        if (p.size() >= 2)
            chained.push_back(std::move(piece));
        else
            ++section.dropped_pieces;
    };
    for (std::size_t i = 0; i < open.size(); ++i)
        for (int side = 0; side < 2; ++side)
            if (!used[i] && partner[i * 2 + static_cast<std::size_t>(side)] == kFree) walk(i, side);
    for (std::size_t i = 0; i < open.size(); ++i)
        if (!used[i]) walk(i, 0);

    std::vector<SectionPiece> pieces;
    for (SectionPiece& p : section.pieces)
        if (p.closed) pieces.push_back(std::move(p));
    for (SectionPiece& p : chained) pieces.push_back(std::move(p));
    section.pieces = std::move(pieces);
    return report;
}

// -------------------------------------------------------------------------------------------------
// Nesting.

void validate(const NestingParams& params) {
    if (!(std::isfinite(params.distance) && params.distance >= 0.0))
        throw InvalidInput("nest_layers: params.distance must be finite and >= 0 (got " +
                           format_number(params.distance) + ")");
    if (!(params.coverage > 0.0 && params.coverage <= 1.0))
        throw InvalidInput("nest_layers: params.coverage must be in (0, 1] (got " +
                           format_number(params.coverage) + ")");
}

NestingReport nest_layers(std::vector<Layer>& layers, const std::vector<int>& rank,
                          const NestingParams& params) {
    validate(params);
    const std::size_t n = layers.size();
    if (!rank.empty() && rank.size() != n)
        throw InvalidInput("nest_layers: rank has " + std::to_string(rank.size()) +
                           " entries for " + std::to_string(n) + " layers");
    NestingReport report;
    Box2 all;
    for (const Layer& l : layers) all.extend(l.bounds());
    const double d =
        params.distance > 0.0 ? params.distance : 0.05 * std::hypot(all.size().x, all.size().y);
    report.distance = d;
    for (Layer& l : layers) l.outer = std::vector<std::string>{};
    if (n < 2) return report;

    std::vector<LayerIndex> index;
    std::vector<std::vector<double>> weights;
    std::vector<double> area(n);
    index.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        index.emplace_back(layers[i], d);
        weights.push_back(vertex_weights(layers[i]));
        area[i] = signed_area(layers[i].points);
    }
    auto rank_of = [&](std::size_t i) { return rank.empty() ? -1 : rank[i]; };
    const double theta = params.coverage;

    std::vector<Candidate> links;
    struct Pending {
        std::size_t a, b;  // a open; b closed (b under a?) or open (stacked, direction open)
        OneWay ab, ba;     // a measured against b, b against a
    };
    std::vector<Pending> pending;
    // inside[a * n + b]: the share of a's length inside b when b is closed (0 for a pair too far
    // apart to be measured: their boxes do not meet).
    std::vector<double> inside(n * n, 0.0);
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = a + 1; b < n; ++b) {
            const Layer &la = layers[a], &lb = layers[b];
            const bool may_contain = (lb.closed && index[b].box().overlaps(index[a].box())) ||
                                     (la.closed && index[a].box().overlaps(index[b].box()));
            if (!may_contain && !index[a].box().inflated(d).overlaps(index[b].box())) continue;
            const OneWay ab = measure(la, weights[a], index[b], d);
            const OneWay ba = measure(lb, weights[b], index[a], d);
            inside[a * n + b] = ab.inside;
            inside[b * n + a] = ba.inside;
            const bool alongside = ab.near >= theta || ba.near >= theta;
            if (la.closed && lb.closed) {
                const bool a_in = ab.inside >= 0.5, b_in = ba.inside >= 0.5;
                if (a_in && b_in) {
                    bool a_under = std::abs(area[a]) < std::abs(area[b]);
                    if (rank_of(a) >= 0 && rank_of(b) >= 0 && rank_of(a) != rank_of(b)) {
                        a_under = rank_of(a) < rank_of(b);
                        ++report.order_decisions;
                    }
                    links.push_back(a_under ? Candidate{a, b, 2.0 + ab.inside}
                                            : Candidate{b, a, 2.0 + ba.inside});
                } else if (a_in) {
                    links.push_back({a, b, 2.0 + ab.inside});
                } else if (b_in) {
                    links.push_back({b, a, 2.0 + ba.inside});
                }
            } else if (!la.closed && lb.closed) {
                if (ab.inside >= 0.5)
                    links.push_back({a, b, 2.0 + ab.inside});
                else if (alongside)
                    pending.push_back({a, b, ab, ba});
            } else if (la.closed && !lb.closed) {
                if (ba.inside >= 0.5)
                    links.push_back({b, a, 2.0 + ba.inside});
                else if (alongside)
                    pending.push_back({b, a, ba, ab});
            } else if (alongside) {
                pending.push_back({a, b, ab, ba});
            }
        }

    // Inner side of each open layer: where its near loops lie, else inside its chord polygon.
    std::vector<double> vote(n, 0.0);
    for (const Pending& p : pending)
        if (layers[p.b].closed) vote[p.a] += p.ba.side;
    std::vector<int> inner(n, 1);
    std::vector<char> known(n, 0);  // inner side decided by near loops, not guessed from the chord
    for (std::size_t i = 0; i < n; ++i)
        if (!layers[i].closed) {
            known[i] = vote[i] != 0.0;
            inner[i] = known[i] ? sign_of(vote[i]) : (area[i] < 0.0 ? -1 : 1);
        }

    for (const Pending& p : pending) {
        const double strength = std::max(p.ab.near, p.ba.near);
        if (layers[p.b].closed) {
            if (sign_of(p.ba.side) == inner[p.a])
                links.push_back({p.b, p.a, strength});
            else
                ++report.side_conflicts;
            continue;
        }
        // Both open: positive evidence means b is over a. A side guessed from the chord only
        // counts when neither side is known from loops.
        const bool use_a = known[p.a] || !known[p.b], use_b = known[p.b] || !known[p.a];
        // Each piece must lie on one side of the other where they are near (agreement by
        // length >= 90%); a piece that wraps around the other's end is not stacked on it.
        auto one_sided = [](const OneWay& w) {
            return w.side_weight == 0.0 || std::abs(w.side) >= 0.8 * w.side_weight;
        };
        if (!one_sided(p.ab) || !one_sided(p.ba)) {
            ++report.side_conflicts;
            continue;
        }
        double from_a = 0.0, from_b = 0.0;
        if (const int s = sign_of(p.ba.side); s != 0 && use_a)
            from_a = (s == -inner[p.a] ? 1.0 : -1.0) * std::abs(p.ba.side);
        if (const int s = sign_of(p.ab.side); s != 0 && use_b)
            from_b = (s == inner[p.b] ? 1.0 : -1.0) * std::abs(p.ab.side);
        // Each on the other's outer side, or each on the other's inner side: neither order
        // agrees with both (a guessed side may be wrong, but which one is not known).
        if (from_a * from_b < 0.0) {
            ++report.side_conflicts;
            continue;
        }
        const double evidence = from_a + from_b;
        if (evidence > 0.0) {
            links.push_back({p.a, p.b, strength});
        } else if (evidence < 0.0) {
            links.push_back({p.b, p.a, strength});
        } else if (rank_of(p.a) >= 0 && rank_of(p.b) >= 0 && rank_of(p.a) != rank_of(p.b)) {
            ++report.order_decisions;
            links.push_back(rank_of(p.a) < rank_of(p.b) ? Candidate{p.a, p.b, strength}
                                                        : Candidate{p.b, p.a, strength});
        }
    }
    report.candidate_links = links.size();

    // Strongest first, never closing a cycle.
    std::stable_sort(links.begin(), links.end(), [](const Candidate& x, const Candidate& y) {
        return x.strength > y.strength;
    });
    std::vector<std::vector<std::size_t>> out(n);
    // Would `c` put a layer under a loop that it mostly lies outside of (c.under, or a layer
    // under it, under c.over or a closed layer over it)? A chain of open layers can imply it
    // where no pair of the chain says so (an armpit, where the pieces cross).
    auto outside_a_loop = [&](const Candidate& c) {
        std::vector<std::size_t> loops;
        for (std::size_t y = 0; y < n; ++y)
            if (layers[y].closed && (y == c.over || reaches(out, c.over, y))) loops.push_back(y);
        for (std::size_t x = 0; x < n && !loops.empty(); ++x) {
            if (x != c.under && !reaches(out, x, c.under)) continue;
            for (std::size_t y : loops)
                if (inside[x * n + y] < 0.5) return true;
        }
        return false;
    };
    for (const Candidate& c : links) {
        if (reaches(out, c.over, c.under)) {
            ++report.dropped_for_cycles;
            continue;
        }
        if (outside_a_loop(c)) {
            ++report.dropped_outside_loops;
            continue;
        }
        out[c.under].push_back(c.over);
    }
    // Transitive reduction: drop a -> b when another path leads from a to b.
    std::vector<std::vector<std::size_t>> reduced(n);
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b : out[a])
            if (!reaches(out, a, b, a, b)) reduced[a].push_back(b);
    for (std::size_t a = 0; a < n; ++a) {
        std::sort(reduced[a].begin(), reduced[a].end());
        for (std::size_t b : reduced[a]) layers[a].outer->push_back(layers[b].name);
        report.links += reduced[a].size();
    }
    return report;
}

// -------------------------------------------------------------------------------------------------
// Whole slices.

void validate(const SliceParams& params) {
    if (params.heights.empty()) throw InvalidInput("slice: params.heights is empty");
    for (double h : params.heights)
        if (!std::isfinite(h)) throw InvalidInput("slice: params.heights has " + format_number(h));
    if (!(std::isfinite(params.thickness) && params.thickness >= 0.0))
        throw InvalidInput("slice: params.thickness must be finite and >= 0 (got " +
                           format_number(params.thickness) + ")");
    for (const auto& [name, t] : params.mesh_thickness)
        if (!(std::isfinite(t) && t >= 0.0))
            throw InvalidInput("slice: params.mesh_thickness['" + shown_text(name) +
                               "'] must be finite and >= 0 (got " + format_number(t) + ")");
    validate(params.nesting);
    validate(params.weld);
}

SliceReport slice_meshes(const std::vector<SliceMesh>& meshes, const SliceParams& params,
                         const ProgressFn& progress) {
    validate(params);
    std::map<std::string, std::size_t> by_name;
    for (std::size_t m = 0; m < meshes.size(); ++m)
        if (!by_name.emplace(meshes[m].name, m).second)
            throw InvalidInput("slice: two meshes are named '" + shown_text(meshes[m].name) + "'");
    std::vector<std::size_t> sequence;
    std::vector<int> mesh_rank(meshes.size(), -1);
    for (const std::string& name : params.order) {
        auto it = by_name.find(name);
        if (it == by_name.end()) {
            std::string known;
            for (const auto& [k, v] : by_name) known += (known.empty() ? "" : ", ") + shown_text(k);
            throw InvalidInput("slice: params.order names '" + shown_text(name) +
                               "', which is not a mesh (meshes: " + known + ")");
        }
        if (mesh_rank[it->second] >= 0)
            throw InvalidInput("slice: params.order names '" + shown_text(name) + "' twice");
        mesh_rank[it->second] = static_cast<int>(sequence.size());
        sequence.push_back(it->second);
    }
    for (std::size_t m = 0; m < meshes.size(); ++m)
        if (mesh_rank[m] < 0) sequence.push_back(m);
    for (const auto& [name, t] : params.mesh_thickness)
        if (by_name.count(name) == 0)
            throw InvalidInput("slice: params.mesh_thickness names '" + shown_text(name) +
                               "', which is not a mesh");
    std::vector<double> mesh_edge(meshes.size(), 0.0);
    if (params.weld.enabled && params.weld.tolerance == 0.0)
        for (std::size_t m = 0; m < meshes.size(); ++m)
            mesh_edge[m] = median_edge_length(meshes[m]);

    SliceReport report;
    const auto names = plane_coordinate_names(params.axis);
    for (std::size_t h = 0; h < params.heights.size(); ++h) {
        if (progress &&
            !progress("slice", static_cast<double>(h) / static_cast<double>(params.heights.size())))
            throw Cancelled();
        PlaneSlice slice;
        slice.height = params.heights[h];
        std::vector<Layer> layers;
        std::vector<int> rank;
        for (std::size_t m : sequence) {
            const SliceMesh& mesh = meshes[m];
            MeshSection section = section_mesh(mesh, params.axis, slice.height);
            weld_section(section, mesh_edge[m], params.weld);
            slice.totals.crossed_triangles += section.crossed_triangles;
            slice.totals.branch_points += section.branch_points;
            slice.totals.merged_points += section.merged_points;
            slice.totals.dropped_pieces += section.dropped_pieces;
            if (section.pieces.empty()) {
                slice.missed_meshes.push_back(mesh.name);
                continue;
            }
            // Group by component(s) (or not), longest piece first within a group.
            const auto t = params.mesh_thickness.find(mesh.name);
            const double thickness =
                t != params.mesh_thickness.end() ? t->second : params.thickness;
            std::map<std::vector<std::uint32_t>, std::vector<std::pair<Layer, WeldedLayer>>> groups;
            for (SectionPiece& piece : section.pieces) {
                Layer layer;
                layer.closed = piece.closed;
                layer.points = std::move(piece.points);
                if (layer.closed && signed_area(layer.points) < 0.0)
                    std::reverse(layer.points.begin(), layer.points.end());
                layer.thickness = thickness;
                std::vector<std::uint32_t> key;
                if (params.split_components)
                    key = piece.welded_components.empty()
                              ? std::vector<std::uint32_t>{piece.component}
                              : piece.welded_components;
                const WeldedLayer weld{{},
                                       piece.welded_components.empty() ? 0 : piece.welded_pieces,
                                       piece.welded_overlaps,
                                       layer.closed};
                groups[key].emplace_back(std::move(layer), weld);
            }
            for (auto& [components, group] : groups) {
                std::stable_sort(group.begin(), group.end(), [](const auto& a, const auto& b) {
                    return a.first.length() > b.first.length();
                });
                std::string base = mesh.name;
                for (std::size_t k = 0; k < components.size(); ++k)
                    base += (k == 0 ? ".c" : "+c") + std::to_string(components[k]);
                for (std::size_t j = 0; j < group.size(); ++j) {
                    Layer& layer = group[j].first;
                    layer.name = base + "_" + std::to_string(j + 1);
                    (layer.closed ? slice.closed_layers : slice.open_layers) += 1;
                    slice.vertices += layer.points.size();
                    if (group[j].second.pieces > 0) {
                        group[j].second.name = layer.name;
                        slice.welded.push_back(group[j].second);
                    }
                    layers.push_back(std::move(layer));
                    rank.push_back(params.order.empty() ? -1 : mesh_rank[m]);
                }
            }
        }
        if (!layers.empty()) {
            slice.nesting = nest_layers(layers, rank, params.nesting);
            Scene scene(std::move(layers), params.units);
            scene.metadata["plane"] = "\"" + std::string(axis_name(params.axis)) + " = " +
                                      format_number(slice.height) + "\"";
            scene.metadata["coords"] = std::string("[\"") + names[0] + "\", \"" + names[1] + "\"]";
            slice.scene = std::move(scene);
        }
        report.slices.push_back(std::move(slice));
    }
    if (progress && !progress("slice", 1.0)) throw Cancelled();
    return report;
}

std::vector<double> regular_heights(double low, double high, double step) {
    if (!(std::isfinite(step) && step > 0.0))
        throw InvalidInput("slice: the step must be finite and > 0 (got " + format_number(step) +
                           ")");
    if (!(std::isfinite(low) && std::isfinite(high))) throw InvalidInput("slice: non-finite range");
    const double k0 = std::ceil(low / step), k1 = std::floor(high / step);
    if (k1 - k0 > 100000.0)
        throw InvalidInput("slice: step " + format_number(step) +
                           " gives more than 100000 heights");
    std::vector<double> out;
    for (double k = k0; k <= k1; k += 1.0) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.12g", k * step);  // 0.15, not 0.15000000000000002
        const double h = std::strtod(buf, nullptr);
        if (h > low && h < high) out.push_back(h == 0.0 ? 0.0 : h);
    }
    return out;
}

std::string slice_file_name(const std::string& prefix, Axis axis, double height, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(height));
    const bool zero = std::string(buf).find_first_not_of("0.") == std::string::npos;
    return prefix + "_" + axis_name(axis) + (height < 0.0 && !zero ? "-" : "+") + buf + ".json";
}

int slice_name_decimals(const std::vector<double>& heights) {
    int first_distinct = -1;
    for (int d = 2; d <= 9; ++d) {
        std::set<std::string> seen;
        bool exact = true;
        for (double h : heights) {
            seen.insert(slice_file_name("", Axis::Y, h, d));
            const double scale = std::pow(10.0, d);
            exact = exact && std::abs(std::round(h * scale) / scale - h) <=
                                 1e-9 * std::max(1.0, std::abs(h));
        }
        const bool distinct =
            seen.size() == std::set<double>(heights.begin(), heights.end()).size();
        if (distinct && first_distinct < 0) first_distinct = d;
        if (distinct && exact) return d;
    }
    return first_distinct >= 0 ? first_distinct : 9;
}

}  // namespace strata
