#pragma once
/// @file SVG in and out, so that a person can draw a scene or look at one in a browser.
///
/// Reading: <polyline>, <polygon> and <path> elements in document order, inside to outside;
/// `transform` attributes (of the element and its ancestors) applied; y is flipped (SVG's y
/// points down, strata's up). Attributes data-thickness, data-weight, data-alpha, data-beta,
/// data-outer (space- or comma-separated names) and id (the layer name) are honoured.
/// Writing: one coloured <polyline>/<polygon> per layer carrying the same data-* attributes,
/// viewBox fitted to the scene, y flipped back, so that read(write(scene)) == scene.
///
/// Details of reading:
/// - <path> data follows the full SVG grammar (M L H V Z C S Q T A, absolute and relative,
///   implicit repeats); curves and arcs are flattened within `flatten_tolerance`. Each subpath
///   is one layer (closed when it ends with Z), named id, id_2, id_3 ...; a subpath made of a
///   lone moveto is ignored. <polygon> is closed, <polyline> open; <line>, <rect>, <circle>
///   and <ellipse> are read too. A layer without an id is called "layer_<k>", k its index.
/// - `transform` functions: matrix, translate, scale, rotate (with optional centre), skewX,
///   skewY, in lists. The root's viewBox is ignored: points are in the root's user units.
/// - Skipped: the content of <defs>, <clipPath>, <mask>, <symbol>, <marker>, <pattern>, and
///   any element whose data-strata-role is not "layer" (the writer marks its underlay, vertex
///   dots and marks "underlay", "vertices" and "marks").
/// - When any element has data-outer, every layer has `outer` set (empty when absent);
///   otherwise the document order is one implicit stack. data-strata-units on the root <svg>
///   gives the scene's units. Layer::extra and Scene::metadata are not carried by SVG.
/// - Names XML 1.0 cannot hold (a C0 control other than tab, newline and return, e.g. ESC; a
///   byte of no UTF-8 character): when the scene or the underlay has one, the writer writes
///   every name and the units as shown_text() shows them (\xNN, a backslash as \\) and marks
///   the root data-strata-names="escaped"; the reader undoes \\ and \xNN in the ids,
///   data-outer and data-strata-units of a document so marked, and only there.

#include "strata/geometry/scene.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace strata {

/// Parameters of parse_scene_svg().
struct SvgReadParams {
    /// Largest distance between a curve (C/S/Q/T/A path commands) and its flattened
    /// polyline, in SVG user units (after transforms). > 0.
    double flatten_tolerance = 0.01;
    /// Most vertices that flattening curves and arcs may make in the whole document (>= 1).
    /// A document that needs more is refused with InvalidInput naming the element: curves
    /// far larger than the tolerance (coordinates of 1e57 in a 700-byte file, found by
    /// fuzz_svg) would otherwise fill the memory. Lines and listed points are not counted.
    std::size_t max_curve_points = std::size_t{1} << 20;
};

/// Throws InvalidInput naming the first out-of-range field.
void validate(const SvgReadParams& params);

/// Parses a scene from SVG text. @throws InvalidInput naming `source`, the element (by its
/// line and id) and the attribute and value at fault.
Scene parse_scene_svg(std::string_view text, const std::string& source = "<svg>",
                      const SvgReadParams& params = {});
/// parse_scene_svg() of a file's content. @throws IoError unreadable file.
Scene read_scene_svg(const std::filesystem::path& path, const SvgReadParams& params = {});

/// A place to point at in a picture (e.g. a crossing found by check_scene()): a red ring at
/// `at`, and, when `to` differs from `at`, a red line from `at` to `to` (e.g. the two closest
/// points of a pair of layers closer than required). Scene units. `title` is shown on hover.
struct SvgMark {
    Vec2 at{0.0};
    Vec2 to{0.0};
    std::string title;
};

/// Parameters of scene_to_svg().
struct SvgWriteParams {
    const Scene* underlay =
        nullptr;                 ///< Optional: drawn faintly under the scene (e.g. the original).
    double width_px = 800.0;     ///< Width of the picture in pixels; height keeps the aspect.
    double stroke_px = 1.5;      ///< Stroke width of the layers in pixels.
    bool draw_vertices = false;  ///< Small dots at the vertices.
    /// Drawn over the scene, in a <g data-strata-role="marks"> that parse_scene_svg() skips.
    /// They do not widen the picture: marks outside the scene's box are cut off.
    std::vector<SvgMark> marks;
};

/// Throws InvalidInput naming the first out-of-range field (width_px > 0, stroke_px >= 0).
void validate(const SvgWriteParams& params);

/// A standalone SVG document showing `scene` (and the underlay). Coordinates are written
/// with round-trip precision; the underlay is a <g data-strata-role="underlay"> that
/// parse_scene_svg() skips. @throws InvalidInput bad params.
std::string scene_to_svg(const Scene& scene, const SvgWriteParams& params = {});
/// One picture of a comparison (see panels_to_svg()).
struct SvgPanel {
    std::string title;                ///< Caption drawn above the picture.
    const Scene* scene = nullptr;     ///< Drawn in colour.
    const Scene* underlay = nullptr;  ///< Optional, drawn faintly under it.
    std::vector<SvgMark> marks;       ///< Drawn over it (SvgWriteParams::marks).
};

/// Several scenes side by side (stacked vertically when they are wider than tall), each with
/// its caption, e.g. before / naive / strata. Meant for looking, not for reading back.
/// @throws InvalidInput when a panel has no scene or `params` is out of range.
std::string panels_to_svg(const std::vector<SvgPanel>& panels, const SvgWriteParams& params = {});

/// scene_to_svg() written atomically to `path`. @throws IoError.
void write_scene_svg(const Scene& scene, const std::filesystem::path& path,
                     const SvgWriteParams& params = {});

}  // namespace strata
