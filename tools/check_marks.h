#pragma once
/// @file What a check found, as marks on a picture: `strata check --svg` and the picture of
/// `strata untangle --svg` draw the same marks.

#include "strata/geometry/checks.h"
#include "strata/geometry/scene.h"
#include "strata/io/svg_io.h"

#include <string>
#include <vector>

namespace strata::cli {

/// `v` with 6 significant digits ("inf" for +infinity), as the report tables print numbers.
std::string short_number(double v);

/// Marks (SvgMark) at the crossings, touches and self-crossings that `report` (check_scene()
/// of `scene`) lists, each titled with the layers (as shown_name() shows them) and segments.
std::vector<SvgMark> contact_marks(const Scene& scene, const CheckReport& report);

/// Picture settings for `scene` with the problems `report` (check_scene() of `scene`) lists
/// marked (SvgWriteParams::marks): contact_marks(), then each vertex on the wrong side or
/// closer than required, and a line between the closest points of each near pair whose gap is
/// below required x (1 - `separation_tolerance`). Each mark's title names the layers (as
/// shown_name() shows them), the segments or vertex, and the distances. Nothing else of the
/// settings is changed from the defaults.
SvgWriteParams check_marks(const Scene& scene, const CheckReport& report,
                           double separation_tolerance);

}  // namespace strata::cli
