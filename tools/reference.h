#pragma once
/// @file `--reference ORIG`: the original a scene comes from (before a decimation), matched
/// to it by layer name, as `strata check` and `strata untangle` take it.

#include "strata/geometry/input_sides.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <string>
#include <vector>

namespace strata::cli {

/// What a scene takes from its original.
struct Reference {
    Scene scene;  ///< ORIG as read (with the default thickness given to it).
    /// Per layer of the scene: the outside side ORIG gives its namesake where that is open (the
    /// vote of outside_side() is unreliable on a layer decimated to a few vertices), else the
    /// scene's own outside_side().
    std::vector<int> outside_sides;
    /// ORIG's sides of its open layers (record_input_sides()), carried onto the scene's
    /// vertices by nearest vertex (InputSides::matched()).
    InputSides sides;
    /// ORIG's vertices on the side of an open layer the global order does not give them
    /// (rolled or folded over; InputSides::rolled_count() on ORIG).
    std::size_t rolled = 0;
};

/// Reads ORIG at `path` and matches it to `scene` by layer name. `near_distance`: the near
/// distance of the outside sides (scene units, 0 = automatic); `thickness`: given to ORIG's
/// layers of thickness 0, as the scene's (`--thickness`, <= 0: none). Notes of the reader go
/// to stderr.
/// @throws IoError ORIG unreadable (the reader names the file and position).
/// @throws InvalidInput no layer of `scene` has a namesake in ORIG, or, with `every_layer`,
/// one has none (the message names ORIG and the layers).
Reference read_reference(const std::string& path, const Scene& scene, double near_distance,
                         bool every_layer, double thickness = 0.0);

/// read_reference() on an original already read (`original`, kept in the result); `name`
/// names it in the errors (its path, or e.g. "reference"). Same throws but IoError.
Reference match_reference(Scene original, const Scene& scene, double near_distance,
                          bool every_layer, const std::string& name);

}  // namespace strata::cli
