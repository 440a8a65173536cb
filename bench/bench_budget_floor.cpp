// strata_bench_budget_floor: is a layer that simplify() leaves above its target at a floor?
// Simplifies each scene with the open layers' ends kept (SimplifyParams::trim_ends off); then,
// for every layer left above its target, holding the rest of the output fixed, tries every
// subset of that layer's input vertices (at their input places, in order) of fewer vertices
// than it kept, and counts those that pass simplify()'s own final check (check_scene() with the
// gap rule's separations, the input's outside sides and local sides, the same tolerance).
// With `ends` the subsets keep both ends of an open layer (what simplify() does without
// trim_ends); with `any` they need not. A layer none of whose subsets pass is at a floor for
// the vertices it may keep there (moving them, or the other layers, is not searched).
//
//   strata_bench_budget_floor [--remove R] [--max N] SCENE...
//
// Prints one row per layer left above its target. Inputs that already cross are skipped.
#include "strata/geometry/checks.h"
#include "strata/geometry/input_gaps.h"
#include "strata/geometry/input_sides.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

using namespace strata;

namespace {

struct Count {
    std::size_t tried = 0, passed = 0;
    std::size_t best = 0;  // fewest vertices among the passing subsets (0: none)
};

// Every subset of layer l's input vertices with between `lo` and `hi` vertices (both ends kept
// when `keep_ends`), the other layers as in `out`, checked as simplify() checks; at most `max`.
Count search(const Scene& checked_input, const Scene& out, const SimplifyReport& report,
             std::size_t l, std::size_t lo, std::size_t hi, bool keep_ends, const CheckParams& base,
             const InputSides& sides, std::size_t max) {
    Count count;
    const Layer& in = checked_input.layer(l);
    const std::size_t n = in.points.size();
    for (std::size_t size = lo; size <= hi && count.tried < max; ++size) {
        // Choose `size` of the n ids in order, as a bitmask walk over combinations.
        std::vector<std::size_t> pick(size);
        for (std::size_t i = 0; i < size; ++i) pick[i] = i;
        for (;;) {
            const bool ends_ok =
                !keep_ends || in.closed || (pick.front() == 0 && pick.back() == n - 1);
            if (ends_ok) {
                std::vector<Layer> layers = out.layers();
                layers[l].points.clear();
                for (std::size_t id : pick) layers[l].points.push_back(in.points[id]);
                Scene scene(std::move(layers), checked_input.units());
                for (const Scene::RaisedSeparation& r : checked_input.raised_separations())
                    scene.raise_required_separation(r.a, r.b, r.value);
                std::vector<std::vector<std::size_t>> origins = report.origins;
                origins[l] = pick;
                if (scene.layer(l).points.size() == pick.size()) {
                    const InputSides renumbered = sides.renumbered(origins);
                    CheckParams params = base;
                    params.input_sides = &renumbered;
                    const CheckReport check = check_scene(scene, params);
                    ++count.tried;
                    if (check.is_collision_free() && check.separations_hold()) {
                        ++count.passed;
                        if (count.best == 0 || size < count.best) count.best = size;
                    }
                }
                if (count.tried >= max) break;
            }
            // Next combination.
            std::size_t i = size;
            while (i > 0 && pick[i - 1] == n - size + i - 1) --i;
            if (i == 0) break;
            ++pick[i - 1];
            for (std::size_t j = i; j < size; ++j) pick[j] = pick[j - 1] + 1;
        }
    }
    return count;
}

}  // namespace

int main(int argc, char** argv) {
    double remove = 0.9;
    std::size_t max = 20000;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--remove" && i + 1 < argc) {
            remove = std::atof(argv[++i]);
        } else if (a == "--max" && i + 1 < argc) {
            max = static_cast<std::size_t>(std::atoll(argv[++i]));
        } else {
            files.push_back(a);
        }
    }
    std::printf("%-34s %-8s %6s %6s %5s | %-22s | %-22s\n", "scene", "layer", "input", "target",
                "kept", "ends kept: tried/pass", "ends free: tried/pass");
    for (const std::string& file : files) {
        try {
            const Scene input = read_scene(file);
            if (!check_scene(input).is_collision_free()) {
                std::printf("%-34s input crosses: skipped\n", file.c_str());
                continue;
            }
            SimplifyParams params;
            params.remove = remove;
            params.trim_ends = false;
            Scene out = input;
            const SimplifyReport report = simplify(out, params);
            // simplify()'s final check: the gap rule on a copy of the input, its sides.
            Scene checked_input = input;
            InputGapParams gaps;
            gaps.fraction = std::min(
                1.0, params.keep_input_gaps / (1.0 - params.untangling.separation_tolerance));
            keep_input_gaps(checked_input, gaps);
            CheckParams base;
            base.separation_tolerance = params.untangling.separation_tolerance;
            base.outside_sides = outside_sides(checked_input);
            const InputSides sides = record_input_sides(checked_input);
            const std::string name = file.substr(file.find_last_of('/') + 1);
            for (std::size_t l = 0; l < out.size(); ++l) {
                const LayerSimplifyReport& r = report.layers[l];
                if (r.after <= r.target) continue;
                const std::size_t floor = out.layer(l).closed ? 3 : 2;
                const Count ends = search(checked_input, out, report, l, floor, r.after - 1, true,
                                          base, sides, max);
                const Count any = search(checked_input, out, report, l, floor, r.after - 1, false,
                                         base, sides, max);
                std::printf(
                    "%-34s %-8s %6zu %6zu %5zu | %9zu / %-4zu (%2zu) | %9zu / %-4zu (%2zu)\n",
                    name.c_str(), r.name.c_str(), r.before, r.target, r.after, ends.tried,
                    ends.passed, ends.best, any.tried, any.passed, any.best);
            }
        } catch (const std::exception& e) {
            std::printf("%-34s error: %s\n", file.c_str(), e.what());
        }
    }
    return 0;
}
