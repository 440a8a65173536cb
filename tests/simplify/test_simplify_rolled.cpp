// Rolled layers (issue 19): an inner layer that comes around the end of the outer one and lies
// on top of it. The input's own sides are the order to keep there (input_sides.h).
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "strata/simplify/scene_families.h"
#include "strata/simplify/simplify.h"
#include "support/fixtures.h"
#include "support/require.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

using namespace strata;

namespace {

std::vector<std::vector<std::size_t>> identity(const Scene& scene) {
    std::vector<std::vector<std::size_t>> ids;
    for (const Layer& layer : scene.layers()) {
        ids.emplace_back(layer.points.size());
        std::iota(ids.back().begin(), ids.back().end(), std::size_t{0});
    }
    return ids;
}

// Gap between the layers of a rolled scene, scene units (scene_families.cpp).
double rolled_gap(const FamilyParams& p) {
    return p.gap * 10.0 / static_cast<double>(p.points - 1);
}

// simplify() of a rolled input, and the exact check of its output against the input's sides.
struct Simplified {
    Scene out;
    SimplifyReport report;
    CheckReport check;
};

// simplify() of `input` with these settings: reported collision-free, and checked here again,
// independently of simplify()'s own check, against the input's sides (`sides`,
// record_input_sides(input); `outside`, outside_sides(input)): no crossing, the sides kept,
// gaps >= 0.9 x required.
Simplified simplify_keeping_sides(const Scene& input, const std::vector<int>& outside,
                                  const InputSides& sides, const char* decimator, double remove,
                                  UntangleSchedule schedule) {
    SimplifyParams params;
    params.decimator = decimator;
    params.remove = remove;
    params.schedule = schedule;
    Simplified r{input, {}, {}};
    r.report = simplify(r.out, params);
    CHECK(r.report.collision_free);
    const InputSides out_sides = sides.renumbered(r.report.origins);
    r.check =
        test::check_with_sides(r.out, outside, params.untangling.separation_tolerance, &out_sides);
    test::require_sides_kept(r.check, 0.9);
    return r;
}

}  // namespace

TEST_CASE("the input's sides record the roll; a vertex that changes side is flagged", "[rolled]") {
    for (double gap : {1.0, 2.0, 4.0}) {
        INFO("gap " << gap);
        FamilyParams params;
        params.points = 300;
        params.gap = gap;
        const Scene scene = make_scene(SceneFamily::Rolled, params);
        const InputSides sides = record_input_sides(scene);
        const std::vector<int> outside = outside_sides(scene);
        // Inner (0) under outer (1); the roll's top part lies over the outer layer.
        CHECK(sides.rolled_count(scene, outside) > 0);

        CheckParams cp;
        cp.outside_sides = outside;
        const InputSides own = sides.renumbered(identity(scene));
        cp.input_sides = &own;
        const CheckReport against_itself = check_scene(scene, cp);
        CHECK(against_itself.crossing_count == 0);
        CHECK(against_itself.nesting_violation_count == 0);

        // The roll's top part moved under the inner's own base: those vertices left the side
        // of the outer layer the input gives them (the segments joining them to the roll's
        // arc cross too; what is checked here is the nesting).
        std::vector<Layer> layers = scene.layers();
        const double g = rolled_gap(params);
        std::size_t moved = 0;
        for (Vec2& p : layers[0].points)
            if (p.y > 2.5 * g && p.x < 8.0) {
                p.y = -2.0 * g;  // under the inner's own base: the order of the input is lost
                ++moved;
            }
        REQUIRE(moved > 0);
        const Scene flipped(layers);
        const CheckReport changed = check_scene(flipped, cp);
        CHECK(changed.nesting_violation_count > 0);
    }
}

TEST_CASE("simplify keeps a roll: clean, gaps, sides, budget and shape", "[rolled]") {
    const char* const decimators[] = {"random", "visvalingam", "max-error"};
    for (double gap : {2.0, 4.0}) {
        FamilyParams fp;
        fp.points = 600;
        fp.gap = gap;
        const Scene input = make_scene(SceneFamily::Rolled, fp);
        const double g = rolled_gap(fp);
        const std::vector<int> outside = outside_sides(input);
        const InputSides sides = record_input_sides(input);
        REQUIRE(sides.rolled_count(input, outside) > 0);
        for (const char* decimator : decimators)
            for (double remove : {0.9, 0.95})
                for (UntangleSchedule schedule :
                     {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                    INFO("gap " << gap << " " << decimator << " remove " << remove
                                << (schedule == UntangleSchedule::Deferred ? " deferred"
                                                                           : " immediate"));
                    const Simplified s =
                        simplify_keeping_sides(input, outside, sides, decimator, remove, schedule);
                    const Scene& out = s.out;
                    const SimplifyReport& report = s.report;
                    // The rolled layer meets its budget. (The outer one is a straight line:
                    // its collinear removals are refused the same way without the roll, a
                    // weakness of the driver's local test, not of the sides.)
                    // Budget and shape below: asked of the error-driven decimators with the
                    // default, deferred schedule. The immediate schedule stays clean but
                    // refuses most removals of the rolled layer (measured at 600 points, gap
                    // 2: 577 vertices left for a target of 79, Hausdorff 0.12 to 0.34).
                    const bool shape_asked = std::string(decimator) != "random" &&
                                             schedule == UntangleSchedule::Deferred;
                    if (shape_asked) CHECK(report.layers[0].after <= report.layers[0].target);
                    CHECK(report.rolled_vertices > 0);
                    CHECK(s.check.separation_violation_count == 0);
                    // The shape: within 2 gaps of the input. Not asked of the random
                    // decimator, which may remove the whole bend of the roll and leave the
                    // untangling to pull the layer around the end of the other one (measured:
                    // Hausdorff 0.75 = 22 gaps on gap 2, clean; README, what is missing).
                    if (shape_asked)
                        for (std::size_t l = 0; l < out.size(); ++l)
                            CHECK(hausdorff(out.layer(l), input.layer(l), 1e-6 * g).symmetric() <=
                                  2.0 * g);
                    // The roll is kept: the top of the roll (input y = 3 gaps, over the outer
                    // layer at y = gap) stays over the outer layer.
                    const Layer& inner = out.layer(0);
                    for (std::size_t k = 0; k < inner.points.size(); ++k) {
                        const Vec2 was = input.layer(0).points[report.origins[0][k]];
                        if (was.y > 2.5 * g && was.x < 8.0) CHECK(inner.points[k].y > 1.5 * g);
                    }
                }
    }
}

namespace {

// simplify() on `input` at the given settings: clean, the input's sides kept, gaps >= 0.9 x
// required, every layer on target, Hausdorff <= 2 x `gap`.
void check_kept(const Scene& input, double gap, const char* decimator, double remove,
                UntangleSchedule schedule) {
    const Simplified s = simplify_keeping_sides(
        input, outside_sides(input), record_input_sides(input), decimator, remove, schedule);
    const Scene& out = s.out;
    CHECK(s.report.targets_met);
    for (std::size_t l = 0; l < out.size(); ++l)
        CHECK(hausdorff(out.layer(l), input.layer(l), 1e-6 * gap).symmetric() <= 2.0 * gap);
}

}  // namespace

TEST_CASE("a wavy roll meets every target with both schedules", "[rolled]") {
    for (double gap : {2.0, 4.0}) {
        const Scene input = test::wavy_roll(600, gap);
        const double g = gap * 10.0 / 599.0;
        const std::vector<int> outside = outside_sides(input);
        const InputSides sides = record_input_sides(input);
        REQUIRE(sides.rolled_count(input, outside) > 0);
        for (const char* decimator : {"visvalingam", "max-error"})
            for (double remove : {0.9, 0.95})
                for (UntangleSchedule schedule :
                     {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                    INFO("gap " << gap << " " << decimator << " remove " << remove
                                << (schedule == UntangleSchedule::Deferred ? " deferred"
                                                                           : " immediate"));
                    check_kept(input, g, decimator, remove, schedule);
                }
    }
}

TEST_CASE("both layers rolled together, and a shirt rolled over a jacket on a body", "[rolled]") {
    const Scene together = test::both_rolled(600, 4.0);
    const Scene shirt = test::shirt_rolled_over_jacket(600, 4.0);
    {
        const CheckReport in = check_scene(together);
        REQUIRE(in.crossing_count == 0);
        REQUIRE(in.total_self_crossings() == 0);
        const CheckReport in2 = check_scene(shirt);
        REQUIRE(in2.crossing_count == 0);
        REQUIRE(in2.total_self_crossings() == 0);
        // The shirt's top lies over the jacket: the global order is broken there.
        CHECK(record_input_sides(shirt).rolled_count(shirt, outside_sides(shirt)) > 0);
    }
    for (const char* decimator : {"visvalingam", "max-error"})
        for (double remove : {0.9, 0.95})
            for (UntangleSchedule schedule :
                 {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                INFO(decimator << " remove " << remove
                               << (schedule == UntangleSchedule::Deferred ? " deferred"
                                                                          : " immediate"));
                {
                    INFO("both rolled");
                    check_kept(together, 4.0 * 10.0 / 599.0, decimator, remove, schedule);
                }
                {
                    INFO("shirt over jacket");
                    check_kept(shirt, 4.0 * 2.0 * 3.14159265358979323846 / 600.0, decimator, remove,
                               schedule);
                }
            }
}

TEST_CASE("a collar folded around a closed cord keeps the cord in the fold", "[rolled]") {
    constexpr double kPi = 3.14159265358979323846;
    for (double gap : {2.0, 4.0}) {
        const Scene input = test::collar_wrapped_cord(600, gap);
        const double g = gap * 2.0 * kPi / 600.0;
        const std::size_t body = 0, cord = 1, collar = 2;
        REQUIRE(input.layer(cord).closed);
        REQUIRE_FALSE(input.layer(collar).closed);
        const std::vector<int> outside = outside_sides(input);
        const InputSides sides = record_input_sides(input);
        {
            // The cord, under the collar, lies on its outside face: the global order calls
            // every one of its vertices near the collar wrong, the input's sides none.
            const CheckReport in = check_scene(input);
            REQUIRE(in.crossing_count == 0);
            REQUIRE(in.total_self_crossings() == 0);
            std::size_t cord_wrong = 0;
            for (const NestingViolation& v : in.nesting_violations) {
                CHECK(v.layer == cord);
                CHECK(v.other == collar);
                cord_wrong += v.layer == cord;
            }
            CHECK(cord_wrong == in.nesting_violation_count);
            CHECK(cord_wrong > input.layer(cord).points.size() / 2);
            CHECK(sides.rolled_count(input, outside) == in.nesting_violation_count);
            const InputSides own = sides.renumbered(identity(input));
            test::require_sides_kept(test::check_with_sides(input, outside, 0.0, &own), 1.0);
        }
        for (const char* decimator : {"random", "visvalingam", "max-error"})
            for (double remove : {0.9, 0.95})
                for (UntangleSchedule schedule :
                     {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                    INFO("gap " << gap << " " << decimator << " remove " << remove
                                << (schedule == UntangleSchedule::Deferred ? " deferred"
                                                                           : " immediate"));
                    if (std::string(decimator) != "random") {
                        check_kept(input, g, decimator, remove, schedule);
                        continue;
                    }
                    // The random decimator: clean with the input's sides kept (its shape and
                    // budget are not asked, as for the other rolled families above).
                    const Simplified s =
                        simplify_keeping_sides(input, outside, sides, decimator, remove, schedule);
                    const Scene& out = s.out;
                    CHECK(s.report.rolled_vertices > 0);
                    // The cord stays in the fold: off the body, between the collar's two parts.
                    for (const Vec2& p : out.layer(cord).points) {
                        const double r = std::hypot(p.x, p.y);
                        CHECK(r > 1.0 + 1.0 * g);
                        CHECK(r < 1.0 + 4.0 * g);
                    }
                    CHECK(out.layer(body).points.size() >= 3);
                }
    }
}

TEST_CASE("the random decimator's shape error is the decimation's, not the roll's", "[rolled]") {
    // Each rolled family against its unrolled counterpart (same layers and vertex counts, the
    // global order kept), decimated at random with the same seed: the roll adds at most 2 gaps
    // to the Hausdorff distance (measured at 600 points: the same or less, README).
    for (SceneFamily family : all_scene_families()) {
        if (!is_rolled(family)) continue;
        FamilyParams fp;
        fp.points = 600;
        const Scene rolled = make_scene(family, fp);
        fp.unrolled = true;
        const Scene unrolled = make_scene(family, fp);
        const double g = 2.0 * rolled.layer(0).thickness;  // every family: layer 0 half a gap
        for (double remove : {0.9, 0.95})
            for (UntangleSchedule schedule :
                 {UntangleSchedule::Deferred, UntangleSchedule::Immediate}) {
                INFO(family_name(family)
                     << " remove " << remove
                     << (schedule == UntangleSchedule::Deferred ? " deferred" : " immediate"));
                SimplifyParams params;
                params.decimator = "random";
                params.remove = remove;
                params.schedule = schedule;
                double h[2] = {0.0, 0.0};
                for (int k = 0; k < 2; ++k) {
                    const Scene& input = k == 0 ? rolled : unrolled;
                    Scene out = input;
                    const SimplifyReport report = simplify(out, params);
                    CHECK(report.collision_free);
                    CHECK(report.targets_met);
                    for (std::size_t l = 0; l < out.size(); ++l)
                        h[k] = std::max(
                            h[k], hausdorff(out.layer(l), input.layer(l), 1e-6 * g).symmetric());
                }
                CHECK(h[0] <= h[1] + 2.0 * g);
            }
    }
}

TEST_CASE("sides matched by nearest vertex (strata check --reference) judge a simplified roll",
          "[rolled]") {
    FamilyParams fp;
    fp.points = 400;
    fp.gap = 2.0;
    const Scene input = make_scene(SceneFamily::Rolled, fp);
    const double g = rolled_gap(fp);
    const InputSides recorded = record_input_sides(input);
    SimplifyParams params;
    params.remove = 0.9;
    Scene out = input;
    const SimplifyReport report = simplify(out, params);
    REQUIRE(report.collision_free);

    CheckParams cp;
    cp.outside_sides = outside_sides(input);
    cp.separation_tolerance = params.untangling.separation_tolerance;
    // Without the vertex correspondence, as the CLI has it: the same verdict as simplify()'s.
    const InputSides matched = InputSides::matched(recorded, input, out);
    cp.input_sides = &matched;
    CHECK(check_scene(out, cp).nesting_violation_count == 0);
    // The global order alone calls the roll wrong.
    cp.input_sides = nullptr;
    CHECK(check_scene(out, cp).nesting_violation_count > 0);

    // The roll's top pushed under the outer layer, between the two layers (crossing it): the
    // outer layer's vertices there now lie on the other side of the inner layer's nearest
    // part than in the reference, which the matched sides find. Done on the input, whose
    // outer layer has vertices over that stretch (the simplified one keeps none on its
    // straight stretches).
    std::vector<Layer> layers = input.layers();
    std::size_t moved = 0;
    for (Vec2& p : layers[0].points)
        if (p.y > 2.5 * g && p.x < 7.5 && p.x > 5.5) {
            p.y = 0.5 * g;
            ++moved;
        }
    REQUIRE(moved > 0);
    const Scene pushed(layers);
    const InputSides matched_pushed = InputSides::matched(recorded, input, pushed);
    cp.input_sides = &matched_pushed;
    CHECK(check_scene(pushed, cp).nesting_violation_count > 0);
}

namespace {

// An open layer `name` through `points`.
Layer open_layer(const char* name, std::vector<Vec2> points) {
    Layer layer;
    layer.name = name;
    layer.points = std::move(points);
    return layer;
}

// A rolled around the end of B (y = 1, x from -1 to 9): its lower sheet (y = 0) under B, a
// bend at (11, 1), its upper sheet (y = 2) over B back to x = 5. The reference of the first
// two tests of InputSides::matched() below.
Scene roll_around_end() {
    return Scene({open_layer("a", {{0, 0},
                                   {2, 0},
                                   {4, 0},
                                   {6, 0},
                                   {8, 0},
                                   {10, 0},
                                   {11, 1},
                                   {10, 2},
                                   {9, 2},
                                   {8, 2},
                                   {7, 2},
                                   {6, 2},
                                   {5, 2}}),
                  open_layer("b", {{-1, 1}, {1, 1}, {3, 1}, {5, 1}, {7, 1}, {9, 1}})});
}

// check_scene() of `out` by the sides recorded in `reference` carried onto it without the
// vertex correspondence (InputSides::matched(), as `strata check --reference` does), and by
// the reference's outside sides.
CheckReport check_matched(const Scene& out, const Scene& reference) {
    const InputSides matched = InputSides::matched(record_input_sides(reference), reference, out);
    CheckParams cp;
    cp.outside_sides = outside_sides(reference);
    cp.input_sides = &matched;
    return check_scene(out, cp);
}

}  // namespace

TEST_CASE("sides matched without the correspondence keep a moved vertex on its own sheet",
          "[rolled]") {
    // A rolled around the end of B: its lower sheet (y = 0) under B (y = 1), its upper sheet
    // (y = 2) over B. In the "output" B moved up to y = 1.8 and a vertex of A's lower sheet
    // followed it to (6, 1.5): still under B, but nearer the upper sheet of the reference
    // (0.5) than its own (1.5). Its unmoved neighbours keep it between theirs (the output of
    // a simplification keeps its vertices' order), on the lower sheet: no violation; moved
    // over B it is one. Before, the nearest segment gave it the upper sheet's side, over B.
    const Scene reference = roll_around_end();
    Layer a_out = open_layer("a", {{0, 0}, {6, 1.5}, {10, 0}, {11, 1}, {10, 2}, {5, 2}});
    const Layer b_out = open_layer("b", {{-1, 1.8}, {9, 1.8}});
    const CheckReport ok = check_matched(Scene({a_out, b_out}), reference);
    CHECK(ok.crossing_count == 0);
    CHECK(ok.nesting_violation_count == 0);

    // Over B now (across it): the lower sheet's vertex is on the wrong side.
    a_out.points[1] = {6, 1.9};
    const CheckReport bad = check_matched(Scene({a_out, b_out}), reference);
    CHECK(bad.nesting_violation_count > 0);
}

TEST_CASE("sides matched without the correspondence keep a roll's end on its sheet", "[rolled]") {
    // The reference of the test above. In the "output" B moved down to y = 0.2, A's lower
    // sheet to y = -0.1, its bend and upper sheet a little, and the roll's end to (6, 0.4):
    // still over B, but 4 times nearer the lower sheet's vertex (6, 0) than its own (6, 2),
    // beyond the band of 3 times the nearest that the in-order matching chose from. Every
    // vertex but the first moved, so the run's stretch holds both sheets; the order puts the
    // end after the bend, on the upper sheet: no violation. Before, the upper sheet was no
    // candidate, the nearest match was kept and the end was judged under B (the shirt at 95%,
    // seeds 5 and 13, and at 600 points, seed 2: the roll's end moved toward the main part).
    const Scene reference = roll_around_end();
    Layer a_out = open_layer("a", {{0, 0}, {4, -0.1}, {8, -0.1}, {11.1, 1}, {10, 2.1}, {6, 0.4}});
    const Layer b_out = open_layer("b", {{-1, 0.2}, {8.5, 0.2}});
    const CheckReport ok = check_matched(Scene({a_out, b_out}), reference);
    CHECK(ok.crossing_count == 0);
    CHECK(ok.nesting_violation_count == 0);

    // The roll's end pulled across B, under it: a violation (the nearest match, the lower
    // sheet's side, hid it before).
    a_out.points[5] = {6, 0.1};
    const CheckReport bad = check_matched(Scene({a_out, b_out}), reference);
    CHECK(bad.nesting_violation_count > 0);
}

TEST_CASE("sides matched without the correspondence keep a run moved alike on its sheet",
          "[rolled]") {
    // A rolled around the end of B, densely sampled (0.25): its lower sheet (y = 0) under B
    // (y = 0.5), a half-circle bend around (10, 0.5), its upper sheet (y = 1) back to x = 5.
    // In the "output" B moved up to y = 1.3 and ends at x = 8.9; A's lower sheet followed,
    // its last vertex to (8.75, 0.99), on top of the upper sheet's vertex (8.75, 1), but still
    // under B; its bend is at (9.3, 1.3) around B's end. By distance alone the order can put
    // that vertex on the upper sheet (the bend then matched just after it there), over B: a
    // violation that is not one (the shirt at 95%, seed 8: the engine moved the main part's
    // last vertices 0.1-0.2 outward, onto the roll's place). The vertex moved as its
    // neighbours did, by about (0, 1); matched to the upper sheet it would not have moved.
    Layer a;
    a.name = "a";
    for (int i = 0; i <= 40; ++i) a.points.push_back({0.25 * i, 0.0});
    const double pi = std::acos(-1.0);
    for (int i = 1; i <= 5; ++i)
        a.points.push_back({10 + 0.5 * std::sin(pi * i / 6), 0.5 - 0.5 * std::cos(pi * i / 6)});
    for (int i = 0; i <= 20; ++i) a.points.push_back({10 - 0.25 * i, 1.0});
    Layer b;
    b.name = "b";
    for (int i = 0; i <= 42; ++i) b.points.push_back({-1 + 0.25 * i, 0.5});
    const Scene reference({a, b});
    Layer a_out = a;
    a_out.points = {{0, 0.05}, {6, 0.9}, {7, 0.92}, {8, 0.95}, {8.75, 0.99},
                    {9.3, 1.3}, {7, 1.7},  {5, 1.7}};
    Layer b_out = b;
    b_out.points = {{-1, 1.3}, {8.9, 1.3}};
    const CheckReport ok = check_matched(Scene({a_out, b_out}), reference);
    CHECK(ok.crossing_count == 0);
    CHECK(ok.nesting_violation_count == 0);
}

TEST_CASE("an untangling of rolled vertices that stalls gives up (only there)", "[rolled]") {
    // The shirt rolled over a jacket's end, random decimation, immediate schedule. In the
    // rolled scene at 95% (seed 0) one removal cannot be untangled: its job holds rolled
    // vertices and gives up (from its fifth pass) instead of running all 16 passes. In the
    // counterpart at 90% (seed 1) one removal cannot be untangled either (a shirt chord cut
    // into the body): its job holds no rolled vertex and runs them all. (The rolled scene at
    // 90%, seed 1, keeps that removal: its chord is shifted out of the body, chord_shifts.)
    FamilyParams fp;
    fp.points = 3000;
    const Scene rolled = make_scene(SceneFamily::ShirtRoll, fp);
    fp.unrolled = true;
    const Scene unrolled = make_scene(SceneFamily::ShirtRoll, fp);
    SimplifyParams params;
    params.decimator = "random";
    params.schedule = UntangleSchedule::Immediate;
    for (int k = 0; k < 2; ++k) {
        INFO((k == 0 ? "rolled" : "unrolled"));
        Scene out = k == 0 ? rolled : unrolled;
        params.remove = k == 0 ? 0.95 : 0.9;
        params.seed = k == 0 ? 0 : 1;
        const SimplifyReport report = simplify(out, params);
        CHECK(report.collision_free);
        CHECK(report.targets_met);
        REQUIRE(report.refused >= 1);
        if (k == 0) {
            CHECK(report.gave_up == report.refused);
            CHECK(report.rounds < 16 * static_cast<int>(report.refused));
        } else {
            CHECK(report.gave_up == 0);
            CHECK(report.chord_shifts == 0);  // no rolled job
        }
    }
}

TEST_CASE("a rolled removal whose chord cuts into the fold is kept by shifting the chord",
          "[rolled]") {
    // The collar folded around the cord (300 points, gap 2), random decimation at 95%, seed 8,
    // immediate schedule: removals on the collar's turned-back part have chords that come
    // closer to the cord in the fold than their separation. There is room for them where the
    // collar was: moving a chord's two ends toward the removed vertex keeps its removal with
    // no untangling pass (before, one of them was refused: its untangling gave up after five
    // passes). One untangling there leaves the collar farther from the input than any shape
    // error it had so far, by more than a separation: refused (report.shape_refused). Every shifted
    // removal passed the job's exact check; the output is clean with the input's sides, on budget.
    // The unrolled counterpart has no rolled job: nothing is shifted.
    FamilyParams fp;
    fp.points = 300;
    fp.gap = 2.0;
    for (const bool unrolled : {false, true}) {
        INFO((unrolled ? "unrolled" : "rolled"));
        fp.unrolled = unrolled;
        const Scene input = make_scene(SceneFamily::CollarWrap, fp);
        SimplifyParams params;
        params.decimator = "random";
        params.remove = 0.95;
        params.seed = 8;
        params.schedule = UntangleSchedule::Immediate;
        Scene out = input;
        const SimplifyReport report = simplify(out, params);
        CHECK(report.collision_free);
        CHECK(report.targets_met);
        const std::vector<int> outside = outside_sides(input);
        const InputSides out_sides = record_input_sides(input).renumbered(report.origins);
        test::require_sides_kept(
            test::check_with_sides(out, outside, params.untangling.separation_tolerance,
                                   &out_sides),
            0.9);
        if (unrolled) {
            CHECK(report.chord_shifts == 0);
        } else {
            CHECK(report.chord_shifts >= 1);
            CHECK(report.chord_shifts <= report.untangle_calls);
            // One removal is refused, not for its untangling (none gives up) but for the shape
            // error it would leave (report.shape_refused).
            CHECK(report.refused == report.shape_refused);
            CHECK(report.refused <= 1);
            CHECK(report.gave_up == 0);
        }
    }
}

TEST_CASE("a rolled job's result does not leave the shape farther from the input", "[rolled]") {
    // The shirt rolled over a jacket's end (9,600 points, gap 2), random decimation at 95%,
    // seed 2, immediate schedule. A chord near the roll's tip is shifted (0.30 gap toward its
    // removed vertex); the next removal there, from that start, was untangled by pulling the
    // tip 3.3 gaps out along the body, 2.34 gaps from the input (its counterpart: 2.00, and
    // 1.71 before chord shifts). A rolled job's result (a shift or an untangling) may not
    // leave the shape around its free vertices farther from the input than the removal alone
    // would, or than the largest separation: that untangling is refused, and the output stays
    // within 2 gaps of the input, clean, on budget.
    FamilyParams fp;
    fp.points = 9600;
    fp.gap = 2.0;
    const Scene input = make_scene(SceneFamily::ShirtRoll, fp);
    const double g = 2.0 * input.layer(0).thickness;
    SimplifyParams params;
    params.decimator = "random";
    params.remove = 0.95;
    params.seed = 2;
    params.schedule = UntangleSchedule::Immediate;
    Scene out = input;
    const SimplifyReport report = simplify(out, params);
    CHECK(report.collision_free);
    CHECK(report.targets_met);
    CHECK(report.chord_shifts >= 1);
    CHECK(report.shape_refused >= 1);
    CHECK(report.shape_refused <= report.refused);
    double h = 0.0;
    for (std::size_t l = 0; l < out.size(); ++l)
        h = std::max(h, hausdorff(out.layer(l), input.layer(l), 1e-6 * g).symmetric());
    CHECK(h <= 2.0 * g);
    const std::vector<int> outside = outside_sides(input);
    const InputSides out_sides = record_input_sides(input).renumbered(report.origins);
    test::require_sides_kept(
        test::check_with_sides(out, outside, params.untangling.separation_tolerance, &out_sides),
        0.9);
}
