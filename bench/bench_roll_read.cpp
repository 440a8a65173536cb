// strata_bench_roll_read: does a tangled scene still show the original's rolls?
// For a scene decimated naively from ORIGINAL (what `strata simplify --no-untangle` writes:
// its vertices are the original's), compares the sides `strata untangle` infers from TANGLED
// alone (infer_input_sides() with untangling_outside_sides()) with the original's sides at
// the same vertices (InputSides::matched(), as `strata check --reference` takes them). A
// rolled vertex is one whose original side of an open layer is not the global order's. The
// roll is "read" when the outside sides agree with the original's and every rolled vertex is
// inferred on its original side: the roll is still a region of the tangled scene (issue 19's
// "scenes where the roll is a connected region"); otherwise the decimation cut it.
//
//   strata_bench_roll_read ORIGINAL TANGLED...
//
// Prints one line per TANGLED: "read" or "cut", then the rolled vertices, how many were
// inferred on their side, on the other side and with none, and the vertices with a side in
// both whose sides differ.
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/scene_io.h"
#include "strata/untangle/outside_sides.h"

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

using namespace strata;

namespace {

// Throws InvalidInput naming `path` unless `scene` has `original`'s layers, by name, in order
// (the sides are compared layer index by layer index).
void require_same_layers(const Scene& original, const Scene& scene, const std::string& path) {
    bool same = original.size() == scene.size();
    for (std::size_t l = 0; same && l < scene.size(); ++l)
        same = original.layer(l).name == scene.layer(l).name;
    if (!same) throw InvalidInput(path + ": its layers are not the original's, by name, in order");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: strata_bench_roll_read ORIGINAL TANGLED...\n");
        return 2;
    }
    try {
        const Scene original = read_scene(argv[1]);
        const std::vector<int> outside = outside_sides(original);
        const InputSides recorded = record_input_sides(original);
        for (int i = 2; i < argc; ++i) {
            const Scene tangled = read_scene(argv[i]);
            require_same_layers(original, tangled, argv[i]);
            const InputSides wanted = InputSides::matched(recorded, original, tangled);
            const std::vector<int> read_outside = untangling_outside_sides(tangled);
            const InputSides inferred = infer_input_sides(tangled, {}, read_outside);
            std::size_t rolled = 0, kept = 0, other = 0, none = 0, differ = 0;
            for (std::size_t a = 0; a < tangled.size(); ++a)
                for (std::size_t b = 0; b < tangled.size(); ++b) {
                    if (a == b) continue;
                    const int global = global_side(original.relation(a, b), outside[b]);
                    for (std::size_t k = 0; k < tangled.layer(a).points.size(); ++k) {
                        const int want = wanted.side(a, k, b), got = inferred.side(a, k, b);
                        if (want != 0 && got != 0 && want != got) ++differ;
                        if (want == 0 || global == 0 || want == global) continue;
                        ++rolled;
                        ++(got == want ? kept : got == 0 ? none : other);
                    }
                }
            const bool read = read_outside == outside && kept == rolled;
            std::printf("%s %s rolled %zu kept %zu other %zu none %zu differ %zu\n", argv[i],
                        read ? "read" : "cut", rolled, kept, other, none, differ);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "strata_bench_roll_read: %s\n", e.what());
        return 2;
    }
    return 0;
}
