#include "untangle/detail/engine.h"

#include "untangle/detail/projection.h"
#include "untangle/detail/separation.h"

#include "geometry/detail/parallel.h"
#include "strata/core/error.h"
#include "strata/geometry/checks.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace strata::detail {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

std::vector<double> segment_lengths(const Layer& layer) {
    std::vector<double> lengths;
    for (std::size_t i = 0; i < layer.segment_count(); ++i)
        lengths.push_back(glm::distance(layer.segment_start(i), layer.segment_end(i)));
    return lengths;
}

double finest_layer_median(const Scene& scene) {
    double finest = std::numeric_limits<double>::infinity();
    for (const Layer& layer : scene.layers())
        finest = std::min(finest, median(segment_lengths(layer)));
    return std::isfinite(finest) ? finest : 0.0;
}

// The pieces' current vertex positions.
std::vector<std::vector<Vec2>> shapes_of(const Scene& work, const std::vector<Piece>& pieces) {
    std::vector<std::vector<Vec2>> shapes;
    for (const Piece& piece : pieces) {
        shapes.emplace_back();
        for (std::size_t v : piece.vertices)
            shapes.back().push_back(work.layer(piece.layer).points[v]);
    }
    return shapes;
}

// UntangleParams::give_up_when_stalled: `worst` holds the worst violation at the first step
// of every pass so far. True when the last one, extrapolated to the last of `passes` passes at
// the geometric mean of its last two rates of decrease, stays above `allowed`. Measured on the
// driver's untanglings (docs/simplify.md): failing ones decrease slowly and level off, the
// successful ones fall to about `allowed` within a few passes.
bool is_stalled(const std::vector<double>& worst, int passes, double allowed) {
    if (worst.size() < 5 || !(allowed > 0.0)) return false;  // from the fifth pass on
    const std::size_t k = worst.size() - 1;
    const double now = worst[k], before = worst[k - 1], earlier = worst[k - 2];
    if (!(before > 0.0) || !(earlier > 0.0)) return false;
    const double rate = std::sqrt(std::min(1.0, now / before) * std::min(1.0, before / earlier));
    const double left = static_cast<double>(passes) - 1.0 - static_cast<double>(k);
    return now * std::pow(rate, std::max(left, 0.0)) > allowed;
}

}  // namespace

double median_segment_length(const Scene& scene) {
    std::vector<double> lengths;
    for (const Layer& layer : scene.layers()) {
        const std::vector<double> l = segment_lengths(layer);
        lengths.insert(lengths.end(), l.begin(), l.end());
    }
    return median(std::move(lengths));
}

void take_input_sides(RelationSource& relations, const Scene& work, const InputSides& sides,
                      const std::vector<int>& outside_signs,
                      const std::function<std::size_t(std::size_t, std::size_t)>& id_of) {
    if (sides.empty()) return;
    const Scene& input = *relations.scene;
    const std::size_t n = work.size();
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t layer = relations.of(i);
        for (std::size_t j = 0; j < n; ++j) {
            const std::size_t other = relations.of(j);
            if (other == layer || input.layer(other).closed) continue;
            const int wanted = global_side(input.relation(layer, other), outside_signs[other]);
            if (wanted == 0) continue;
            const std::size_t count = work.layer(i).points.size();
            for (std::size_t k = 0; k < count; ++k) {
                const std::size_t id = id_of ? id_of(i, k) : k;
                const int side = sides.side(layer, id, other);
                RelationSource::Side how = RelationSource::Side::Global;
                if (sides.beyond_end(layer, id, other))
                    how = RelationSource::Side::AnySide;
                else if (side != 0 && side != wanted)
                    how = RelationSource::Side::Flipped;
                if (how == RelationSource::Side::Global) continue;
                auto& all = relations.local_sides;
                if (all.empty()) all.resize(n);
                if (all[i].empty()) all[i].resize(count);
                all[i][k].push_back({j, how});
            }
        }
    }
}

EngineSettings resolve_settings(const Scene& scene, const UntangleParams& params) {
    EngineSettings settings;
    settings.min_separation =
        params.min_separation > 0.0 ? params.min_separation : 0.01 * median_segment_length(scene);
    settings.sample_spacing =
        params.sample_spacing > 0.0 ? params.sample_spacing : finest_layer_median(scene);
    const Vec2 size = scene.bounds().size();
    settings.diagonal = std::max(std::hypot(size.x, size.y), std::numeric_limits<double>::min());
    // outside_side() of the layers not given, side by side (each reads the whole scene: a
    // local untangling's fixed cost); an exception is the first layer's, as one by one.
    const std::size_t n = scene.size();
    settings.outside_signs.resize(n);
    parallel_for_each_index(n, [&](std::size_t i) {
        settings.outside_signs[i] = i < params.outside_sides.size() && !scene.layer(i).closed
                                        ? params.outside_sides[i]
                                        : outside_side(scene, i);
    });
    return settings;
}

EngineResult run_engine(Scene& work, const std::vector<Piece>& pieces, const UntangleParams& params,
                        const RelationSource& relations, const EngineSettings& settings,
                        const std::function<bool(const Scene&)>& is_ok,
                        const ProgressFn& progress) {
    EngineResult result;
    std::size_t free_vertices = 0;
    for (const Piece& piece : pieces)
        free_vertices +=
            static_cast<std::size_t>(std::count(piece.is_free.begin(), piece.is_free.end(), 1));
    // UntangleParams::finish_separations: the finishing stage runs before the first check
    // and before the check that ends every round; before the checks after single projection
    // steps (check_every_step) only once the projection has taken the tangles out.
    SeparationParams finish;
    finish.min_separation = settings.min_separation;
    finish.outside_signs = &settings.outside_signs;
    finish.stop_when_wrong_stays = settings.finish_stop_when_wrong_stays;
    finish.open_cut_bends = settings.open_cut_bends;
    auto check = [&] {
        const auto begin = Clock::now();
        result.ok = is_ok(work);
        result.seconds_check += seconds_since(begin);
    };
    // The last run of the finishing stage left a close vertex on the wrong side of another
    // layer (true when the stage is off: nothing tells).
    bool wrong_side = true;
    // The last finish_and_check() moved nothing (the stage made no move, or undid them all)
    // and was not limited to untangled scenes, and nothing has moved since: calling
    // finish_and_check(false) again would give the same result.
    bool idle_since_finish = false;
    FinishCache finish_cache;  // the same work scene and pieces at every call
    auto finish_and_check = [&](bool only_when_untangled) {
        idle_since_finish = true;  // the stage off: the check alone, on the same scene
        if (params.finish_separations) {
            const auto begin = Clock::now();
            finish.only_when_untangled = only_when_untangled;
            const SeparationResult f =
                finish_separations(work, pieces, relations, finish, &finish_cache);
            wrong_side = f.wrong_side > 0;
            idle_since_finish = f.moves == 0 && !only_when_untangled;
            ++result.finishes;
            result.finish_moves += f.moves;
            result.seconds_finish += seconds_since(begin);
        }
        check();
    };
    finish_and_check(false);
    auto start = Clock::now();
    result.converged = result.ok;  // nothing to do is a converged run
    const int total_rounds = params.max_rounds * params.max_passes;
    std::vector<std::vector<Vec2>> rest = shapes_of(work, pieces);  // shape matching's rest
    // The fields are built once, then follow the moved vertices: each pass updates, per
    // layer, the range of vertices that moved since (LayerField::update(), which equals a
    // rebuild and, for the grid, recomputes only the leaves near the moves).
    std::optional<SceneFields> built;
    std::vector<std::vector<Vec2>> built_points;
    // The fields are sampled only at the free vertices and on their segments. Where these
    // lie in a part of the scene (a local run), grid fields cover only their box
    // (FieldParams::region, exact up to a band width beyond it): a pass that starts with them
    // more than half a band width out of it builds the fields again.
    auto samples_box = [&] {
        Box2 box;
        for (const Piece& piece : pieces) {
            const std::vector<Vec2>& x = work.layer(piece.layer).points;
            const std::size_t m = piece.vertices.size();
            for (std::size_t k = 0; k < m; ++k) {
                if (!piece.is_free[k]) continue;
                box.extend(x[piece.vertices[k]]);
                if (k > 0 || piece.is_whole_loop) box.extend(x[piece.vertices[(k + m - 1) % m]]);
                if (k + 1 < m || piece.is_whole_loop) box.extend(x[piece.vertices[(k + 1) % m]]);
            }
        }
        return box;
    };
    const Box2 bounds = work.bounds();
    const bool local_grid = params.field.backend == FieldBackend::Grid && [&] {
        const Box2 box = samples_box();
        return !(box.contains(bounds.min) && box.contains(bounds.max));
    }();
    FieldParams field_params = params.field;
    if (!local_grid) field_params.region = Box2{};  // sampled everywhere
    const bool give_up = params.give_up_when_stalled || settings.give_up_when_stalled;
    std::vector<double> worst;  // give_up: worst violation at each pass's start
    for (int pass = 0; pass < params.max_passes && !result.ok && !result.gave_up; ++pass) {
        ++result.passes;
        start = Clock::now();
        Box2 box;
        if (local_grid) box = samples_box();
        if (built && local_grid) {
            const Box2 safe = field_params.region.inflated(0.5 * built->params().band_width);
            if (!(safe.contains(box.min) && safe.contains(box.max))) {
                built.reset();
                built_points.clear();
            }
        }
        if (!built) {
            if (local_grid) field_params.region.extend(box);
            built.emplace(work, field_params, settings.outside_signs);
            for (const Layer& layer : work.layers()) built_points.push_back(layer.points);
        } else {
            for (std::size_t j = 0; j < work.size(); ++j) {
                const std::vector<Vec2>& now = work.layer(j).points;
                std::vector<Vec2>& then = built_points[j];
                std::size_t first = now.size(), last = 0;
                for (std::size_t v = 0; v < now.size(); ++v)
                    if (now[v] != then[v]) {
                        first = std::min(first, v);
                        last = v;
                    }
                if (first > last) continue;
                const std::size_t count = last - first + 1;
                built->field(j).update(now, PolylineEdit{first, count, count});
                then = now;
            }
        }
        const SceneFields& fields = *built;
        result.seconds_fields += seconds_since(start);
        // Aim above the grid's interpolation error, or its fields cannot see the gap.
        const double separation =
            params.min_separation > 0.0 || params.field.backend != FieldBackend::Grid
                ? settings.min_separation
                : std::max(settings.min_separation, 0.25 * fields.params().voxel_size);
        start = Clock::now();
        ProjectionPass engine(work, relations, fields, params, separation, settings.sample_spacing);
        engine.set_keep_simple(settings.keep_simple);
        engine.set_ends_by_nearest(settings.ends_by_nearest);
        result.converged = false;
        if (!settings.rest_at_start) rest = shapes_of(work, pieces);
        for (int round = 0; round < params.max_rounds; ++round) {
            const bool match = settings.rest_at_start ? pass > 0 || round > 0 : round > 0;
            if (match && params.shape == ShapeMode::ShapeMatching) {
                engine.match_shapes(work, pieces, rest);
                idle_since_finish = false;
            }
            // V (Eq. 7) of the round's last projection step: shape matching moves the
            // vertices at the start of every round, the projection must settle them again.
            double moved = 0.0;
            for (int s = 0; s < params.gradient_steps && !result.ok; ++s) {
                moved = engine.project(work, pieces);
                idle_since_finish = false;
                if (settings.check_every_step && s + 1 < params.gradient_steps) {
                    result.seconds_untangle += seconds_since(start);
                    finish_and_check(true);
                    start = Clock::now();
                }
                if (give_up && round == 0 && s == 0 && !result.ok) {
                    worst.push_back(engine.max_violation());
                    // EngineSettings::give_up_when_stalled: only while the finishing stage
                    // still finds a close vertex on the wrong side (a tangle the projection
                    // does not take out), not for gaps still short.
                    if ((params.give_up_when_stalled || wrong_side) &&
                        is_stalled(worst, params.max_passes, engine.slack())) {
                        result.gave_up = true;
                        break;
                    }
                }
            }
            ++result.rounds;
            if (result.ok || result.gave_up) break;
            result.mean_speed = free_vertices ? moved / static_cast<double>(free_vertices) : 0.0;
            if (progress &&
                !progress("untangle", static_cast<double>(result.rounds) / total_rounds))
                throw Cancelled();
            if (result.mean_speed <= params.tolerance * settings.diagonal) {
                result.converged = true;
                break;
            }
            // The exact check after every round: a region that is already good stops here.
            result.seconds_untangle += seconds_since(start);
            finish_and_check(false);
            start = Clock::now();
            if (result.ok) break;
        }
        result.seconds_untangle += seconds_since(start);
        // A pass whose last round ended with a full finishing run that moved nothing (often
        // one that undid its moves) would repeat that run on the same scene.
        if (!result.ok && !idle_since_finish) finish_and_check(false);
    }
    return result;
}

}  // namespace strata::detail
