#pragma once
/// @file Slicing 3D meshes (garments on a body) by axis-aligned planes into layered 2D scenes,
/// and inferring the nesting ("a is under b") of the slices. Documented in docs/slicing.md.
///
/// Data flow: read_slice_mesh() (OBJ, PLY, STL through OpenMesh; OFF read by strata) ->
/// SliceMesh (triangles, double precision) -> section_mesh() (closed loops and open polylines
/// of one plane) -> nest_layers() (`outer` links) -> Scene. slice_meshes() runs the whole chain for
/// several meshes and heights. Lengths are in mesh units (the units of the mesh file).

#include "strata/core/progress.h"
#include "strata/geometry/scene.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace strata {

/// The axis a slicing plane is perpendicular to.
enum class Axis { X, Y, Z };

/// "x", "y" or "z".
const char* axis_name(Axis axis);
/// Parses "x", "y" or "z" (case-insensitive).  @throws InvalidInput naming the value.
Axis parse_axis(std::string_view text);
/// The two in-plane coordinates of `p`, in this order: axis x -> (y, z), axis y -> (x, z),
/// axis z -> (x, y). The axis y case matches the shared slices ("coords": ["x", "z"]).
Vec2 plane_coordinates(const glm::dvec3& p, Axis axis);
/// Names of the two in-plane coordinates, e.g. {"x", "z"} for axis y.
std::array<const char*, 2> plane_coordinate_names(Axis axis);

/// What reading a mesh file found and changed.
struct MeshReadReport {
    std::size_t file_vertices = 0;  ///< Vertices OpenMesh loaded (with its own duplicates).
    std::size_t file_faces = 0;     ///< Faces OpenMesh loaded (polygons, before triangulation).
    /// Faces OpenMesh could not connect to their neighbours (complex edge or vertex: a
    /// non-manifold configuration). OpenMesh re-adds them with duplicated vertices;
    /// read_slice_mesh() maps those back to the originals, so they are sliced with their
    /// neighbours (see `reconnected_vertices`).
    std::size_t complex_faces = 0;
    /// Faces OpenMesh dropped (repeated or invalid vertex index), counted from its messages.
    std::size_t dropped_faces = 0;
    std::size_t reconnected_vertices = 0;  ///< OpenMesh duplicates mapped back to the original.
    /// True when the coordinates were re-read from the text in double precision (ASCII OBJ
    /// and OFF; OpenMesh 9 itself reads every format through single precision).
    bool double_precision = false;
    std::size_t degenerate_triangles = 0;  ///< Triangles with a repeated vertex, removed.
    /// OpenMesh's own messages (omlog / omerr), captured instead of printed, one per line.
    std::vector<std::string> messages;
};

/// A triangle mesh ready to slice: polygons fan-triangulated from their first vertex,
/// connected components numbered. Connectivity is the file's: two vertices at the same
/// position are distinct unless the file shares the index (STL: OpenMesh merges equal
/// positions), so separate panels stay separate components, as in the shared slices.
struct SliceMesh {
    std::string name;                                     ///< Prefix of the layer names.
    std::vector<glm::dvec3> vertices;                     ///< Mesh units.
    std::vector<std::array<std::uint32_t, 3>> triangles;  ///< Indices into `vertices`.
    /// Per triangle: its connected component (triangles sharing a vertex are connected),
    /// numbered by decreasing vertex count (ties: more triangles, then first triangle), so 0
    /// is the largest; this is the numbering of the shared slices (`skirt.c8+c10`).
    std::vector<std::uint32_t> component;
    std::size_t component_count = 0;
    MeshReadReport read_report;  ///< Filled by read_slice_mesh().

    /// Axis-aligned bounds of the vertices (min, max); both zero for an empty mesh.
    std::array<glm::dvec3, 2> bounds() const;
};

/// Builds a SliceMesh from polygons (>= 3 indices each) over `vertices`: fan-triangulates,
/// drops triangles with a repeated vertex, labels components (unused vertices are kept).
/// @throws InvalidInput a non-finite coordinate or an index out of range (naming it).
SliceMesh make_slice_mesh(std::string name, std::vector<glm::dvec3> vertices,
                          const std::vector<std::vector<std::uint32_t>>& polygons);

/// Reads an OBJ, PLY or STL file through OpenMesh, or an ASCII OFF file (OFF, COFF, NOFF,
/// STOFF ...: the first three numbers of a vertex line are its position) with strata's own
/// reader, in double precision, and makes a SliceMesh of it (see make_slice_mesh()). `name`
/// defaults to the file stem. OpenMesh's messages are captured into read_report.messages;
/// nothing is printed.
/// @throws IoError the file is missing or OpenMesh cannot read it (with its message).
/// @throws InvalidInput an unsupported extension, or a mesh without faces.
SliceMesh read_slice_mesh(const std::filesystem::path& path, const std::string& name = {});

/// One polyline of a plane section.
struct SectionPiece {
    std::vector<Vec2> points;     ///< In-plane coordinates (plane_coordinates()); no two
                                  ///< consecutive points equal (closed: first != last either).
    bool closed = false;          ///< A loop; otherwise it ends at mesh borders.
    std::uint32_t component = 0;  ///< SliceMesh::component of its triangles.
    /// Components of every piece weld_section() joined into this one, increasing (empty: not
    /// welded; `component` is then the only one, else the first of the chain).
    std::vector<std::uint32_t> welded_components;
    std::size_t welded_pieces = 1;    ///< Pieces of section_mesh() chained into this one.
    std::size_t welded_overlaps = 0;  ///< Of its joins, those made at overlapping ends.
};

/// The intersection of a mesh with one plane.
struct MeshSection {
    std::vector<SectionPiece> pieces;   ///< In the order they were found (by first triangle).
    std::size_t crossed_triangles = 0;  ///< Triangles with vertices on both sides.
    /// Crossing points on a non-manifold edge (more than two crossed triangles): the pieces
    /// through it were paired by straightest continuation, any odd one ends there.
    std::size_t branch_points = 0;
    std::size_t merged_points = 0;   ///< Coincident consecutive points merged into one.
    std::size_t dropped_pieces = 0;  ///< Pieces that collapsed to a point (or a closed
                                     ///< piece with fewer than 3 distinct points).
};

/// @brief Intersects `mesh` with the plane `axis` = `height` (mesh units).
///
/// Every triangle with vertices on both sides gives one segment between the crossing points
/// of its two crossing edges; segments are chained through the shared edges into loops, or
/// into open polylines that end at mesh borders. Symbolic perturbation: a vertex exactly on
/// the plane counts as slightly above it, so a triangle never has exactly one crossing edge,
/// triangles lying in the plane are skipped (not crossed), and a crossing point whose upper
/// vertex lies on the plane is that vertex exactly. Coincident consecutive points (from such
/// vertices and from degenerate slivers) are merged, so no piece has a zero-length segment.
MeshSection section_mesh(const SliceMesh& mesh, Axis axis, double height);

/// Parameters of weld_section(): joining the open pieces of one mesh that meet at a seam.
struct WeldParams {
    bool enabled = true;  ///< false: every open piece stays its own layer (`--no-weld`).
    /// Ends of two open pieces (or the two ends of one) at most this far apart are joined, at
    /// their midpoint. Mesh units, >= 0; 0 = automatic: kAutoWeldFraction of the median
    /// triangle edge length of the mesh (median_edge_length()).
    double tolerance = 0.0;
    /// Overlapping ends: when a segment among the last `overlap_segments` of one end crosses
    /// a segment among the last `overlap_segments` of another end, both are cut at the
    /// crossing and joined there. >= 0; 0 = only ends that meet are welded.
    int overlap_segments = 3;
};

/// The automatic weld tolerance as a share of the median triangle edge length. Panels of a
/// sewn garment meet to within float rounding (1e-7 m against 5e-3 m edges on the Codim-IPC
/// skirt), while ends that belong apart (a collar's tips, a slit) are edges apart.
constexpr double kAutoWeldFraction = 0.05;

/// Throws InvalidInput naming the first out-of-range field.
void validate(const WeldParams& params);

/// Median length of the triangle edges of `mesh` (mesh units); 0 for a mesh without triangles.
double median_edge_length(const SliceMesh& mesh);

/// What weld_section() joined.
struct WeldReport {
    double tolerance = 0.0;    ///< Tolerance actually used, mesh units.
    std::size_t joins = 0;     ///< Pairs of ends joined (meeting or overlapping).
    std::size_t overlaps = 0;  ///< Of these, joins at overlapping ends (cut at the crossing).
    std::size_t closed = 0;    ///< Chains of open pieces that closed into a loop.
};

/// @brief Joins the open pieces of `section` (all from one mesh) whose ends meet within
/// `params.tolerance` or overlap near their ends (see WeldParams) into longer polylines, closed
/// when a chain closes. Joins are made closest first (meeting ends before overlaps), each end
/// at most once. Closed pieces are left alone. Nothing happens when params.enabled is false.
/// @param mesh_edge  median edge length of the mesh, for the automatic tolerance (mesh units).
/// @throws InvalidInput bad params.
WeldReport weld_section(MeshSection& section, double mesh_edge, const WeldParams& params = {});

/// Parameters of nest_layers(). Lengths are in scene units.
struct NestingParams {
    /// D: how close two layers must come to be related (open layers only; containment of
    /// closed loops does not depend on it). 0 = automatic: 5% of the diagonal of the
    /// bounding box of all layers (the automatic near distance of check_scene). >= 0.
    double distance = 0.0;
    /// Share of a layer's length that must lie within D of another for the two to "run
    /// alongside" each other. In (0, 1].
    double coverage = 0.5;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const NestingParams& params);

/// What nest_layers() found.
struct NestingReport {
    double distance = 0.0;               ///< D actually used.
    std::size_t links = 0;               ///< Direct `outer` links written (transitive reduction).
    std::size_t candidate_links = 0;     ///< Relations found before the reduction.
    std::size_t dropped_for_cycles = 0;  ///< Relations dropped because they closed a cycle.
    /// Relations dropped because, with those kept before, they put a layer under a closed one
    /// that it mostly lies outside of.
    std::size_t dropped_outside_loops = 0;
    /// Pairs near enough to relate but left side by side: a loop on an open layer's outer
    /// side; two open layers not each on one side of the other (one wraps around an end), or
    /// each on the other's outer side (or each on the other's inner side).
    std::size_t side_conflicts = 0;
    std::size_t order_decisions = 0;  ///< Relations decided by `rank` where geometry was even.
};

/// @brief Sets `outer` on every layer (possibly to an empty list) from the geometry.
///
/// Rules (docs/slicing.md has the details and the reasons):
/// - closed / closed: a is under b when most of a (by length) lies inside b (if both, the
///   smaller area is inside); any distance.
/// - open / closed: the open layer is under a loop it mostly lies inside; it is over a loop
///   it mostly lies outside of when the two run alongside (coverage of either within D) and
///   the loop is on the open layer's inner side (the side most of its near loops are on; with
///   no such loop, the inside of the polygon closed by its chord).
/// - open / open: stacked only when they run alongside; the one on the outer side of the
///   other is over it. Pieces that merely meet end to end, or that each lie on the other's
///   outer side (or each on the other's inner side), stay side by side.
/// Relations are added strongest first, skipping any that would close a cycle or put a layer
/// (directly or through others) under a loop it mostly lies outside of; only the transitive
/// reduction is written.
/// @param layers  modified in place (only `outer`); names must be unique.
/// @param rank    optional, one per layer: position of its mesh in a user-given order
///                (smaller = further inside, < 0 = unknown); breaks geometric ties.
/// @throws InvalidInput bad params, or rank of the wrong size.
NestingReport nest_layers(std::vector<Layer>& layers, const std::vector<int>& rank = {},
                          const NestingParams& params = {});

/// Parameters of slice_meshes().
struct SliceParams {
    Axis axis = Axis::Y;          ///< Planes are perpendicular to this axis.
    std::vector<double> heights;  ///< Plane positions along `axis`, mesh units; >= 1.
    /// Name each layer after the connected component it comes from:
    /// `<mesh>.c<k>_<j>` instead of `<mesh>_<j>` (k as in SliceMesh::component).
    bool split_components = false;
    /// Mesh names, innermost first (e.g. body, shirt, jacket). Empty: the order given. Sets
    /// the order of the layers in each scene and breaks geometric ties of the nesting.
    /// Every name must be a mesh name, at most once; unnamed meshes follow in given order.
    std::vector<std::string> order;
    NestingParams nesting;   ///< See nest_layers().
    WeldParams weld;         ///< See weld_section(); on by default.
    double thickness = 0.0;  ///< Thickness written to every layer, mesh units, >= 0.
    /// Thickness per mesh name (mesh units, >= 0), overriding `thickness` for that mesh's
    /// layers; every name must be a mesh name.
    std::map<std::string, double> mesh_thickness;
    std::string units;       ///< Length unit written to the scenes ("dm", "m"); may be empty.
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const SliceParams& params);

/// A layer of slice_meshes() welded from several pieces of section_mesh().
struct WeldedLayer {
    std::string name;          ///< Layer name in the scene.
    std::size_t pieces = 0;    ///< Open pieces joined.
    std::size_t overlaps = 0;  ///< Joins made at overlapping ends.
    bool closed = false;       ///< The chain closed into a loop.
};

/// One plane of slice_meshes().
struct PlaneSlice {
    double height = 0.0;
    /// The layers, or nothing when the plane misses every mesh. Layer j of a mesh (or of a
    /// component) is the j-th longest of its pieces, from 1; a piece welded from several
    /// components is named after all of them (`skirt.c1+c2_1`). Metadata: "plane", "coords".
    std::optional<Scene> scene;
    std::size_t closed_layers = 0, open_layers = 0, vertices = 0;
    std::vector<std::string> missed_meshes;  ///< Meshes the plane does not cross.
    MeshSection totals;  ///< Counters summed over the meshes (pieces left empty).
    std::vector<WeldedLayer> welded;  ///< Layers made of several pieces, in scene order.
    NestingReport nesting;
};

/// What slice_meshes() produced: one entry per height, in the order of params.heights.
struct SliceReport {
    std::vector<PlaneSlice> slices;
};

/// @brief Slices every mesh at every height and nests the layers of each plane.
/// @param meshes   distinct names; the layers of a plane are grouped by mesh (params.order).
/// @param progress optional; called once per height; return false to cancel.
/// @throws InvalidInput bad params, duplicate mesh names, unknown names in params.order.
/// @throws Cancelled.
SliceReport slice_meshes(const std::vector<SliceMesh>& meshes, const SliceParams& params = {},
                         const ProgressFn& progress = {});

/// Heights k * step (k integer) strictly inside (low, high), increasing.
/// @throws InvalidInput step not finite or <= 0, or more than 100000 heights.
std::vector<double> regular_heights(double low, double high, double step);

/// File name of the slice at `height`: `<prefix>_<axis><sign><value>.json` with `decimals`
/// decimals, e.g. slice_file_name("mh", Axis::Y, 1.5, 2) == "mh_y+1.50.json".
std::string slice_file_name(const std::string& prefix, Axis axis, double height, int decimals);

/// Smallest number of decimals (>= 2, <= 9) that tells every height of `heights` apart
/// and writes each of them exactly when it has few enough decimals.
int slice_name_decimals(const std::vector<double>& heights);

}  // namespace strata
