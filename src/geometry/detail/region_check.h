#pragma once
// RegionCheck: check_scene()'s counts for scenes moved only inside a box (a local
// untangling's), from one whole check of the reference and a check near the box. Internal to
// the library (untangle_local() uses it); implemented in checks.cpp beside the whole check,
// whose scans it shares.

#include "strata/core/types.h"
#include "strata/geometry/checks.h"

#include <cstddef>
#include <limits>
#include <memory>

namespace strata {

/// The counts of a CheckReport that its verdicts are made of.
struct CheckCounts {
    std::size_t crossing_count = 0;              ///< CheckReport::crossing_count.
    std::size_t touch_count = 0;                 ///< CheckReport::touch_count.
    std::size_t self_crossing_count = 0;         ///< CheckReport::total_self_crossings().
    std::size_t separation_violation_count = 0;  ///< CheckReport::separation_violation_count.
    std::size_t nesting_violation_count = 0;     ///< CheckReport::nesting_violation_count.
    /// CheckReport::min_separation_ratio.
    double min_separation_ratio = std::numeric_limits<double>::infinity();
    /// CheckReport::is_collision_free().
    bool is_collision_free() const {
        return crossing_count == 0 && self_crossing_count == 0 && nesting_violation_count == 0;
    }
    /// CheckReport::separations_hold().
    bool separations_hold() const { return separation_violation_count == 0; }
};

/// The counts of `report`.
CheckCounts counts_of(const CheckReport& report);

/// @brief check_scene() of scenes that differ from a reference scene only by vertices moved
/// inside a box (a local untangling's): the reference is checked in full once, and each
/// scene then only near the box, with the same counts (and min_separation_ratio) as
/// check_scene(scene, params) would give.
///
/// What lies away from the box cannot change: the contacts of segments whose reference box
/// misses the box and the touches at a point outside it, and the separations and nesting of
/// the vertices farther from the box than the near distance (and than the largest separation
/// threshold), are taken from the reference's check; the contacts between the segments that
/// meet the box, and the separations and nesting of the vertices near it, are checked again.
///
/// check() checks the whole scene instead (check_scene(), counted by whole_checks()) when
/// that argument does not hold: a moved vertex, or a neighbour of one, outside the box in
/// the reference or in the scene; a segment at a moved vertex of zero length in either (it
/// would change which segments are adjacent); a layer of fewer than 3 vertices that moved;
/// an automatic near distance that changed (the scene's bounds did); and, for every scene,
/// when params.outside_sides is empty (the votes of outside_side() read the whole scene) or
/// the box is empty.
class RegionCheck {
  public:
    /// Checks `reference` in full. `reference` is not copied: it must outlive this object
    /// and stay unchanged. @throws InvalidInput bad params (as check_scene()).
    RegionCheck(const Scene& reference, const CheckParams& params, const Box2& box);
    ~RegionCheck();
    RegionCheck(RegionCheck&&) noexcept;
    RegionCheck& operator=(RegionCheck&&) noexcept;

    /// check_scene(reference, params), whole. check() may be called from several threads.
    const CheckReport& reference_report() const;
    /// The counts of check_scene(scene, params). `scene`: the reference with some vertices
    /// moved (same layers, vertex counts, closedness, relations and thicknesses).
    /// @throws InvalidInput `scene` has other layer or vertex counts or closedness.
    CheckCounts check(const Scene& scene) const;
    /// The check() calls that checked the whole scene (see above).
    std::size_t whole_checks() const;

  private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace strata
