#pragma once
/// @file Generated multi-layered scenes, one function per family of the untangling benchmark
/// (bench/bench_untangle.cpp, docs/untangle.md) and its tests: untangled, valid inputs with
/// known geometry, to be tangled by a decimation. Deterministic; lengths in scene units.

#include "strata/core/types.h"
#include "strata/geometry/scene.h"

#include <cstddef>
#include <string>
#include <vector>

namespace strata {

/// The families.
enum class SceneFamily {
    Stack,        ///< `layers` open layers offset along the normal of a wavy curve (one stack).
    Loops,        ///< `layers` concentric wavy closed loops (one stack, each inside the next).
    Folded,       ///< A stack of `layers` open layers folded twice (an S): its outer layers face
                  ///< each other across the first fold, its inner ones across the second.
    Rolled,       ///< Two open layers; the inner one comes around the end of the outer one and lies
                  ///< on top of it (the paper's Fig. 7b,c): the global order does not hold there.
    Jacket,       ///< A closed body loop under an open jacket arc that covers 3/4 of it.
    Legs,         ///< Two closed leg loops side by side inside a closed skirt loop (`outer` links).
    RolledTwice,  ///< Rolled, then the inner layer's top turned back once more over itself.
    RolledBoth,   ///< Both layers rolled together: on top the inner one lies over the outer
                  ///< (both run back there, so the sides along their travel stay as below).
    ShirtRoll,    ///< A closed body under a shirt rolled over the end of a jacket.
    CollarWrap,   ///< A closed body under a collar folded around a closed cord at its end: the
                  ///< cord, under the collar, lies on the collar's outside face all along.
};

/// All families, in the order above.
std::vector<SceneFamily> all_scene_families();
/// "stack", "loops", "folded", "rolled", "jacket", "legs", "rolled_twice", "rolled_both",
/// "shirt_roll", "collar_wrap".
std::string family_name(SceneFamily family);
/// The family has a part lying on the other side of an open layer than the global order
/// says (Rolled, RolledTwice, ShirtRoll, CollarWrap): its nesting holds against its own sides
/// (record_input_sides()), not against the global order. Not RolledBoth: rolled together,
/// each layer's side of the other, taken along its direction of travel, stays the same.
bool is_rolled(SceneFamily family);

/// Size and spacing of a generated scene.
struct FamilyParams {
    std::size_t layers = 6;    ///< Layers (Stack, Loops, Folded); the others have fixed counts.
    std::size_t points = 300;  ///< Vertices per layer (about; closed loops exactly).
    /// Gap between neighbouring layers in segment lengths (> 0); every layer's thickness is
    /// half the gap, so the required separation is half the gap.
    double gap = 2.0;
    /// The rolled families' counterpart that keeps the global order, with the same layers and
    /// about the same vertex counts (the "same scene unrolled", for timings): Rolled and
    /// RolledTwice turn their roll away from the other layer (the inner layer mirrored across
    /// its base), ShirtRoll's jacket ends before the shirt's roll (shifted back by one radian),
    /// CollarWrap's cord lies outside the collar's turned-back part instead of inside the
    /// fold. No effect on the other families.
    bool unrolled = false;
    double scale = 1.0;  ///< Every coordinate multiplied by this (> 0) ...
    Vec2 offset{0.0};    ///< ... then shifted by this.
};

/// The scene of `family`. @throws InvalidInput on bad params (zero points or layers, gap or
/// scale not > 0).
Scene make_scene(SceneFamily family, const FamilyParams& params = {});

}  // namespace strata
