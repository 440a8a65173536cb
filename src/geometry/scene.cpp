#include "strata/geometry/scene.h"

#include "strata/core/error.h"
#include "strata/core/format.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

namespace strata {

const char* relation_name(Relation r) {
    switch (r) {
        case Relation::Same:
            return "same";
        case Relation::Under:
            return "under";
        case Relation::Over:
            return "over";
        case Relation::SideBySide:
            return "side-by-side";
    }
    return "?";
}

namespace {

std::string layer_label(const Layer& layer, std::size_t index) {
    return "layer '" + shown_text(layer.name) + "' (#" + std::to_string(index) + ")";
}

void check_finite(const Layer& layer, const std::string& label) {
    for (std::size_t k = 0; k < layer.points.size(); ++k) {
        const Vec2& p = layer.points[k];
        if (!std::isfinite(p.x) || !std::isfinite(p.y))
            throw InvalidInput(label + ": point " + std::to_string(k) +
                               " has a non-finite coordinate (" + format_number(p.x) + ", " +
                               format_number(p.y) + ")");
    }
}

void check_count(const Layer& layer, const std::string& label) {
    const std::size_t need = layer.closed ? 3 : 2;
    if (layer.points.size() < need)
        throw InvalidInput(label + ": a " + (layer.closed ? "closed" : "open") +
                           " layer needs at least " + std::to_string(need) +
                           " distinct points (got " + std::to_string(layer.points.size()) + ")");
}

// Removes exact consecutive duplicates (and, when closed, last == first); returns the count.
std::size_t remove_duplicates(std::vector<Vec2>& points, bool closed) {
    const std::size_t before = points.size();
    points.erase(std::unique(points.begin(), points.end()), points.end());
    if (closed)
        while (points.size() > 1 && points.back() == points.front()) points.pop_back();
    return before - points.size();
}

}  // namespace

std::size_t validate_layer(Layer& layer) {
    const std::string label = "layer '" + shown_text(layer.name) + "'";
    if (layer.name.empty()) throw InvalidInput("layer: name must not be empty");
    auto check_range = [&](const char* field, double value, double lo, double hi, bool open_lo) {
        const bool ok = std::isfinite(value) && (open_lo ? value > lo : value >= lo) && value <= hi;
        if (!ok)
            throw InvalidInput(label + ": " + field + " must be in " + (open_lo ? "(" : "[") +
                               format_number(lo) + ", " + format_number(hi) + "] (got " +
                               format_number(value) + ")");
    };
    const double inf = std::numeric_limits<double>::max();
    check_range("thickness", layer.thickness, 0.0, inf, false);
    check_range("weight", layer.weight, 0.0, inf, true);
    if (layer.alpha) check_range("alpha", *layer.alpha, 0.0, 1.0, false);
    if (layer.beta) check_range("beta", *layer.beta, 0.0, 1.0, false);
    check_finite(layer, label);  // before removing duplicates: indices are the input's
    const std::size_t removed = remove_duplicates(layer.points, layer.closed);
    check_count(layer, label);
    return removed;
}

Scene::Scene(std::vector<Layer> layers, std::string units)
    : layers_(std::move(layers)), units_(std::move(units)) {
    const std::size_t n = layers_.size();
    std::unordered_map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < n; ++i) {
        Layer& layer = layers_[i];
        if (layer.name.empty())
            throw InvalidInput("layer #" + std::to_string(i) + ": name must not be empty");
        if (!index.emplace(layer.name, i).second)
            throw InvalidInput(layer_label(layer, i) + ": name already used by layer #" +
                               std::to_string(index[layer.name]));
        const std::size_t removed = validate_layer(layer);
        if (removed > 0) {
            diagnostics_.removed_duplicates += removed;
            diagnostics_.notes.push_back(layer_label(layer, i) + ": removed " +
                                         std::to_string(removed) +
                                         " exact consecutive duplicate point(s)");
        }
        if (layer.outer) implicit_stack_ = false;
    }

    outer_.assign(n, {});
    inner_.assign(n, {});
    if (implicit_stack_) {
        for (std::size_t i = 0; i + 1 < n; ++i) outer_[i].push_back(i + 1);
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            if (!layers_[i].outer) continue;
            for (const std::string& name : *layers_[i].outer) {
                auto it = index.find(name);
                if (it == index.end())
                    throw InvalidInput(layer_label(layers_[i], i) + ": outer names '" +
                                       shown_text(name) + "', which is not a layer of the scene");
                if (std::find(outer_[i].begin(), outer_[i].end(), it->second) != outer_[i].end()) {
                    diagnostics_.notes.push_back(layer_label(layers_[i], i) + ": outer lists '" +
                                                 shown_text(name) + "' twice; counted once");
                    continue;
                }
                outer_[i].push_back(it->second);
            }
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j : outer_[i]) inner_[j].push_back(i);

    // Topological order (Kahn); a leftover means a cycle, which we report by walking it.
    std::vector<std::size_t> indegree(n, 0), order;
    for (std::size_t i = 0; i < n; ++i) indegree[i] = inner_[i].size();
    std::vector<std::size_t> ready;
    for (std::size_t i = 0; i < n; ++i)
        if (indegree[i] == 0) ready.push_back(i);
    while (!ready.empty()) {
        const std::size_t i = ready.back();
        ready.pop_back();
        order.push_back(i);
        for (std::size_t j : outer_[i])
            if (--indegree[j] == 0) ready.push_back(j);
    }
    if (order.size() != n) {
        std::size_t start = 0;
        while (indegree[start] == 0) ++start;
        // Follow links that stay inside the cyclic part until a layer repeats.
        std::vector<std::size_t> path{start};
        std::vector<char> seen(n, 0);
        seen[start] = 1;
        for (;;) {
            std::size_t next = n;
            for (std::size_t j : outer_[path.back()])
                if (indegree[j] != 0) {
                    next = j;
                    break;
                }
            path.push_back(next);
            if (seen[next]) break;
            seen[next] = 1;
        }
        std::string cycle;
        auto first = std::find(path.begin(), path.end(), path.back());
        for (auto it = first; it != path.end(); ++it)
            cycle += (it == first ? "" : " -> ") + ("'" + shown_text(layers_[*it].name) + "'");
        throw InvalidInput("scene: outer links form a cycle: " + cycle);
    }

    // Longest chain of half-thickness sums from each layer, over the DAG in topological order.
    under_.assign(n, std::vector<char>(n, 0));
    separation_.assign(n, std::vector<double>(n, 0.0));
    std::vector<std::size_t> position(n);
    for (std::size_t k = 0; k < n; ++k) position[order[k]] = k;
    for (std::size_t a = 0; a < n; ++a) {
        std::vector<double> best(n, -1.0);
        best[a] = 0.0;
        for (std::size_t k = position[a]; k < n; ++k) {
            const std::size_t u = order[k];
            if (best[u] < 0.0) continue;
            for (std::size_t v : outer_[u]) {
                const double link = 0.5 * (layers_[u].thickness + layers_[v].thickness);
                best[v] = std::max(best[v], best[u] + link);
            }
        }
        for (std::size_t b = 0; b < n; ++b)
            if (b != a && best[b] >= 0.0) {
                under_[a][b] = 1;
                separation_[a][b] = separation_[b][a] = best[b];
            }
    }
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b)
            if (a != b && !under_[a][b] && !under_[b][a])
                separation_[a][b] = 0.5 * (layers_[a].thickness + layers_[b].thickness);
}

void Scene::set_points(std::size_t i, std::vector<Vec2> points) {
    Layer& layer = layers_.at(i);
    std::swap(layer.points, points);
    try {
        check_finite(layer, layer_label(layer, i));
        check_count(layer, layer_label(layer, i));
    } catch (...) {
        std::swap(layer.points, points);
        throw;
    }
}

std::optional<std::size_t> Scene::find(std::string_view name) const {
    for (std::size_t i = 0; i < layers_.size(); ++i)
        if (layers_[i].name == name) return i;
    return std::nullopt;
}

Relation Scene::relation(std::size_t a, std::size_t b) const {
    if (a == b) return Relation::Same;
    if (under_.at(a).at(b)) return Relation::Under;
    if (under_.at(b).at(a)) return Relation::Over;
    return Relation::SideBySide;
}

double Scene::required_separation(std::size_t a, std::size_t b) const {
    return a == b ? 0.0 : separation_.at(a).at(b);
}

void Scene::raise_required_separation(std::size_t a, std::size_t b, double value) {
    if (a == b || a >= layers_.size() || b >= layers_.size())
        throw InvalidInput("scene: raise_required_separation needs two distinct layers (got " +
                           std::to_string(a) + " and " + std::to_string(b) + " of " +
                           std::to_string(layers_.size()) + ")");
    if (!(std::isfinite(value) && value >= 0.0))
        throw InvalidInput("scene: raise_required_separation value must be finite and >= 0 (got " +
                           format_number(value) + ")");
    if (separation_[a][b] >= value) return;
    separation_[a][b] = separation_[b][a] = value;
    raised_.push_back({std::min(a, b), std::max(a, b), value});
}

Box2 Scene::bounds() const {
    Box2 box;
    for (const Layer& layer : layers_) box.extend(layer.bounds());
    return box;
}

std::size_t Scene::vertex_count() const {
    std::size_t count = 0;
    for (const Layer& layer : layers_) count += layer.points.size();
    return count;
}

}  // namespace strata
