#include "strata/untangle/untangle.h"

#include "geometry/detail/region_check.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "untangle/detail/engine.h"

#include <tbb/task_group.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace strata {

namespace {

// Throws InvalidInput when params.outside_sides or params.input_sides do not fit `scene`.
void validate_sides(const Scene& scene, const UntangleParams& params) {
    const std::vector<int>& outside = params.outside_sides;
    if (!outside.empty() && outside.size() != scene.size())
        throw InvalidInput("untangle: params.outside_sides has " + std::to_string(outside.size()) +
                           " entries for " + std::to_string(scene.size()) + " layers");
    for (std::size_t i = 0; i < outside.size(); ++i)
        if (!scene.layer(i).closed && outside[i] != 1 && outside[i] != -1)
            throw InvalidInput("untangle: params.outside_sides[" + std::to_string(i) +
                               "] (layer '" + shown_text(scene.layer(i).name) +
                               "') must be +1 or -1 (got " + std::to_string(outside[i]) + ")");
    const InputSides* sides = params.input_sides;
    if (sides && !sides->empty() && sides->size() != scene.size())
        throw InvalidInput("untangle: params.input_sides has " + std::to_string(sides->size()) +
                           " layers for " + std::to_string(scene.size()));
}

// The rolled vertices of `sides` (as InputSides::rolled_count() counts them) that are not
// listed among the nesting violations of `check`.
std::size_t rolled_kept(const Scene& scene, const InputSides& sides,
                        const std::vector<int>& outside_signs, std::size_t rolled,
                        const CheckReport& check) {
    std::size_t lost = 0;
    for (const NestingViolation& v : check.nesting_violations) {
        const int side = sides.side(v.layer, v.vertex, v.other);
        const int wanted = global_side(scene.relation(v.layer, v.other), outside_signs[v.other]);
        if (side != 0 && wanted != 0 && side != wanted) ++lost;
    }
    return rolled - std::min(rolled, lost);
}

// `region`: the vertices that may move (the free vertices of `pieces`) stay in this box, with
// their neighbours, or the check is of the whole scene; the checks then look only near it
// (RegionCheck), with the same verdicts as whole ones. nullptr: whole checks.
UntangleReport run(Scene& scene, const std::vector<Piece>& pieces, const UntangleParams& params,
                   const ProgressFn& progress, bool keep_simple = false,
                   const Box2* region = nullptr) {
    validate(params);
    validate_sides(scene, params);
    UntangleReport report;
    report.tries = 1;
    const Scene original = scene;
    try {
        for (const Piece& piece : pieces)
            report.free_vertices +=
                static_cast<std::size_t>(std::count(piece.is_free.begin(), piece.is_free.end(), 1));
        // Orientation of open layers from the input, where the nesting is the intended one (or
        // from params.outside_sides): what the untangling pushes toward, and what its checks
        // judge by, with the sides given if any (a fresh vote on the result could flip a short
        // layer's outside and call a swapped order clean).
        detail::EngineSettings settings = detail::resolve_settings(scene, params);
        CheckParams check_params;
        check_params.separation_tolerance = params.separation_tolerance;
        check_params.outside_sides = settings.outside_signs;
        // Short passes (UntangleParams' defaults): shape matching pulls toward the input.
        settings.rest_at_start = true;
        settings.keep_simple = keep_simple;
        const bool has_sides = params.input_sides && !params.input_sides->empty();
        check_params.input_sides = has_sides ? params.input_sides : nullptr;
        settings.open_cut_bends = has_sides && params.open_cut_bends;
        // `check`: the last whole check, if any; `counts`: the last check's counts. The check
        // of the input (the reference of the region checks) runs beside the engine's first
        // steps (the fields, the finishing stage, which do not use it); the first verdict
        // waits for it.
        std::optional<RegionCheck> region_check;
        CheckReport check;
        CheckCounts counts;
        tbb::task_group checking;
        bool is_checking = true;
        checking.run([&] {
            if (region)
                check = region_check.emplace(original, check_params, *region).reference_report();
            else
                check = check_scene(original, check_params);
        });
        auto checked = [&] {
            if (!is_checking) return;
            is_checking = false;
            checking.wait();
            counts = counts_of(check);
            report.crossings_before = counts.crossing_count;
        };
        // Waits for the check of the input before leaving (it reads `original`).
        struct Waiter {
            tbb::task_group& group;
            bool& is_running;
            ~Waiter() {
                if (!is_running) return;
                try {
                    group.wait();
                } catch (...) {  // leaving on another exception already
                }
            }
        } waiter{checking, is_checking};
        auto is_ok = [&](const Scene& s) {
            checked();
            if (region_check) {
                counts = region_check->check(s);
            } else {
                check = check_scene(s, check_params);
                counts = counts_of(check);
            }
            return counts.is_collision_free() && counts.separations_hold();
        };
        detail::RelationSource relations;
        relations.scene = &original;
        if (has_sides) {
            detail::take_input_sides(relations, original, *params.input_sides,
                                     settings.outside_signs);
            report.rolled_vertices =
                params.input_sides->rolled_count(original, settings.outside_signs);
        }
        const detail::EngineResult r =
            detail::run_engine(scene, pieces, params, relations, settings, is_ok, progress);
        checked();
        report.passes = r.passes;
        report.rounds = r.rounds;
        report.converged = r.converged;
        report.collision_free = r.ok;
        report.mean_speed = r.mean_speed;
        report.gave_up = r.gave_up;
        report.seconds_fields = r.seconds_fields;
        report.seconds_untangle = r.seconds_untangle;
        report.seconds_check = r.seconds_check;
        report.seconds_finish = r.seconds_finish;
        report.finishes = r.finishes;
        report.finish_moves = r.finish_moves;
        report.crossings_after = counts.crossing_count;
        report.min_separation_ratio_after = counts.min_separation_ratio;
        if (report.rolled_vertices > 0) {
            // The last check judged the final scene; list every violation if it did not (a
            // region check lists none).
            if (region_check || check.nesting_violations.size() < check.nesting_violation_count) {
                check_params.max_listed =
                    std::max(check_params.max_listed, counts.nesting_violation_count);
                check = check_scene(scene, check_params);
            }
            report.rolled_kept = rolled_kept(original, *params.input_sides, settings.outside_signs,
                                             report.rolled_vertices, check);
        }
        for (std::size_t l = 0; l < scene.size(); ++l)
            for (std::size_t v = 0; v < scene.layer(l).points.size(); ++v) {
                const double d =
                    glm::distance(scene.layer(l).points[v], original.layer(l).points[v]);
                report.max_displacement = std::max(report.max_displacement, d);
                if (d > 1e-12 * settings.diagonal) ++report.moved_vertices;
            }
    } catch (...) {
        scene = original;
        throw;
    }
    return report;
}

// Unit tangents of open `layer` at `count` points evenly spaced along its length.
std::vector<Vec2> tangents_along(const Layer& layer, std::size_t count) {
    std::vector<Vec2> out;
    const double total = layer.length();
    if (!(total > 0.0)) return out;
    std::size_t segment = 0;
    double before = 0.0;  // length of the segments before `segment`
    for (std::size_t k = 0; k < count; ++k) {
        const double at = (static_cast<double>(k) + 0.5) / static_cast<double>(count) * total;
        while (segment + 1 < layer.segment_count() &&
               before + glm::distance(layer.segment_start(segment), layer.segment_end(segment)) <
                   at) {
            before += glm::distance(layer.segment_start(segment), layer.segment_end(segment));
            ++segment;
        }
        const Vec2 d = layer.segment_end(segment) - layer.segment_start(segment);
        const double len = glm::length(d);
        out.push_back(len > 0.0 ? d / len : Vec2(0.0));
    }
    return out;
}

// The centroid of the area of closed `layer` (of its polygon; its vertex centroid when the area
// is 0) when it lies inside it (a body, not a band). The area's, not the vertices': a decimation
// that keeps more of a body's vertices on one side moves their centroid toward that side (the
// collar at 95%, seed 28: vertex centroid (-0.39, 0.29), area centroid (-0.09, 0.04), of a
// body of radius 1 centred at the origin), and the collar around it then seems to sweep the
// other way.
std::optional<Vec2> body_centre(const Layer& layer) {
    if (layer.points.empty()) return std::nullopt;
    Vec2 centre(0.0);
    for (const Vec2& p : layer.points) centre += p;
    centre /= static_cast<double>(layer.points.size());
    double area = 0.0;  // twice the signed area
    Vec2 moment(0.0);
    for (std::size_t k = 0, m = layer.points.size(); k < m; ++k) {
        const Vec2 u = layer.points[k] - centre, w = layer.points[(k + 1) % m] - centre;
        const double cross = u.x * w.y - u.y * w.x;
        area += cross;
        moment += cross * (u + w);
    }
    if (area != 0.0) centre += moment / (3.0 * area);
    bool inside = false;
    for (std::size_t k = 0, m = layer.points.size(); k < m; ++k) {
        const Vec2 u = layer.points[k], w = layer.points[(k + 1) % m];
        if ((u.y > centre.y) != (w.y > centre.y) &&
            centre.x < u.x + (centre.y - u.y) / (w.y - u.y) * (w.x - u.x))
            inside = !inside;
    }
    if (!inside) return std::nullopt;
    return centre;
}

// The largest closed layer (bounding-box diagonal) with a body_centre() under layer `b`
// (directly or with layers between them); none if there is none.
std::optional<std::size_t> largest_body_under(const Scene& scene, std::size_t b) {
    std::optional<std::size_t> best;
    double best_size = -1.0;
    for (std::size_t a = 0; a < scene.size(); ++a) {
        if (scene.relation(a, b) != Relation::Under) continue;
        const Layer& inner = scene.layer(a);
        if (!inner.closed || !body_centre(inner)) continue;
        const Vec2 size = inner.bounds().size();
        const double d = std::hypot(size.x, size.y);
        if (d > best_size) {
            best_size = d;
            best = a;
        }
    }
    return best;
}

// The angle (radians) open `layer` turns through seen from `centre`: the sum over its segments
// of the signed angle between their ends, counter-clockwise positive.
double swept_angle(const Layer& layer, const Vec2& centre) {
    double swept = 0.0;
    for (std::size_t k = 0; k + 1 < layer.points.size(); ++k) {
        const Vec2 u = layer.points[k] - centre, w = layer.points[k + 1] - centre;
        swept += std::atan2(u.x * w.y - u.y * w.x, glm::dot(u, w));
    }
    return swept;
}

}  // namespace

std::vector<int> untangling_outside_sides(const Scene& scene) {
    std::vector<int> sides = outside_sides(scene);
    const std::size_t n = scene.size();
    // An open layer with neighbours both under and over it, whose neighbours' sides (within
    // the reach of record_input_sides()) under it and over it say opposite outsides: both
    // counted together (the vote counts the layers under it alone unless they tie). A
    // decimation that scatters the vertices on one side leaves the other's count standing.
    std::optional<InputSides> recorded;
    for (std::size_t i = 0; i < n; ++i) {
        if (scene.layer(i).closed || scene.inner_of(i).empty() || scene.outer_of(i).empty())
            continue;
        if (!recorded) recorded = record_input_sides(scene);
        auto tally = [&](const std::vector<std::size_t>& layers, int sign) {
            long vote = 0;
            for (std::size_t j : layers)
                for (std::size_t k = 0; k < scene.layer(j).points.size(); ++k)
                    vote += sign * recorded->side(j, k, i);
            return vote;
        };
        const long under = tally(scene.inner_of(i), -1), over = tally(scene.outer_of(i), 1);
        if ((under > 0 && over < 0) || (under < 0 && over > 0)) {
            const long both = under + over;
            if (both != 0) sides[i] = both > 0 ? 1 : -1;
        }
    }
    // An open layer directly over a closed one that runs around it (the mean, weighted by
    // length, of the sine between its segments and the direction from the closed layer's
    // centroid, body_centre(), beyond kAround): outside away from that centroid, whatever the
    // vote.
    constexpr double kAround = 0.8;
    std::vector<char> around(n, 0);  // decided by the rule above
    for (std::size_t b = 0; b < n; ++b) {
        const Layer& layer = scene.layer(b);
        if (layer.closed) continue;
        for (std::size_t a : scene.inner_of(b)) {
            const Layer& inner = scene.layer(a);
            if (!inner.closed) continue;
            const std::optional<Vec2> centre = body_centre(inner);
            if (!centre) continue;
            double turn = 0.0, total = 0.0;
            for (std::size_t k = 0; k + 1 < layer.points.size(); ++k) {
                const Vec2 d = layer.points[k + 1] - layer.points[k];
                const Vec2 r = 0.5 * (layer.points[k] + layer.points[k + 1]) - *centre;
                const double rl = glm::length(r);
                if (!(rl > 0.0)) continue;
                turn += (r.x * d.y - r.y * d.x) / rl;
                total += glm::length(d);
            }
            if (!(total > 0.0) || std::abs(turn / total) < kAround) continue;
            // Counter-clockwise around the centre: the outside is on the right (+1).
            sides[b] = turn > 0.0 ? 1 : -1;
            around[b] = 1;
            break;
        }
    }
    // An open layer over a body that the rule above left to its vote (the largest closed
    // layer under it, directly or with layers between them, bounding-box diagonals, whose
    // body_centre() lies inside it), which it sweeps around by at least kSweep (the angle
    // its vertices turn through seen from that centroid): outside away from the body. For a
    // layer that runs back in part (a fold or a roll at its end, where the mean sine fails),
    // whose vote counts the neighbours' vertices a tangle scattered. The largest: a small loop
    // in a fold of the layer (a collar's cord) is swept around the other way. With layers
    // between: a jacket over a shirt over a body wraps the body as the shirt does, and a
    // shirt's roll over the jacket's end (its vertices on the jacket's outside) scattered by a
    // tangle turns the jacket's vote; the link of parallel layers below misses them when the
    // roll lengthens the shirt (its tangents at the same fractions of their lengths part).
    constexpr double kSweep = 2.0 * 3.14159265358979323846 / 3.0;
    for (std::size_t b = 0; b < n; ++b) {
        if (scene.layer(b).closed || around[b]) continue;
        const std::optional<std::size_t> body = largest_body_under(scene, b);
        if (!body) continue;
        const double swept = swept_angle(scene.layer(b), *body_centre(scene.layer(*body)));
        if (std::abs(swept) >= kSweep) sides[b] = swept > 0.0 ? 1 : -1;
    }
    // Directly related open layers that run along each other (the mean cosine of their
    // tangents at the same fraction of their lengths beyond +-kParallel): the same outside
    // side when they travel the same way, opposite ones when they travel opposite ways.
    constexpr std::size_t kSamples = 64;
    constexpr double kParallel = 0.8;
    std::vector<std::vector<Vec2>> tangents(n);
    for (std::size_t i = 0; i < n; ++i)
        if (!scene.layer(i).closed) tangents[i] = tangents_along(scene.layer(i), kSamples);
    // Components of such pairs, with each layer's parity to its component's first layer.
    std::vector<std::size_t> component(n);
    std::vector<int> parity(n, 1);
    for (std::size_t i = 0; i < n; ++i) component[i] = i;
    bool linked = false;
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b : scene.outer_of(a)) {
            if (tangents[a].size() != kSamples || tangents[b].size() != kSamples) continue;
            double cosine = 0.0;
            for (std::size_t k = 0; k < kSamples; ++k)
                cosine += glm::dot(tangents[a][k], tangents[b][k]);
            cosine /= static_cast<double>(kSamples);
            if (std::abs(cosine) < kParallel) continue;
            const int together = cosine > 0.0 ? 1 : -1;
            const std::size_t ca = component[a], cb = component[b];
            if (ca == cb) continue;  // the first link found decides
            const int flip = parity[a] * parity[b] * together;
            for (std::size_t i = 0; i < n; ++i)
                if (component[i] == cb) {
                    component[i] = ca;
                    parity[i] *= flip;
                }
            linked = true;
        }
    if (!linked) return sides;
    // A component whose layers' votes disagree with their parities (a tangle scatters the
    // vertices each layer's vote counts) takes the majority of its votes, a tie its innermost
    // layer's (the lowest index).
    for (std::size_t c = 0; c < n; ++c) {
        int sum = 0, first = 0;
        bool agree = true, any = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (component[i] != c || scene.layer(i).closed) continue;
            const int vote = sides[i] * parity[i];
            if (!any) first = vote;
            agree = agree && vote == first;
            any = true;
            sum += vote;
        }
        if (!any || agree) continue;
        const int chosen = sum > 0 ? 1 : sum < 0 ? -1 : first;
        for (std::size_t i = 0; i < n; ++i)
            if (component[i] == c && !scene.layer(i).closed) sides[i] = chosen * parity[i];
    }
    return sides;
}

void validate(const UntangleParams& params) {
    auto fail = [](const char* field, double value, const char* range) {
        throw InvalidInput(std::string("untangle: params.") + field + " must be " + range +
                           " (got " + format_number(value) + ")");
    };
    if (params.gradient_steps < 1) fail("gradient_steps", params.gradient_steps, ">= 1");
    if (!(params.step > 0.0 && params.step <= 1.0)) fail("step", params.step, "in (0, 1]");
    if (!(params.max_step_fraction > 0.0 && params.max_step_fraction <= 1.0))
        fail("max_step_fraction", params.max_step_fraction, "in (0, 1]");
    if (params.edge_samples < 0) fail("edge_samples", params.edge_samples, ">= 0");
    if (!(params.sample_spacing >= 0.0) || !std::isfinite(params.sample_spacing))
        fail("sample_spacing", params.sample_spacing, ">= 0 and finite");
    if (!(params.alpha >= 0.0 && params.alpha <= 1.0)) fail("alpha", params.alpha, "in [0, 1]");
    if (!(params.beta >= 0.0 && params.beta <= 1.0)) fail("beta", params.beta, "in [0, 1]");
    if (!(params.tolerance > 0.0) || !std::isfinite(params.tolerance))
        fail("tolerance", params.tolerance, "> 0");
    if (params.max_rounds < 1) fail("max_rounds", params.max_rounds, ">= 1");
    if (params.max_passes < 1) fail("max_passes", params.max_passes, ">= 1");
    if (!(params.min_separation >= 0.0) || !std::isfinite(params.min_separation))
        fail("min_separation", params.min_separation, ">= 0 and finite");
    if (!(params.separation_tolerance >= 0.0 && params.separation_tolerance < 1.0))
        fail("separation_tolerance", params.separation_tolerance, "in [0, 1)");
    validate(params.field);
    validate(params.composition);
}

namespace {

// `given`, with the outside sides of untangling_outside_sides(scene) unless it gives them.
UntangleParams with_outside_sides(const Scene& scene, const UntangleParams& given) {
    UntangleParams params = given;
    if (params.outside_sides.empty()) params.outside_sides = untangling_outside_sides(scene);
    return params;
}

// One untangling of the whole scene; `keep_simple`: EngineSettings::keep_simple.
UntangleReport untangle_once(Scene& scene, const UntangleParams& params, const ProgressFn& progress,
                             bool keep_simple) {
    UntangleReport report = run(scene, whole_scene_pieces(scene), params, progress, keep_simple);
    report.kept_simple = keep_simple;
    return report;
}

// What the tries of one call cost (UntangleReport::tries, passes, rounds, finishes,
// finish_moves and seconds), summed over every try whichever try's result is kept.
struct TriesCost {
    UntangleReport sum;

    void add(const UntangleReport& r) {
        sum.tries += r.tries;
        sum.passes += r.passes;
        sum.rounds += r.rounds;
        sum.finishes += r.finishes;
        sum.finish_moves += r.finish_moves;
        sum.seconds_fields += r.seconds_fields;
        sum.seconds_untangle += r.seconds_untangle;
        sum.seconds_check += r.seconds_check;
        sum.seconds_finish += r.seconds_finish;
    }

    // `kept` (the result of one of the tries) with the cost of all of them.
    UntangleReport charged_to(UntangleReport kept) const {
        kept.tries = sum.tries;
        kept.passes = sum.passes;
        kept.rounds = sum.rounds;
        kept.finishes = sum.finishes;
        kept.finish_moves = sum.finish_moves;
        kept.seconds_fields = sum.seconds_fields;
        kept.seconds_untangle = sum.seconds_untangle;
        kept.seconds_check = sum.seconds_check;
        kept.seconds_finish = sum.seconds_finish;
        return kept;
    }
};

// a x b for positive counts, at most INT_MAX (a pass cap or a step count a user made large).
int saturated_product(int a, int b) {
    const long long product = static_cast<long long>(a) * static_cast<long long>(b);
    return static_cast<int>(std::min<long long>(product, std::numeric_limits<int>::max()));
}

// After a failed try (`failed`, whose result `scene` holds), another one from the input
// (`second`, its result in `attempt`): the second result is kept when clean, the first stands
// otherwise; the report counts both.
UntangleReport after_retry(Scene& scene, const UntangleReport& failed, Scene&& attempt,
                           const UntangleReport& second) {
    TriesCost cost;
    cost.add(failed);
    cost.add(second);
    if (!second.collision_free) return cost.charged_to(failed);
    scene = std::move(attempt);
    return cost.charged_to(second);
}

}  // namespace

namespace {

// Whether `scene` has regions on a rolled side by its inferred sides (infer_input_sides()):
// where it has, which side a region belongs on is in question.
bool has_rolled_regions(const Scene& scene) {
    const std::vector<int> outside = untangling_outside_sides(scene);
    return infer_input_sides(scene, {}, outside).rolled_count(scene, outside) > 0;
}

// When the tries with params fail, they run again with long rounds (UntangleParams::
// long_rounds_factor) and the first clean result is kept; the report counts both. Where the
// sides are in question (`in_question()`: not an original's, and the scene has rolled regions;
// asked only when the tries failed), the retry takes the inferred sides alone
// (`tries(scene, params, true)`), which keep the rolled regions: with the global order and the
// other readings, longer rounds let a wrong reading hold (the collar at 95%, seeds 4 and 9,
// came out clean by the global order with its fold unrolled), and the untangling had better
// say it failed.
template <class Tries, class InQuestion>
UntangleReport with_long_rounds(Scene& scene, const UntangleParams& params,
                                InQuestion&& in_question_of, Tries&& tries) {
    const Scene input = scene;
    UntangleReport report = tries(scene, params, false);
    if (report.collision_free || params.long_rounds_factor <= 1) return report;
    const bool in_question = in_question_of(input);
    UntangleParams longer = params;
    longer.gradient_steps = saturated_product(params.gradient_steps, params.long_rounds_factor);
    longer.long_rounds_factor = 1;
    Scene attempt = input;
    UntangleReport second = tries(attempt, longer, in_question);
    second.long_rounds = true;
    return after_retry(scene, report, std::move(attempt), second);
}

UntangleReport untangle_tries(Scene& scene, const UntangleParams& given,
                              const ProgressFn& progress) {
    const UntangleParams params = with_outside_sides(scene, given);
    const Scene input = scene;
    UntangleReport report = untangle_once(scene, params, progress, false);
    if (report.collision_free) return report;
    // Second try, from the input: no vertex move that makes a self-crossing (the projection
    // and shape matching make them, and nothing takes them out: docs/untangle.md).
    Scene simple = input;
    const UntangleReport second = untangle_once(simple, params, progress, true);
    return after_retry(scene, report, std::move(simple), second);
}

// `inferred_only`: the tries by the inferred sides alone, when they have rolled regions (a
// failed report otherwise); no global order, no other reading.
UntangleReport inferring_sides_tries(Scene& scene, const UntangleParams& params,
                                     const ProgressFn& progress, InputSides* kept,
                                     bool inferred_only) {
    // Regions of the input on the other side of an open layer than the global order says (a
    // roll, which the global order pushes back): kept there, when that comes out clean.
    const InputSides recorded = record_input_sides(scene);
    const UntangleParams global = with_outside_sides(scene, params);
    InputSides inferred = recorded.by_region(scene, global.outside_sides);
    UntangleParams with_sides = global;
    with_sides.input_sides = &inferred;
    with_sides.open_cut_bends = false;  // inferred sides: a cut bend is what is in question
    const bool rolled = inferred.rolled_count(scene, with_sides.outside_sides) > 0;
    // By the inferred sides, then by the global order; the second tries (no self-crossing
    // made) only when neither first try is clean, so that a scene one of them cleans costs
    // what it did without them.
    const Scene input = scene;
    UntangleReport first;  // the global order's first try: the result when nothing is clean
    Scene first_scene;
    TriesCost cost;
    // One try from the input into `attempt`; true when it comes out clean.
    auto clean_try = [&](const UntangleParams& p, bool keep_simple, Scene& attempt,
                         UntangleReport& report) {
        attempt = input;
        report = untangle_once(attempt, p, progress, keep_simple);
        cost.add(report);
        return report.collision_free;
    };
    if (inferred_only) {
        UntangleReport report;
        if (!rolled) return report;
        for (bool keep_simple : {false, true}) {
            Scene attempt;
            if (!clean_try(with_sides, keep_simple, attempt, report)) continue;
            report.inferred_sides = true;
            if (kept) *kept = std::move(inferred);
            scene = std::move(attempt);
            return cost.charged_to(report);
        }
        return cost.charged_to(report);
    }
    for (bool keep_simple : {false, true}) {
        Scene attempt;
        UntangleReport report;
        if (rolled && clean_try(with_sides, keep_simple, attempt, report)) {
            report.inferred_sides = true;
            if (kept) *kept = std::move(inferred);
        } else if (!clean_try(global, keep_simple, attempt, report)) {
            if (!keep_simple) {
                first = report;
                first_scene = std::move(attempt);
            }
            // Without rolled regions the inferred sides are the global order's, but for the
            // vertices they give no side (around an end of the other layer, a tie): there only
            // the distance counts. A fold cut by the decimation (the folded scenes) can come
            // out clean so where the global order, pushing those vertices too, does not.
            if (rolled || !clean_try(with_sides, keep_simple, attempt, report)) continue;
            report.inferred_sides = true;
            if (kept) *kept = std::move(inferred);
        }
        scene = std::move(attempt);
        return cost.charged_to(report);
    }
    // Neither is clean: the other readings of the regions whose recorded sides disagree
    // (InputSides::region_alternatives(), at most params.other_readings of them, best fitting
    // first), each tried once, then once more without self-crossings made (as above); of the
    // clean results of the first round that has one, the one that moves the input least.
    std::vector<InputSides> others;
    if (params.other_readings > 0)
        others = recorded.region_alternatives(scene, global.outside_sides);
    if (others.size() > params.other_readings) others.resize(params.other_readings);
    for (bool keep_simple : {false, true}) {
        std::size_t best = others.size();
        Scene best_scene;
        UntangleReport best_report;
        for (std::size_t i = 0; i < others.size(); ++i) {
            UntangleParams p = global;
            p.input_sides = &others[i];
            p.open_cut_bends = false;
            Scene attempt;
            UntangleReport report;
            if (!clean_try(p, keep_simple, attempt, report) ||
                (best < others.size() && report.max_displacement >= best_report.max_displacement))
                continue;
            best = i;
            best_scene = std::move(attempt);
            best_report = report;
        }
        if (best == others.size()) continue;
        best_report.inferred_sides = true;
        best_report.sides_reading = best + 1;
        if (kept) *kept = std::move(others[best]);
        scene = std::move(best_scene);
        return cost.charged_to(best_report);
    }
    scene = std::move(first_scene);
    return cost.charged_to(first);
}

}  // namespace

UntangleReport untangle(Scene& scene, const UntangleParams& params, const ProgressFn& progress) {
    return untangle_tries(scene, params, progress);
}

UntangleReport untangle_inferring_sides(Scene& scene, const UntangleParams& params,
                                        const ProgressFn& progress, InputSides* kept) {
    if (params.input_sides && !params.input_sides->empty())
        return with_long_rounds(
            scene, params, [](const Scene&) { return false; },  // the original's: not in question
            [&](Scene& s, const UntangleParams& p, bool /*in_question*/) {
                return untangle_tries(s, p, progress);
            });
    const Scene input = scene;
    // has_rolled_regions(input), once, when a retry first asks.
    std::optional<bool> rolled;
    auto rolled_regions = [&](const Scene& s) {
        if (!rolled) rolled = has_rolled_regions(s);
        return *rolled;
    };
    UntangleReport report = with_long_rounds(
        scene, params, rolled_regions, [&](Scene& s, const UntangleParams& p, bool in_question) {
            return inferring_sides_tries(s, p, progress, kept, in_question);
        });
    // Every try failed: where the global order is the reading (nothing read rolled), its second
    // try (no self-crossing made) once more with more passes: the projection of a fold cut by
    // chords can wander for a few hundred passes before it comes out clean.
    if (report.collision_free || params.more_passes_factor <= 1 || rolled_regions(input))
        return report;
    UntangleParams more = with_outside_sides(input, params);
    more.max_passes = saturated_product(params.max_passes, params.more_passes_factor);
    Scene attempt = input;
    UntangleReport last = untangle_once(attempt, more, progress, true);
    last.more_passes = true;
    return after_retry(scene, report, std::move(attempt), last);
}

UntangleReport untangle_local(Scene& scene, const Box2& box, std::size_t n_out,
                              const UntangleParams& params, const ProgressFn& progress) {
    const std::vector<Piece> pieces = localize(scene, box, n_out);
    // The checks look near the pieces (free vertices and collars), with room for the free
    // vertices to move by half the pieces' extent; a move beyond is checked whole.
    Box2 region;
    for (const Piece& piece : pieces)
        for (std::size_t v : piece.vertices) region.extend(scene.layer(piece.layer).points[v]);
    const Vec2 size = region.size();
    region = region.inflated(0.5 * std::max(size.x, size.y));
    return run(scene, pieces, params, progress, false, &region);
}

}  // namespace strata
