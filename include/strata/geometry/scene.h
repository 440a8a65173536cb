#pragma once
/// @file A multi-layered shape: layers and their nesting ("a is under b").

#include "strata/geometry/layer.h"

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace strata {

/// How two distinct layers a and b of a scene are placed with respect to each other.
enum class Relation {
    Same,        ///< a == b.
    Under,       ///< a is under (inside) b: b is reachable from a through `outer` links.
    Over,        ///< a is over (outside) b: a is reachable from b.
    SideBySide,  ///< Neither is under the other; neither may enter the other.
};

/// "same", "under", "over" or "side-by-side" (the names of reports and messages).
const char* relation_name(Relation r);

/// What the scene's validation changed or noticed without rejecting the input.
struct SceneDiagnostics {
    std::size_t removed_duplicates = 0;  ///< Exact consecutive duplicate points removed.
    std::vector<std::string> notes;      ///< One human-readable line per change or oddity.
};

/// @brief Layers plus their nesting, validated on construction.
///
/// "a is under b" is the transitive closure of the `outer` links: a directed acyclic relation.
/// When no layer has `outer` set, the layers are one stack in the given order, innermost
/// first (layer i is directly under layer i + 1). Two layers neither of which is under the
/// other are side by side.
///
/// The required separation of two layers a, b is (t_a + t_b) / 2 for direct neighbours or
/// side-by-side layers; for a under b through a chain of links, the sum of (t_u + t_v) / 2
/// over the links, maximised over all chains from a to b.
class Scene {
  public:
    Scene() = default;

    /// Validates `layers`, removes exact consecutive duplicate points (counted in
    /// diagnostics()), resolves the `outer` names and precomputes the relations.
    /// @throws InvalidInput naming the layer, the point index or field, and the value.
    explicit Scene(std::vector<Layer> layers, std::string units = {});

    std::size_t size() const { return layers_.size(); }
    bool empty() const { return layers_.empty(); }
    const Layer& layer(std::size_t i) const { return layers_.at(i); }
    const std::vector<Layer>& layers() const { return layers_; }

    /// Replaces the points of layer `i` (algorithms move vertices and remove some).
    /// @throws InvalidInput when a point is not finite or too few points remain;
    ///         the scene is unchanged then.
    void set_points(std::size_t i, std::vector<Vec2> points);

    /// Index of the layer called `name`, if any.
    std::optional<std::size_t> find(std::string_view name) const;

    /// True when no layer had `outer` set: the layers are one stack in file order.
    bool is_implicit_stack() const { return implicit_stack_; }
    /// Indices of the layers directly outside / inside layer `i`.
    const std::vector<std::size_t>& outer_of(std::size_t i) const { return outer_.at(i); }
    const std::vector<std::size_t>& inner_of(std::size_t i) const { return inner_.at(i); }

    /// Placement of layer `a` with respect to layer `b`.
    Relation relation(std::size_t a, std::size_t b) const;
    /// Required distance between layers `a` and `b` (scene units), see the class comment,
    /// raised by raise_required_separation().
    double required_separation(std::size_t a, std::size_t b) const;
    /// A required separation raised above what the thicknesses ask (keep_input_gaps()).
    struct RaisedSeparation {
        std::size_t a = 0, b = 0;  ///< Layer indices, a < b.
        double value = 0.0;        ///< Scene units.
    };
    /// Raises required_separation(a, b) (both orders) to at least `value`; the chains through
    /// a and b are not recomputed. No effect when it is already >= value.
    /// @throws InvalidInput a == b, an index out of range, or value not finite or < 0.
    void raise_required_separation(std::size_t a, std::size_t b, double value);
    /// Every raise_required_separation() that changed a value, in call order: what a scene
    /// rebuilt from the same layers needs to be given again.
    const std::vector<RaisedSeparation>& raised_separations() const { return raised_; }

    /// Length unit of the coordinates as given by the file ("m", "dm" ...); may be empty.
    const std::string& units() const { return units_; }
    const SceneDiagnostics& diagnostics() const { return diagnostics_; }
    /// Adds a line to diagnostics().notes (readers note what they kept or changed).
    void add_note(std::string note) { diagnostics_.notes.push_back(std::move(note)); }

    /// Keys of the input file that strata does not know, as JSON text, written back unchanged.
    std::map<std::string, std::string> metadata;

    /// Bounding box of every point, and total vertex count.
    Box2 bounds() const;
    std::size_t vertex_count() const;

  private:
    std::vector<Layer> layers_;
    std::string units_;
    bool implicit_stack_ = true;
    std::vector<std::vector<std::size_t>> outer_, inner_;
    std::vector<std::vector<char>> under_;  // under_[a][b]: a is under b
    std::vector<std::vector<double>> separation_;
    std::vector<RaisedSeparation> raised_;
    SceneDiagnostics diagnostics_;
};

/// Checks one layer alone (finite coordinates, point count, parameter ranges) after removing
/// its exact consecutive duplicates; returns how many were removed.
/// @throws InvalidInput naming the layer, the point index or field, and the value.
std::size_t validate_layer(Layer& layer);

}  // namespace strata
