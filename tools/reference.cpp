#include "reference.h"

#include "cli_util.h"

#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/io/scene_io.h"

#include <iostream>
#include <utility>

namespace strata::cli {

Reference read_reference(const std::string& path, const Scene& scene, double near_distance,
                         bool every_layer, double thickness) {
    Scene original = with_default_thickness(read_scene(path), thickness);
    for (const std::string& note : original.diagnostics().notes)
        std::cerr << "strata: note: " << path << ": " << note << '\n';
    return match_reference(std::move(original), scene, near_distance, every_layer, path);
}

Reference match_reference(Scene original, const Scene& scene, double near_distance,
                          bool every_layer, const std::string& name) {
    Reference ref;
    ref.scene = std::move(original);
    std::string missing;
    std::size_t matched = 0, missing_count = 0;
    for (std::size_t i = 0; i < scene.size(); ++i) {
        const auto j = ref.scene.find(scene.layer(i).name);
        if (j) {
            ++matched;
        } else {
            ++missing_count;
            if (missing_count <= 5)
                missing += (missing.empty() ? "'" : ", '") + shown_text(scene.layer(i).name) + "'";
        }
        // An open layer decimated to a few vertices gets its side from its original.
        ref.outside_sides.push_back(j && !ref.scene.layer(*j).closed
                                        ? outside_side(ref.scene, *j, near_distance)
                                        : outside_side(scene, i, near_distance));
    }
    if (missing_count > 5) missing += ", ...";
    if (matched == 0 && scene.size() > 0)
        throw InvalidInput(name + ": the reference has no layer named as one of the scene's (" +
                           missing + "): layers are matched by name");
    if (every_layer && missing_count > 0)
        throw InvalidInput(name + ": the reference has no layer named " + missing + " (" +
                           std::to_string(missing_count) + " of " + std::to_string(scene.size()) +
                           " layers): layers are matched by name");
    // ORIG's own sides of its open layers (a rolled part): the scene's vertices take those of
    // the nearest vertex of their layer there.
    const InputSides recorded = record_input_sides(ref.scene);
    ref.rolled = recorded.rolled_count(ref.scene, outside_sides(ref.scene, near_distance));
    ref.sides = InputSides::matched(recorded, ref.scene, scene);
    return ref;
}

}  // namespace strata::cli
