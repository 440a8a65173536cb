// Fuzz target: the pipeline. A small scene (a generated family, perturbed, or random
// polylines on a coarse grid; scales 1e-3..1e3, offsets to 1e6) and random parameters go
// through untangle (when the input crosses) and simplify, as `strata simplify` does. Oracles:
// - no crash, no exception but InvalidInput for a scene the constructor refuses;
// - an output reported collision-free passes the independent exact check (never a tangled
//   output called clean);
// - simplify of a clean input (no crossing, nesting kept, gaps >= (1 - tol) x required) is
//   clean: a removal that cannot be made clean is refused, its vertex kept, and counted;
// - an untangling cancelled by its progress callback leaves the scene as it was.
// With STRATA_FUZZ_ROUNDS=N (fuzz/run_fuzzers.sh sets 30), the untangling is cancelled after N
// rounds (calls of its progress callback): a hopeless input (a random scribble) otherwise spends
// a minute and more under ASan in failing tries, and a 30 s run never gets past the seeds. The
// replay tests run without a cap.
#include "byte_reader.h"
#include "check.h"
#include "strata/core/error.h"
#include "strata/geometry/checks.h"
#include "strata/io/json_io.h"
#include "strata/simplify/scene_families.h"
#include "strata/simplify/simplify.h"
#include "strata/untangle/untangle.h"

#include <tbb/global_control.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace {

using strata::fuzz::ByteReader;

// STRATA_FUZZ_ROUNDS, 0 when unset (no cap).
std::size_t round_cap() {
    static const std::size_t cap = [] {
        const char* text = std::getenv("STRATA_FUZZ_ROUNDS");
        const long value = text != nullptr ? std::atol(text) : 0;
        return value > 0 ? static_cast<std::size_t>(value) : std::size_t{0};
    }();
    return cap;
}

bool same_points(const strata::Scene& a, const strata::Scene& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t l = 0; l < a.size(); ++l)
        if (a.layer(l).points != b.layer(l).points) return false;
    return true;
}

double power_of_ten(ByteReader& in) {
    static const double scales[] = {1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3};
    return scales[in.range(0, 6)];
}

double offset(ByteReader& in) {
    static const double offsets[] = {0.0, 0.0, 1.0, -37.5, 1e3, 1e5, -1e6, 1e6};
    return offsets[in.range(0, 7)];
}

std::optional<strata::Scene> family_scene(ByteReader& in) {
    const auto families = strata::all_scene_families();
    strata::FamilyParams fp;
    fp.layers = in.range(2, 4);
    fp.points = in.range(8, 40);
    fp.gap = 0.5 + 4.0 * in.unit();
    fp.scale = power_of_ten(in);
    fp.offset = strata::Vec2(offset(in), offset(in));
    strata::Scene scene;
    try {
        scene = strata::make_scene(families[in.range(0, families.size() - 1)], fp);
    } catch (const strata::InvalidInput&) {
        return std::nullopt;  // e.g. too few points for a fold of that many layers
    }
    // Nudge a few vertices (this may tangle the scene, which is then untangled first).
    const std::size_t nudges = in.range(0, 3);
    const double step = fp.gap * fp.scale;
    for (std::size_t k = 0; k < nudges && !scene.empty(); ++k) {
        const std::size_t l = in.range(0, scene.size() - 1);
        std::vector<strata::Vec2> points = scene.layer(l).points;
        strata::Vec2& p = points[in.range(0, points.size() - 1)];
        p.x += step * (static_cast<double>(in.byte()) - 128.0) / 32.0;
        p.y += step * (static_cast<double>(in.byte()) - 128.0) / 32.0;
        try {
            scene.set_points(l, std::move(points));
        } catch (const strata::InvalidInput&) {
        }
    }
    return scene;
}

std::optional<strata::Scene> random_scene(ByteReader& in) {
    const double scale = power_of_ten(in);
    const strata::Vec2 shift(offset(in), offset(in));
    const std::size_t count = in.range(1, 4);
    const bool linked = in.boolean();
    std::vector<strata::Layer> layers;
    for (std::size_t l = 0; l < count; ++l) {
        strata::Layer layer;
        layer.name = "l" + std::to_string(l);
        layer.closed = in.boolean();
        const std::size_t n = in.range(layer.closed ? 3 : 2, 20);
        for (std::size_t k = 0; k < n; ++k) {
            const double x = (static_cast<double>(in.byte()) - 128.0) / 8.0;
            const double y = (static_cast<double>(in.byte()) - 128.0) / 8.0;
            layer.points.emplace_back(shift.x + scale * x, shift.y + scale * y);
        }
        layer.thickness = in.byte() % 3 == 0 ? 0.0 : scale * in.unit() * 0.5;
        layer.weight = 0.25 + 2.0 * in.unit();
        if (linked) {
            // Links only to later layers: no cycle.
            std::vector<std::string> outer;
            for (std::size_t o = l + 1; o < count; ++o)
                if (in.boolean()) outer.push_back("l" + std::to_string(o));
            layer.outer = outer;
        }
        layers.push_back(std::move(layer));
    }
    try {
        return strata::Scene(std::move(layers));
    } catch (const strata::InvalidInput&) {
        return std::nullopt;
    }
}

// The exact check the way simplify() and untangle() judge their output. `input_sides`: the
// sides recorded in the scene it came from, renumbered to its vertices (simplify()), or
// nullptr (the global order: untangle()).
strata::CheckReport exact_check(const strata::Scene& scene, const std::vector<int>& sides,
                                double tolerance, const strata::InputSides* input_sides = nullptr) {
    strata::CheckParams cp;
    cp.separation_tolerance = tolerance;
    cp.outside_sides = sides;
    cp.input_sides = input_sides;
    return strata::check_scene(scene, cp);
}

bool clean(const strata::CheckReport& r) {
    return r.is_collision_free() && r.separations_hold();
}

// Valid scenes and parameters that simplify() and untangle() refuse with InvalidInput, an error
// and not a crash (the CLI prints it and exits 2). Known: the indexed field refuses a layer
// whose coordinates exceed 1e9 buckets of its segment length, counted from the origin, not
// from the layer (a layer of scale 1e-3 at offset 1e6; found by fuzz_pipeline, see
// fuzz/regressions/pipeline). Anything else is a failure.
int known_refusal(const strata::InvalidInput& e) {
    const std::string what = e.what();
    if (what.find("too large for the bucket size") != std::string::npos) return 0;
    std::fprintf(stderr, "refused: %s\n", e.what());
    FUZZ_CHECK(false, "simplify or untangle refused a valid scene and valid parameters");
    return 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    ByteReader in(data, size);
    std::optional<strata::Scene> built = in.boolean() ? family_scene(in) : random_scene(in);
    if (!built) return 0;
    strata::Scene scene = std::move(*built);

    strata::SimplifyParams params;
    static const char* const decimators[] = {"random", "visvalingam", "max-error"};
    params.decimator = decimators[in.range(0, 2)];
    params.remove = in.unit();
    params.keep = in.byte() % 4 == 0 ? in.range(2, 6) : 0;
    params.max_error = in.byte() % 4 == 0 ? in.unit() * scene.bounds().size().x * 0.1 : 0.0;
    params.seed = in.byte();
    params.schedule =
        in.boolean() ? strata::UntangleSchedule::Deferred : strata::UntangleSchedule::Immediate;
    params.batch = in.range(1, 16);
    params.n_out = in.range(1, 8);
    params.global = in.byte() % 8 == 0;
    params.keep_input_gaps = in.boolean() ? 0.9 : in.unit();
    params.untangling.max_passes = static_cast<int>(in.range(1, 16));
    params.untangling.gradient_steps = static_cast<int>(in.range(1, 10));
    params.untangling.finish_separations = in.byte() % 4 != 0;
    if (in.byte() % 4 == 0) params.untangling.shape = strata::ShapeMode::None;
    const double tolerance = params.untangling.separation_tolerance;

    // An input that crosses is untangled first (the CLI's --input-crossings untangle).
    const std::vector<int> input_sides = strata::outside_sides(scene);
    if (!strata::check_scene(scene).is_collision_free()) {
        strata::UntangleParams u;
        u.max_passes = static_cast<int>(in.range(1, 8));
        u.max_rounds = static_cast<int>(in.range(1, 4));
        u.gradient_steps = static_cast<int>(in.range(1, 10));
        u.finish_separations = in.byte() % 4 != 0;
        const strata::Scene tangled = scene;
        strata::UntangleReport ur;
        strata::InputSides inferred;  // the sides it kept, when it kept inferred ones
        std::size_t rounds = 0;
        const strata::ProgressFn capped = [&](std::string_view, double) {
            return round_cap() == 0 || ++rounds <= round_cap();
        };
        try {
            ur = strata::untangle_inferring_sides(scene, u, capped, &inferred);  // as the CLI
        } catch (const strata::InvalidInput& e) {
            return known_refusal(e);
        } catch (const strata::Cancelled&) {
            FUZZ_CHECK(same_points(scene, tangled), "a cancelled untangle changed the scene");
            return 0;
        }
        // Judged as it judged itself: the global order, or the sides inferred per region of
        // the tangled scene where it kept those.
        const strata::CheckReport after =
            ur.inferred_sides ? exact_check(scene, strata::outside_sides(tangled),
                                            u.separation_tolerance, &inferred)
                              : exact_check(scene, input_sides, u.separation_tolerance);
        if (ur.collision_free) FUZZ_CHECK(clean(after), "untangle called a tangled output clean");
        if (!after.is_collision_free()) return 0;  // refused, as the CLI does
    }

    const strata::Scene input = scene;
    const std::vector<int> sides = strata::outside_sides(input);
    // The input is the reference of the sides of open layers (a rolled part stays rolled).
    const strata::InputSides recorded = strata::record_input_sides(input);
    const bool input_clean = clean(exact_check(input, sides, tolerance, &recorded));
    strata::SimplifyReport report;
    try {
        report = strata::simplify(scene, params);
    } catch (const strata::InvalidInput& e) {
        return known_refusal(e);
    }
    const strata::InputSides kept = recorded.renumbered(report.origins);
    const strata::CheckReport after = exact_check(scene, sides, tolerance, &kept);
    if (report.collision_free) FUZZ_CHECK(clean(after), "simplify called a tangled output clean");
    FUZZ_CHECK(scene.size() == input.size(), "simplify changed the layer count");
    if (params.untangle && input_clean) {
        if (!clean(after) && std::getenv("STRATA_FUZZ_DUMP")) {
            // Reproduction: the input scene, for `strata simplify` and `strata check`.
            std::FILE* f = std::fopen(std::getenv("STRATA_FUZZ_DUMP"), "w");
            if (f) {
                const std::string json = strata::scene_to_json(input);
                std::fwrite(json.data(), 1, json.size(), f);
                std::fclose(f);
            }
            std::fprintf(
                stderr,
                "decimator %s remove %g keep %zu max_error %g seed %llu "
                "schedule %s batch %zu n_out %zu global %d keep_gaps %g passes %d "
                "steps %d finish %d\n",
                params.decimator.c_str(), params.remove, params.keep, params.max_error,
                static_cast<unsigned long long>(params.seed),
                params.schedule == strata::UntangleSchedule::Deferred ? "deferred" : "immediate",
                params.batch, params.n_out, params.global ? 1 : 0, params.keep_input_gaps,
                params.untangling.max_passes, params.untangling.gradient_steps,
                params.untangling.finish_separations ? 1 : 0);
            for (const strata::NestingViolation& v : after.nesting_violations)
                std::fprintf(stderr, "nesting: layer %zu vertex %zu vs layer %zu (%s)\n", v.layer,
                             v.vertex, v.other, input.layer(v.other).closed ? "closed" : "open");
        }
        if (!clean(after))
            std::fprintf(stderr,
                         "crossings %zu, self %zu, nesting %zu, separation violations %zu, "
                         "min ratio %g; refused %zu\n",
                         after.crossing_count, after.total_self_crossings(),
                         after.nesting_violation_count, after.separation_violation_count,
                         after.min_separation_ratio, report.refused);
        FUZZ_CHECK(clean(after), "simplify made a clean input tangled");
    }
    return 0;
}
