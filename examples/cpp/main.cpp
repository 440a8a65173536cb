// Reads a slice (JSON or SVG), simplifies it (removes 90 % of the vertices by default),
// writes the result and prints one line per layer.
// Usage: strata_example IN OUT [REMOVE]
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"

#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: strata_example IN OUT [REMOVE]\n";
        return 2;
    }
    try {
        strata::Scene scene = strata::read_scene(argv[1]);
        strata::SimplifyParams params;
        if (argc > 3) params.remove = std::stod(argv[3]);
        const strata::SimplifyReport report = strata::simplify(scene, params);
        strata::write_scene(scene, argv[2]);
        for (const auto& layer : report.layers)
            std::cout << layer.name << ": " << layer.before << " -> " << layer.after
                      << " vertices, hausdorff " << layer.hausdorff << '\n';
        std::cout << (report.collision_free ? "collision-free" : "NOT collision-free") << '\n';
        return report.collision_free ? EXIT_SUCCESS : EXIT_FAILURE;
    } catch (const std::exception& e) {
        std::cerr << "strata_example: " << e.what() << '\n';
        return 1;
    }
}
