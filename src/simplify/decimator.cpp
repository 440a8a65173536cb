#include "strata/simplify/decimator.h"

#include "strata/core/error.h"
#include "strata/geometry/predicates.h"

#include <glm/geometric.hpp>

#include <cmath>

namespace strata {

double span_error(const DecimationView& view, std::size_t a, std::size_t b) {
    const std::size_t n = view.original.size();
    double error = 0.0;
    for (std::size_t i = (a + 1) % n; i != b; i = (i + 1) % n)
        error = std::max(
            error, point_segment_distance(view.original[i], view.current[a], view.current[b]));
    return error;
}

namespace {

class RandomDecimator final : public Decimator {
  public:
    explicit RandomDecimator(std::uint64_t seed) : seed_(seed) {}
    std::string name() const override { return "random"; }
    double cost(std::size_t layer, const DecimationView&, std::size_t, std::size_t v,
                std::size_t) const override {
        // splitmix64 of (seed, layer, vertex): a fixed pseudo-random key, in [0, 1).
        std::uint64_t z =
            seed_ + 0x9E3779B97F4A7C15ULL * (static_cast<std::uint64_t>(layer) * 0x100000001B3ULL +
                                             static_cast<std::uint64_t>(v) + 1);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        z ^= z >> 31;
        return static_cast<double>(z >> 11) * 0x1.0p-53;
    }

  private:
    std::uint64_t seed_;
};

class VisvalingamDecimator final : public Decimator {
  public:
    std::string name() const override { return "visvalingam"; }
    double cost(std::size_t, const DecimationView& view, std::size_t a, std::size_t v,
                std::size_t b) const override {
        const Vec2 p = view.current[a], q = view.current[v], r = view.current[b];
        return 0.5 * std::abs((q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x));
    }
};

class MaxErrorDecimator final : public Decimator {
  public:
    std::string name() const override { return "max-error"; }
    double cost(std::size_t, const DecimationView& view, std::size_t a, std::size_t,
                std::size_t b) const override {
        return span_error(view, a, b);
    }
};

}  // namespace

std::unique_ptr<Decimator> make_random_decimator(std::uint64_t seed) {
    return std::make_unique<RandomDecimator>(seed);
}
std::unique_ptr<Decimator> make_visvalingam_decimator() {
    return std::make_unique<VisvalingamDecimator>();
}
std::unique_ptr<Decimator> make_max_error_decimator() {
    return std::make_unique<MaxErrorDecimator>();
}

std::unique_ptr<Decimator> make_decimator(const std::string& name, std::uint64_t seed) {
    if (name == "random") return make_random_decimator(seed);
    if (name == "visvalingam") return make_visvalingam_decimator();
    if (name == "max-error") return make_max_error_decimator();
    throw InvalidInput("decimator: unknown name '" + name +
                       "' (expected random, visvalingam or max-error)");
}

}  // namespace strata
