// The tries of a whole-scene untangling (untangle(), untangle_inferring_sides()): a second try
// from the input, the inferred sides and the global order, other readings, long rounds and
// more passes, each one an untangling of the whole scene by detail::run_untangling().
#include "strata/untangle/untangle.h"

#include "strata/geometry/checks.h"
#include "strata/geometry/input_sides.h"
#include "untangle/detail/engine.h"
#include "untangle/detail/retract_ends.h"
#include "untangle/detail/run.h"
#include "untangle/detail/try_list.h"
#include "untangle/detail/untwist.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace strata {

namespace {

// `given`, with the outside sides of untangling_outside_sides(scene) unless it gives them.
UntangleParams with_outside_sides(const Scene& scene, const UntangleParams& given) {
    UntangleParams params = given;
    if (params.outside_sides.empty()) params.outside_sides = untangling_outside_sides(scene);
    return params;
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

// The result kept when no try of a call comes out clean: the least tangled of the failed
// tries' results and of the input, in this order (smaller first): crossings between layers
// plus self-crossings, nesting violations, then the larger min separation ratio, then the
// smaller max displacement; the earlier try on a tie, and the input only when strictly less
// tangled than every try (a user loses nothing; docs/untangle.md, "When every try fails").
// Each try's counts are those its final check gives (judged by the sides it kept).
class LeastTangled {
  public:
    /// `failed`: a try of the call failed before this one was made (any_failed()).
    explicit LeastTangled(bool failed = false) : failed_(failed) {}

    /// Stamped on the reports offered from now on (the retries' flags).
    bool long_rounds = false, retry_passes = false, more_passes = false, loop_reading = false,
         ends_by_nearest = false;

    // The result of a failed try (`scene`, `report`); `sides`: the inferred sides it kept
    // (report.inferred_sides), or nullptr for params' own.
    // `reading`: the other reading `sides` is (report.sides_reading), 0 for none.
    void offer(const Scene& scene, UntangleReport report, const InputSides* sides,
               std::size_t reading) {
        report.long_rounds = long_rounds;
        report.retry_passes = retry_passes;
        report.more_passes = more_passes;
        report.loop_reading = loop_reading;
        report.ends_by_nearest = ends_by_nearest;
        report.inferred_sides = sides != nullptr;
        report.sides_reading = reading;
        failed_ = true;
        if (!sides && !input_) input_ = as_input(report);
        if (scene_ && !less_tangled(report, report_)) return;
        scene_ = scene;
        report_ = report;
        sides_.reset();
        if (sides) sides_ = *sides;
    }

    // `failed` (a failed report with the cost of every try, from `input`): `scene` becomes the
    // least tangled result, the input included, and the report is its, with that cost;
    // `kept`, if given, receives the sides it kept when inferred.
    // `tried`, if given, receives the inferred sides the result kept was tried with (reset
    // when it was tried with params' own, or is the input).
    UntangleReport keep(Scene& scene, const Scene& input, const UntangleReport& failed,
                        InputSides* kept, std::optional<InputSides>* tried = nullptr) {
        UntangleReport report = failed;
        if (tried) tried->reset();
        if (input_ && (!scene_ || less_tangled(*input_, report_))) {
            report = *input_;
            scene = input;
        } else if (scene_) {
            report = report_;
            scene = std::move(*scene_);
            if (tried && sides_) *tried = *sides_;
            if (kept && sides_) *kept = std::move(*sides_);
        }
        scene_.reset();
        TriesCost cost;
        cost.add(failed);
        return cost.charged_to(report);
    }

    // Whether a try of the call has failed: from then on, the tries of a list run two at a time
    // (run_list()); the first try of a call runs alone, since most calls need no other.
    bool any_failed() const { return failed_; }
    void mark_failed() { failed_ = true; }

  private:
    static bool less_tangled(const UntangleReport& a, const UntangleReport& b) {
        auto key = [](const UntangleReport& r) {
            return std::make_tuple(r.crossings_after + r.self_crossings_after,
                                   r.nesting_violations_after, -r.min_separation_ratio_after,
                                   r.max_displacement);
        };
        return key(a) < key(b);
    }

    // The input as a result, by the counts before of a try that judged it by params' sides.
    static UntangleReport as_input(const UntangleReport& r) {
        UntangleReport input;
        input.free_vertices = r.free_vertices;
        input.crossings_before = input.crossings_after = r.crossings_before;
        input.self_crossings_before = input.self_crossings_after = r.self_crossings_before;
        input.nesting_violations_before = input.nesting_violations_after =
            r.nesting_violations_before;
        input.min_separation_ratio_before = input.min_separation_ratio_after =
            r.min_separation_ratio_before;
        input.rolled_vertices = r.rolled_vertices;
        input.rolled_kept = input.rolled_kept_before = r.rolled_kept_before;
        input.input_kept = true;
        return input;
    }

    std::optional<Scene> scene_;
    UntangleReport report_;
    std::optional<InputSides> sides_;
    std::optional<UntangleReport> input_;
    bool failed_ = false;
};

// One try of a whole-scene untangling from a list's input: its params and the other arguments of
// detail::run_untangling(); `sides`, `reading`: LeastTangled::offer()'s, for a failed result.
struct TrySpec {
    const UntangleParams* params = nullptr;
    bool keep_simple = false;  // EngineSettings::keep_simple
    const InputSides* sides = nullptr;
    std::size_t reading = 0;
    bool ends_by_nearest = false;  // EngineSettings::ends_by_nearest
};

// The try `spec` on a copy of `input`.
detail::TryResult one_try(const Scene& input, const TrySpec& spec, const ProgressFn& progress) {
    detail::TryResult r{input, {}};
    r.report = detail::run_untangling(r.scene, whole_scene_pieces(r.scene), *spec.params, progress,
                                      spec.keep_simple, nullptr, spec.ends_by_nearest);
    r.report.kept_simple = spec.keep_simple;
    return r;
}

// One untangling of the whole scene in place (TrySpec's arguments). A failed result is offered
// to `failures`.
UntangleReport untangle_once(Scene& scene, const UntangleParams& params, const ProgressFn& progress,
                             bool keep_simple, LeastTangled& failures) {
    detail::TryResult r = one_try(scene, TrySpec{&params, keep_simple}, progress);
    if (!r.report.collision_free) failures.offer(r.scene, r.report, nullptr, 0);
    scene = std::move(r.scene);
    return r.report;
}

// The tries `specs`, each from `input`, by detail::run_try_list(): two at a time once a try of
// the call has failed (LeastTangled::any_failed()). In order, each failed result is offered to
// `failures`, every report is added to `cost` (if given), then `take(i, result)` receives the
// result. With `until_clean` the list ends at the first clean try.
void run_list(const Scene& input, const std::vector<TrySpec>& specs, bool until_clean,
              const ProgressFn& progress, LeastTangled& failures, TriesCost* cost,
              const detail::TakeTry& take) {
    detail::run_try_list(
        specs.size(), until_clean, failures.any_failed(),
        [&](std::size_t i, const ProgressFn& p) { return one_try(input, specs[i], p); },
        [&](std::size_t i, detail::TryResult&& r) {
            if (!r.report.collision_free)
                failures.offer(r.scene, r.report, specs[i].sides, specs[i].reading);
            if (cost) cost->add(r.report);
            take(i, std::move(r));
        },
        progress);
}

// a x b for positive counts, at most INT_MAX (a pass cap or a step count a user made large).
int saturated_product(int a, int b) {
    const long long product = static_cast<long long>(a) * static_cast<long long>(b);
    return static_cast<int>(std::min<long long>(product, std::numeric_limits<int>::max()));
}

// `params` with long_rounds_factor times the gradient steps, and no more long rounds.
UntangleParams longer_rounds(const UntangleParams& params) {
    UntangleParams longer = params;
    longer.gradient_steps = saturated_product(params.gradient_steps, params.long_rounds_factor);
    longer.long_rounds_factor = 1;
    return longer;
}

// After a failed try (`failed`), another one from the input (`second`, its result in
// `attempt`): the second result is kept when clean; otherwise the report is a failed one
// (which result is kept, LeastTangled says). The report counts both.
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
// long_rounds_factor) and the first clean result is kept; the report counts both. Not where
// `ran_long(input)` (asked only when the tries failed): where rolled regions are read, the
// tries already ran the inferred sides with long rounds, before the global order
// (inferring_sides_tries()), and long rounds of the global order and the other readings let a
// wrong reading hold (the collar at 95%, seeds 4 and 9, came out clean by the global order
// with its fold unrolled): the untangling had better say it failed.
template <class Tries, class RanLong>
UntangleReport with_long_rounds(Scene& scene, const UntangleParams& params, RanLong&& ran_long,
                                Tries&& tries, LeastTangled& failures) {
    const Scene input = scene;
    UntangleReport report = tries(scene, params);
    if (report.collision_free || params.long_rounds_factor <= 1 || ran_long(input)) return report;
    Scene attempt = input;
    failures.long_rounds = true;
    UntangleReport second = tries(attempt, longer_rounds(params));
    second.long_rounds = true;
    return after_retry(scene, report, std::move(attempt), second);
}

UntangleReport untangle_tries(Scene& scene, const UntangleParams& given, const ProgressFn& progress,
                              LeastTangled& failures) {
    const UntangleParams params = with_outside_sides(scene, given);
    const Scene input = scene;
    // The first try, then a second from the input: no vertex move that makes a self-crossing
    // (the projection and shape matching make them, and nothing aims at taking them out:
    // docs/untangle.md). The first result is kept unless the second is clean.
    UntangleReport first;
    std::optional<detail::TryResult> second;
    run_list(input, {TrySpec{&params, false}, TrySpec{&params, true}}, true, progress, failures,
             nullptr, [&](std::size_t i, detail::TryResult&& r) {
                 if (i > 0) {
                     second = std::move(r);
                     return;
                 }
                 first = r.report;
                 scene = std::move(r.scene);
             });
    if (!second) return first;
    return after_retry(scene, first, std::move(second->scene), second->report);
}

UntangleReport inferring_sides_tries(Scene& scene, const UntangleParams& params,
                                     const ProgressFn& progress, InputSides* kept,
                                     LeastTangled& failures) {
    // Regions of the input on the other side of an open layer than the global order says (a
    // roll, which the global order pushes back): kept there, when that comes out clean.
    const InputSides recorded = record_input_sides(scene);
    const UntangleParams global = with_outside_sides(scene, params);
    InputSides inferred = recorded.by_region(scene, global.outside_sides);
    UntangleParams with_sides = global;
    with_sides.input_sides = &inferred;
    with_sides.open_cut_bends = false;  // inferred sides: a cut bend is what is in question
    const bool rolled = inferred.rolled_count(scene, with_sides.outside_sides) > 0;
    // Where the input has rolled regions: by the inferred sides, first try then second (no
    // self-crossing made), then both again with long rounds, before the global order, which
    // unrolls them. Elsewhere by the global order, then by the inferred sides (see below), the
    // second tries only when neither first try is clean, so that a scene one of them cleans
    // costs what it did without them.
    const Scene input = scene;
    TriesCost cost;
    // The first clean try of `order` (by the inferred sides or by the global order), the
    // first tries of the order before its second ones, each from the input: `scene` becomes
    // its result, and the report counts every try so far; nullopt when none is clean.
    // `by_sides`: the params of the tries by the inferred sides.
    auto first_clean = [&](std::initializer_list<bool> order,
                           const UntangleParams& by_sides) -> std::optional<UntangleReport> {
        std::vector<TrySpec> specs;
        std::vector<bool> by_inferred;
        for (bool keep_simple : {false, true})
            for (bool inferred_try : order) {
                specs.push_back(inferred_try ? TrySpec{&by_sides, keep_simple, &inferred}
                                             : TrySpec{&global, keep_simple});
                by_inferred.push_back(inferred_try);
            }
        std::optional<UntangleReport> done;
        run_list(input, specs, true, progress, failures, &cost,
                 [&](std::size_t i, detail::TryResult&& r) {
                     if (!r.report.collision_free) return;
                     r.report.inferred_sides = by_inferred[i];
                     scene = std::move(r.scene);
                     done = cost.charged_to(r.report);
                 });
        // Once no try reads the inferred sides any more.
        if (done && done->inferred_sides && kept) *kept = std::move(inferred);
        return done;
    };
    // The other readings of the regions whose recorded sides disagree
    // (InputSides::region_alternatives(), best fitting first), found when first asked for.
    std::optional<std::vector<InputSides>> alternatives;
    auto other_readings = [&]() -> const std::vector<InputSides>& {
        if (!alternatives) alternatives = recorded.region_alternatives(input, global.outside_sides);
        return *alternatives;
    };
    // Where the tries by the inferred sides fail on a scene with rolled regions, before the
    // global order (which unrolls them): the first other reading of the regions (see below)
    // with no side around an end (InputSides::without_end_sides()), first try then second. The
    // shirt at 95%, seed 60 (out of sample), had body vertices cut off by the shirt's chord
    // read flipped: that reading alone failed, and without the sides around the shirt's
    // decimated end it came out clean by the original's sides, where the global order unrolled
    // the shirt. Its failed results are offered to no one: the last resorts start from the
    // least tangled result, and a version that offered them left the folded stack at 95%,
    // seed 45, tangled (exit 1).
    auto ends_by_global_order = [&]() -> std::optional<UntangleReport> {
        if (params.other_readings == 0 || other_readings().empty()) return std::nullopt;
        InputSides reading = other_readings().front().without_end_sides(input);
        UntangleParams by_reading = global;
        by_reading.input_sides = &reading;
        by_reading.open_cut_bends = false;
        LeastTangled not_offered(true);
        std::optional<UntangleReport> done;
        run_list(input,
                 {TrySpec{&by_reading, false, &reading}, TrySpec{&by_reading, true, &reading}},
                 true, progress, not_offered, &cost, [&](std::size_t, detail::TryResult&& r) {
                     if (!r.report.collision_free) return;
                     r.report.inferred_sides = true;
                     r.report.sides_reading = 1;
                     r.report.end_sides_dropped = true;
                     scene = std::move(r.scene);
                     done = cost.charged_to(r.report);
                 });
        if (done && kept) *kept = std::move(reading);
        return done;
    };
    // Without rolled regions the inferred sides are the global order's, but for the vertices
    // they give no side (around an end of the other layer, a tie): there only the distance
    // counts. A fold cut by the decimation (the folded scenes) can come out clean so where the
    // global order, pushing those vertices too, does not.
    std::optional<UntangleReport> done;
    if (rolled) {
        done = first_clean({true}, with_sides);
        if (!done && with_sides.long_rounds_factor > 1) {
            failures.long_rounds = true;
            done = first_clean({true}, longer_rounds(with_sides));
            failures.long_rounds = false;
            if (done) done->long_rounds = true;
        }
        if (!done) done = ends_by_global_order();
        if (!done) done = first_clean({false}, with_sides);
    } else {
        done = first_clean({false, true}, with_sides);
    }
    if (done) return *done;
    // Neither is clean: the other readings of the regions whose recorded sides disagree
    // (InputSides::region_alternatives(), at most params.other_readings of them, best fitting
    // first), each tried once, then once more without self-crossings made (as above); of the
    // clean results of the first round that has one, the one that moves the input least.
    std::vector<InputSides> others;
    if (params.other_readings > 0) others = other_readings();
    if (others.size() > params.other_readings) others.resize(params.other_readings);
    std::vector<UntangleParams> by_other(others.size(), global);
    for (std::size_t i = 0; i < others.size(); ++i) {
        by_other[i].input_sides = &others[i];
        by_other[i].open_cut_bends = false;
    }
    for (bool keep_simple : {false, true}) {
        std::vector<TrySpec> specs;
        for (std::size_t i = 0; i < others.size(); ++i)
            specs.push_back(TrySpec{&by_other[i], keep_simple, &others[i], i + 1});
        std::size_t best = others.size();
        Scene best_scene;
        UntangleReport best_report;
        run_list(input, specs, false, progress, failures, &cost,
                 [&](std::size_t i, detail::TryResult&& r) {
                     if (!r.report.collision_free ||
                         (best < others.size() &&
                          r.report.max_displacement >= best_report.max_displacement))
                         return;
                     best = i;
                     best_scene = std::move(r.scene);
                     best_report = r.report;
                 });
        if (best == others.size()) continue;
        best_report.inferred_sides = true;
        best_report.sides_reading = best + 1;
        if (kept) *kept = std::move(others[best]);
        scene = std::move(best_scene);
        return cost.charged_to(best_report);
    }
    return cost.charged_to(UntangleReport{});  // failed: LeastTangled keeps a result
}

}  // namespace
namespace {

// The report of a clean try `report` (result `result`) kept in place of an earlier result of
// the call (`failed`, its report, from `input`; e.g. the least tangled one it started from):
// failed's counts before and flags, the try's counts after, the displacement from `input`.
UntangleReport as_kept(const UntangleReport& failed, const UntangleReport& report,
                       const Scene& result, const Scene& input) {
    UntangleReport kept = failed;
    kept.collision_free = report.collision_free;
    kept.converged = report.converged;
    kept.gave_up = report.gave_up;
    kept.mean_speed = report.mean_speed;
    kept.crossings_after = report.crossings_after;
    kept.self_crossings_after = report.self_crossings_after;
    kept.nesting_violations_after = report.nesting_violations_after;
    kept.min_separation_ratio_after = report.min_separation_ratio_after;
    kept.rolled_kept = report.rolled_kept;
    kept.input_kept = false;
    detail::measure_displacement(result, input, kept);
    return kept;
}

// One more attempt from the least tangled result `scene` of untangle_inferring_sides() when
// every try failed (`failed`, its report, from `input`): `attempt(s)` works on a copy `s` of
// `scene` and returns its report, or nullopt when it could not start. A clean result is kept,
// with failed's counts before and the displacement from `input` (as_kept()); the report
// counts every try.
template <class Attempt>
UntangleReport from_least_tangled(Scene& scene, const Scene& input, const UntangleReport& failed,
                                  Attempt&& attempt) {
    Scene s = scene;
    const std::optional<UntangleReport> report = attempt(s);
    if (!report) return failed;
    TriesCost cost;
    cost.add(failed);
    cost.add(*report);
    if (!report->collision_free) return cost.charged_to(failed);
    const UntangleReport kept = as_kept(failed, *report, s, input);
    scene = std::move(s);
    return cost.charged_to(kept);
}

// The least tangled result `scene` (`failed`, from `input`), self-crossings left: untwist()
// them, then one more try from there (no self-crossing made) by the sides that result was tried
// with (`p`); kept when clean (report.untwisted).
UntangleReport untwisted_try(Scene& scene, const Scene& input, const UntangleParams& p,
                             const UntangleReport& failed, const ProgressFn& progress) {
    UntangleReport report =
        from_least_tangled(scene, input, failed, [&](Scene& s) -> std::optional<UntangleReport> {
            if (!detail::untwist(s)) return std::nullopt;
            return detail::run_untangling(s, whole_scene_pieces(s), p, progress, true);
        });
    report.untwisted = report.collision_free;
    return report;
}

// The least tangled result `scene` (`failed`, from `input`), after untwisted_try() if it ran:
// retract_ends() judged by the sides that result was tried with (`p`), then one more try from
// there by them (no self-crossing made); kept when clean (report.ends_retracted).
UntangleReport retracted_ends_try(Scene& scene, const Scene& input, const UntangleParams& p,
                                  const UntangleReport& failed, const ProgressFn& progress) {
    std::size_t retracted = 0;
    UntangleReport report =
        from_least_tangled(scene, input, failed, [&](Scene& s) -> std::optional<UntangleReport> {
            const detail::EngineSettings settings = detail::resolve_settings(s, p);
            retracted = detail::retract_ends(s, detail::judge_params(p, settings.outside_signs));
            if (retracted == 0) return std::nullopt;
            return detail::run_untangling(s, whole_scene_pieces(s), p, progress, true);
        });
    report.ends_retracted = report.collision_free ? retracted : 0;
    return report;
}

UntangleReport given_sides_tries(Scene& scene, const UntangleParams& params,
                                 const ProgressFn& progress, LeastTangled& failures);

// The least tangled result `scene` (`failed`, from `input`), after untwisted_try() if it ran:
// untangle()'s tries, long rounds and the retry with more passes once more, from that result,
// by the sides it was tried with (`p`); kept when clean (report.restarted).
UntangleReport restarted_tries(Scene& scene, const Scene& input, const UntangleParams& p,
                               const UntangleReport& failed, const ProgressFn& progress) {
    UntangleReport report =
        from_least_tangled(scene, input, failed, [&](Scene& s) -> std::optional<UntangleReport> {
            LeastTangled not_kept(true);  // a failed restart keeps the result it started from
            return given_sides_tries(s, p, progress, not_kept);
        });
    report.restarted = report.collision_free;
    return report;
}

// `progress` with the tries told apart: every try counts its rounds from 0 again, so a fraction
// that does not grow starts another try, whose stage is "untangle, try N" (N from 2; a progress
// bar that starts again says why). Empty when `progress` is.
ProgressFn numbering_tries(const ProgressFn& progress) {
    if (!progress) return {};
    struct State {
        int tries = 1;
        double last = -1.0;
        std::string stage;
    };
    auto state = std::make_shared<State>();
    return [progress, state](std::string_view stage, double fraction) {
        if (state->last >= 0.0 && fraction <= state->last) ++state->tries;
        state->last = fraction;
        if (state->tries == 1) return progress(stage, fraction);
        state->stage = std::string(stage) + ", try " + std::to_string(state->tries);
        return progress(state->stage, fraction);
    };
}

// `tries(failures)` on `scene` (they offer their failed results to `failures`): when none
// comes out clean, the least tangled result, the input included (LeastTangled), with its
// report; `kept` as untangle_inferring_sides(). `scene` is unchanged on throw.
// `tried`: LeastTangled::keep()'s.
template <class Tries>
UntangleReport clean_or_least_tangled(Scene& scene, InputSides* kept, Tries&& tries,
                                      std::optional<InputSides>* tried = nullptr) {
    const Scene input = scene;
    try {
        LeastTangled failures;
        const UntangleReport report = tries(failures);
        if (report.collision_free) return report;
        return failures.keep(scene, input, report, kept, tried);
    } catch (...) {
        scene = input;
        throw;
    }
}

// `all_tries(scene, params)` (every try, long rounds included); when it fails,
// `cheaper(scene, failed)` (a last try that costs less than all of them again: returns its
// report, or `failed`), then, when that fails too, all the tries once more from the input with
// UntangleParams::retry_passes_factor times the passes, kept when clean (the report counts
// every try).
template <class AllTries, class Cheaper>
UntangleReport with_retry_passes(Scene& scene, const UntangleParams& params, AllTries&& all_tries,
                                 Cheaper&& cheaper, LeastTangled& failures) {
    const Scene input = scene;
    UntangleReport report = all_tries(scene, params);
    if (report.collision_free) return report;
    report = cheaper(scene, report);
    if (report.collision_free) return report;
    const double passes = std::floor(params.max_passes * params.retry_passes_factor);
    if (!(passes > params.max_passes)) return report;
    UntangleParams more = params;
    more.max_passes = static_cast<int>(std::min<double>(passes, std::numeric_limits<int>::max()));
    Scene attempt = input;
    failures.long_rounds = false;  // with_long_rounds() set it for its own retry
    failures.retry_passes = true;
    UntangleReport second = all_tries(attempt, more);
    second.retry_passes = true;
    return after_retry(scene, report, std::move(attempt), second);
}

// One of the last retries of untangle_inferring_sides(), after `failed` (its tries from
// `input`): from the input, by `params`' own sides (the global order, or an original's),
// untangle()'s first and second tries (`ends_by_nearest`: EngineSettings'), each failed one
// offered to `failures`; the first clean result is kept, its report's `mark` set. The report
// counts `failed` and every try; it is failed's when neither comes out clean.
UntangleReport own_sides_retry(Scene& scene, const Scene& input, const UntangleParams& params,
                               bool ends_by_nearest, bool UntangleReport::*mark,
                               const ProgressFn& progress, const UntangleReport& failed,
                               LeastTangled& failures) {
    TriesCost cost;
    cost.add(failed);
    std::optional<UntangleReport> done;
    run_list(input,
             {TrySpec{&params, false, nullptr, 0, ends_by_nearest},
              TrySpec{&params, true, nullptr, 0, ends_by_nearest}},
             true, progress, failures, &cost, [&](std::size_t, detail::TryResult&& r) {
                 if (!r.report.collision_free) return;
                 r.report.*mark = true;
                 scene = std::move(r.scene);
                 done = cost.charged_to(r.report);
             });
    return done ? *done : cost.charged_to(failed);
}

// When `failed` (every try of untangle_inferring_sides() from `input`) is not clean, the last
// retry: own_sides_retry() with the ends read by the nearest feature
// (EngineSettings::ends_by_nearest; report.ends_by_nearest). Only a scene every try failed on
// gets here, so every clean output stays as it was.
UntangleReport with_ends_by_nearest(Scene& scene, const Scene& input, const UntangleParams& given,
                                    const ProgressFn& progress, const UntangleReport& failed,
                                    LeastTangled& failures) {
    if (failed.collision_free || !given.retry_ends_by_nearest) return failed;
    const UntangleParams params = with_outside_sides(input, given);
    failures.long_rounds = failures.retry_passes = failures.more_passes = false;
    failures.ends_by_nearest = true;
    const UntangleReport report = own_sides_retry(
        scene, input, params, true, &UntangleReport::ends_by_nearest, progress, failed, failures);
    failures.ends_by_nearest = false;
    return report;
}

// When `failed` (everything untangle_inferring_sides() tried from `input`, the last resorts
// included; `scene` the result kept so far) is not clean, the last retry: own_sides_retry()
// with UntangleParams::retry_short_edge_fraction for short_edge_fraction
// (report.short_edges). Its failed results are offered to no one: `scene` stays the least
// tangled of the others. Only a scene on which everything failed gets here, so every clean
// output stays as it was.
UntangleReport with_short_edges(Scene& scene, const Scene& input, const UntangleParams& given,
                                const ProgressFn& progress, const UntangleReport& failed) {
    if (failed.collision_free || !(given.retry_short_edge_fraction > given.short_edge_fraction))
        return failed;
    UntangleParams params = with_outside_sides(input, given);
    params.short_edge_fraction = given.retry_short_edge_fraction;
    LeastTangled not_offered(true);
    return own_sides_retry(scene, input, params, false, &UntangleReport::short_edges, progress,
                           failed, not_offered);
}

// Vertex sides of `scene` that `every` gives and `kept` leaves out (once per other layer).
std::size_t sides_left_out(const Scene& scene, const InputSides& every, const InputSides& kept) {
    std::size_t count = 0;
    for (std::size_t a = 0; a < scene.size(); ++a)
        for (std::size_t b = 0; b < scene.size(); ++b)
            for (std::size_t k = 0; k < scene.layer(a).points.size(); ++k)
                count += every.side(a, k, b) != 0 && kept.side(a, k, b) == 0;
    return count;
}

// untangle()'s tries by params' own sides (not in question), then long rounds, then the retry
// with more passes (original_sides_tries() without the sides left out).
UntangleReport given_sides_tries(Scene& scene, const UntangleParams& params,
                                 const ProgressFn& progress, LeastTangled& failures) {
    return with_retry_passes(
        scene, params,
        [&](Scene& t, const UntangleParams& q) {
            return with_long_rounds(
                t, q, [](const Scene&) { return false; },
                [&](Scene& u, const UntangleParams& r) {
                    return untangle_tries(u, r, progress, failures);
                },
                failures);
        },
        [](Scene&, const UntangleReport& failed) { return failed; }, failures);
}

// With params.input_sides given (an original's, not in question): given_sides_tries(), first
// without the sides read at a fold's other sheet (InputSides::off_other_sheets(): `kept`
// receives those sides when that is clean), then, when some are left out and that is not
// clean, with every side from the input (the report counts both); when that fails too,
// with_ends_by_nearest(). Only the tries with every side offer their failed results to
// `failures`: the others are judged by fewer sides.
UntangleReport original_sides_tries(Scene& scene, const UntangleParams& params,
                                    const ProgressFn& progress, InputSides* kept,
                                    LeastTangled& failures) {
    const Scene input = scene;
    InputSides fewer = params.input_sides->off_other_sheets(scene);
    const std::size_t left_out = sides_left_out(scene, *params.input_sides, fewer);
    if (left_out == 0)
        return with_ends_by_nearest(scene, input, params, progress,
                                    given_sides_tries(scene, params, progress, failures), failures);
    UntangleParams without = params;
    without.input_sides = &fewer;
    Scene attempt = scene;
    LeastTangled not_offered;
    UntangleReport first = given_sides_tries(attempt, without, progress, not_offered);
    if (first.collision_free) {
        first.sides_left_out = left_out;
        scene = std::move(attempt);
        if (kept) *kept = std::move(fewer);
        return first;
    }
    failures.mark_failed();
    UntangleReport second = given_sides_tries(scene, params, progress, failures);
    TriesCost cost;
    cost.add(first);
    cost.add(second);
    return with_ends_by_nearest(scene, input, params, progress, cost.charged_to(second), failures);
}

// Every try of untangle_inferring_sides() failed, the retries included (`failed`, from
// `input`): the readings of the small closed loops the inferred sides put on both sides of an
// open layer (InputSides::loop_readings()), each as a first try, then each as a second try
// (no self-crossing made); the first clean result is kept (report.loop_reading). A loop lies
// on one side of a layer, and by_region() never reads a loop split into regions that each
// agree with itself otherwise.
UntangleReport loop_readings_tries(Scene& scene, const Scene& input, const UntangleParams& params,
                                   const ProgressFn& progress, InputSides* kept,
                                   const UntangleReport& failed, LeastTangled& failures) {
    const UntangleParams global = with_outside_sides(input, params);
    std::vector<InputSides> readings =
        infer_input_sides(input, {}, global.outside_sides).loop_readings(input);
    TriesCost cost;
    cost.add(failed);
    failures.long_rounds = failures.retry_passes = failures.more_passes = false;
    failures.loop_reading = true;
    std::vector<UntangleParams> by_reading(readings.size(), global);
    std::vector<TrySpec> specs;
    for (std::size_t i = 0; i < readings.size(); ++i) {
        by_reading[i].input_sides = &readings[i];
        by_reading[i].open_cut_bends = false;  // inferred sides: a cut bend is in question
    }
    for (bool keep_simple : {false, true})
        for (std::size_t i = 0; i < readings.size(); ++i)
            specs.push_back(TrySpec{&by_reading[i], keep_simple, &readings[i], i + 1});
    std::optional<UntangleReport> done;
    run_list(input, specs, true, progress, failures, &cost,
             [&](std::size_t j, detail::TryResult&& r) {
                 if (!r.report.collision_free) return;
                 r.report.inferred_sides = true;
                 r.report.sides_reading = j % readings.size() + 1;
                 r.report.loop_reading = true;
                 scene = std::move(r.scene);
                 done = cost.charged_to(r.report);
             });
    if (!done) return cost.charged_to(failed);
    if (kept) *kept = std::move(readings[done->sides_reading - 1]);  // no try reads it now
    return *done;
}

UntangleReport inferring_sides_and_retries(Scene& scene, const UntangleParams& params,
                                           const ProgressFn& progress, InputSides* kept,
                                           LeastTangled& failures) {
    if (params.input_sides && !params.input_sides->empty())
        return original_sides_tries(scene, params, progress, kept, failures);
    const Scene input = scene;
    // has_rolled_regions(input), once, when a retry first asks.
    std::optional<bool> rolled;
    auto rolled_regions = [&](const Scene& s) {
        if (!rolled) rolled = has_rolled_regions(s);
        return *rolled;
    };
    // Every try failed: where the global order is the reading (nothing read rolled), its second
    // try (no self-crossing made) once more with more passes, before all the tries once more:
    // the projection of a fold cut by chords can wander for a few hundred passes before it comes
    // out clean.
    auto more_passes = [&](Scene& s, const UntangleReport& failed) {
        if (params.more_passes_factor <= 1 || rolled_regions(input)) return failed;
        UntangleParams more = with_outside_sides(input, params);
        more.max_passes = saturated_product(params.max_passes, params.more_passes_factor);
        Scene attempt = input;
        failures.long_rounds = false;
        failures.more_passes = true;
        UntangleReport last = untangle_once(attempt, more, progress, true, failures);
        last.more_passes = true;
        failures.more_passes = false;
        return after_retry(s, failed, std::move(attempt), last);
    };
    const UntangleReport failed = with_retry_passes(
        scene, params,
        [&](Scene& s, const UntangleParams& p) {
            return with_long_rounds(
                s, p, rolled_regions,
                [&](Scene& t, const UntangleParams& q) {
                    return inferring_sides_tries(t, q, progress, kept, failures);
                },
                failures);
        },
        more_passes, failures);
    const UntangleReport report =
        with_ends_by_nearest(scene, input, params, progress, failed, failures);
    if (report.collision_free || !params.loop_readings) return report;
    return loop_readings_tries(scene, input, params, progress, kept, report, failures);
}

}  // namespace

UntangleReport untangle(Scene& scene, const UntangleParams& params, const ProgressFn& given) {
    const ProgressFn progress = numbering_tries(given);
    return clean_or_least_tangled(scene, nullptr, [&](LeastTangled& failures) {
        return untangle_tries(scene, params, progress, failures);
    });
}

namespace {

// untangle_inferring_sides() but for UntangleParams::stiffer_closed; `progress` numbers the
// tries already.
UntangleReport inferring_sides_call(Scene& scene, const UntangleParams& params,
                                    const ProgressFn& progress, InputSides* kept) {
    const Scene input = scene;
    std::optional<InputSides> tried;
    const UntangleReport report = clean_or_least_tangled(
        scene, kept,
        [&](LeastTangled& failures) {
            return inferring_sides_and_retries(scene, params, progress, kept, failures);
        },
        &tried);
    if (report.collision_free) return report;
    // The sides the result kept was tried with: the inferred ones it kept, else params' own
    // (an original's, or the global order).
    UntangleParams p = with_outside_sides(input, params);
    if (tried) {
        p.input_sides = &*tried;
        p.open_cut_bends = false;
    }
    try {
        UntangleReport last = report;
        if (report.self_crossings_after > 0 && params.untwist)
            last = untwisted_try(scene, input, p, report, progress);
        if (!last.collision_free && params.retract_ends)
            last = retracted_ends_try(scene, input, p, last, progress);
        if (!report.input_kept && !last.collision_free && params.restart)
            last = restarted_tries(scene, input, p, last, progress);
        return with_short_edges(scene, input, params, progress, last);
    } catch (...) {
        scene = input;
        throw;
    }
}

// Whether `scene` has both closed and open layers.
bool has_closed_and_open(const Scene& scene) {
    bool closed = false, open = false;
    for (const Layer& layer : scene.layers()) (layer.closed ? closed : open) = true;
    return closed && open;
}

// The mean distance of the vertices of `result` from their places in `input` (same layers).
double mean_displacement(const Scene& result, const Scene& input) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < result.size(); ++i) {
        const std::vector<Vec2>& p = result.layer(i).points;
        const std::vector<Vec2>& q = input.layer(i).points;
        for (std::size_t k = 0; k < p.size() && k < q.size(); ++k, ++count)
            sum += glm::length(p[k] - q[k]);
    }
    return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

}  // namespace

UntangleReport untangle_inferring_sides(Scene& scene, const UntangleParams& params,
                                        const ProgressFn& given, InputSides* kept) {
    const ProgressFn progress = numbering_tries(given);
    if (params.input_sides || !(params.stiffer_closed > 1.0) || !has_closed_and_open(scene))
        return inferring_sides_call(scene, params, progress, kept);
    const Scene input = scene;
    InputSides sides;
    const UntangleReport first = inferring_sides_call(scene, params, progress, &sides);
    if (kept && !sides.empty()) *kept = sides;
    if (!first.collision_free) return first;
    // Without an original, a clean result: untangle()'s tries once more from the input by the
    // sides it kept (the same reading), with the closed layers stiffer (UntangleParams::
    // stiffer_closed); kept when clean and its vertices moved less on average.
    std::vector<Layer> layers = input.layers();
    for (Layer& layer : layers)
        if (layer.closed) layer.weight *= params.stiffer_closed;
    Scene stiffer(std::move(layers), input.units());
    UntangleParams same = with_outside_sides(input, params);
    if (!sides.empty()) {
        same.input_sides = &sides;
        same.open_cut_bends = false;
    }
    UntangleReport second;
    try {
        second = clean_or_least_tangled(stiffer, nullptr, [&](LeastTangled& failures) {
            return untangle_tries(stiffer, same, progress, failures);
        });
    } catch (...) {
        scene = input;
        throw;
    }
    TriesCost cost;
    cost.add(first);
    cost.add(second);
    if (!second.collision_free ||
        !(mean_displacement(stiffer, input) < mean_displacement(scene, input)))
        return cost.charged_to(first);
    for (std::size_t i = 0; i < scene.size(); ++i) scene.set_points(i, stiffer.layer(i).points);
    // The first result's flags (its reading), the second's counts after.
    UntangleReport kept_report = as_kept(first, second, scene, input);
    kept_report.stiffer_closed = true;
    return cost.charged_to(kept_report);
}

}  // namespace strata
