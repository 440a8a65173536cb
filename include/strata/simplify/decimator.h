#pragma once
/// @file Pluggable vertex decimation: a decimator ranks the vertices of a layer by the cost of
/// removing them (lowest first), as libigl's decimate() takes a cost callback. The collision-
/// free driver (simplify.h) decides whether a removal is kept.

#include "strata/core/types.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace strata {

/// What a decimator sees of a layer being decimated. Vertex ids are the indices of the input
/// layer; they do not change while vertices are removed.
struct DecimationView {
    const std::vector<Vec2>& original;  ///< The input positions, by vertex id.
    const std::vector<Vec2>& current;   ///< Current positions (the untangling moves them).
    bool closed = false;                ///< The layer is closed (ids wrap around).
};

/// Ranks removals. Implementations must be deterministic (same cost for the same arguments).
class Decimator {
  public:
    virtual ~Decimator() = default;
    /// Short name ("random", "visvalingam", "max-error").
    virtual std::string name() const = 0;
    /// Cost of removing vertex `v` of `layer` whose alive neighbours are `a` (before) and `b`
    /// (after). Lower costs are removed first. Finite.
    virtual double cost(std::size_t layer, const DecimationView& view, std::size_t a, std::size_t v,
                        std::size_t b) const = 0;
};

/// Largest distance from the input vertices strictly between ids `a` and `b` (wrapping for
/// closed layers) to the segment joining the current positions of `a` and `b`: the error a
/// removal leaves behind, in scene units.
double span_error(const DecimationView& view, std::size_t a, std::size_t b);

/// Random order (the paper's experiments): a seeded pseudo-random key per vertex.
std::unique_ptr<Decimator> make_random_decimator(std::uint64_t seed);
/// Visvalingam-Whyatt: the area of the triangle (a, v, b), scene units squared.
std::unique_ptr<Decimator> make_visvalingam_decimator();
/// Error driven: span_error() of the removal (a Douglas-Peucker-like bound on the distance
/// from every input vertex of the span to the simplified layer), scene units.
std::unique_ptr<Decimator> make_max_error_decimator();

/// "random", "visvalingam" or "max-error". @throws InvalidInput naming the unknown name.
std::unique_ptr<Decimator> make_decimator(const std::string& name, std::uint64_t seed);

}  // namespace strata
