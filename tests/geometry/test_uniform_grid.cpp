// detail::UniformGrid against brute force on random scenes: random segments (some of zero
// length, some duplicated, some far-away outliers), inserted, erased and moved, then box
// queries (with and without repeats) and nearest queries with and without cutoffs.

#include "geometry/detail/uniform_grid.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace {

using strata::Box2;
using strata::Vec2;
using Grid = strata::detail::UniformGrid<std::uint32_t>;

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Seg {
    Vec2 a{0.0}, b{0.0};
    Box2 box() const {
        Box2 r;
        r.extend(a);
        r.extend(b);
        return r;
    }
};

double dist2(const Seg& s, const Vec2& x) {
    const Vec2 d = s.b - s.a;
    const double len2 = d.x * d.x + d.y * d.y;
    double u = len2 > 0.0 ? ((x.x - s.a.x) * d.x + (x.y - s.a.y) * d.y) / len2 : 0.0;
    u = std::clamp(u, 0.0, 1.0);
    const Vec2 c = u == 0.0 ? s.a : (u == 1.0 ? s.b : s.a + u * d);
    const Vec2 e = x - c;
    return e.x * e.x + e.y * e.y;
}

struct Best {
    double d2 = kInf;
    std::uint32_t id = std::numeric_limits<std::uint32_t>::max();
    void offer(std::uint32_t i, double d) {
        if (d < d2 || (d == d2 && i < id)) {
            d2 = d;
            id = i;
        }
    }
};

class Scene {
  public:
    /// A point (x, y) drawn in this order from `fx` then `fy` (coordinates modulo `mod` when
    /// given): argument evaluation order must not depend on the compiler.
    template <class Fx, class Fy>
    Vec2 draw(Fx& fx, Fy& fy, int mod = 0) {
        const auto x = fx(rng_);
        const auto y = fy(rng_);
        if (mod == 0) return Vec2(static_cast<double>(x), static_cast<double>(y));
        return Vec2(static_cast<double>(static_cast<int>(x) % mod),
                    static_cast<double>(static_cast<int>(y) % mod));
    }

    /// long_outliers: some segments run from the scene out to a far point (they touch a huge
    /// number of cells: only for a grid that lists large items apart).
    Scene(std::uint32_t seed, bool long_outliers) : rng_(seed), long_outliers_(long_outliers) {}

    Seg random_segment() {
        std::uniform_real_distribution<double> pos(0.0, 100.0), len(-4.0, 4.0);
        std::uniform_int_distribution<int> kind(0, 19), lattice(0, 100);
        Seg s;
        switch (kind(rng_)) {
            case 0:  // zero length
                s.a = s.b = draw(pos, pos);
                break;
            case 1:  // far-away outlier: a point, or a long segment out to it
                s.a = Vec2(1e6 * (pos(rng_) - 50.0), -3e5);
                s.b = long_outliers_ && kind(rng_) < 10 ? draw(pos, pos) : s.a;
                break;
            case 2:  // on the lattice (exact ties)
            case 3:
                s.a = draw(lattice, lattice);
                s.b = s.a + draw(lattice, lattice, 3);
                break;
            case 4:  // a copy of a live one (same geometry, another id)
                if (!live_.empty()) {
                    s = std::next(live_.begin(), static_cast<long>(rng_() % live_.size()))->second;
                    break;
                }
                [[fallthrough]];
            default:
                s.a = draw(pos, pos);
                s.b = s.a + draw(len, len);
        }
        return s;
    }

    /// Fills `grid` with `count` new segments by build() (dense cells packed), then checks.
    void build(Grid& grid, int count) {
        std::vector<std::uint32_t> ids;
        for (int k = 0; k < count; ++k) {
            live_[next_id_] = random_segment();
            ids.push_back(next_id_++);
        }
        grid.build(ids, [&](std::uint32_t id) { return live_.at(id).box(); });
        check(grid);
    }

    void run(Grid& grid, int steps) {
        for (int step = 0; step < steps; ++step) {
            const int op = static_cast<int>(rng_() % 10);
            if (op < 5 || live_.empty()) {
                const Seg s = random_segment();
                live_[next_id_] = s;
                grid.insert(next_id_++, s.box());
            } else if (op < 7) {
                auto it = std::next(live_.begin(), static_cast<long>(rng_() % live_.size()));
                grid.erase(it->first, it->second.box());
                live_.erase(it);
            } else {
                auto it = std::next(live_.begin(), static_cast<long>(rng_() % live_.size()));
                const Seg s = random_segment();
                grid.move(it->first, it->second.box(), s.box());
                it->second = s;
            }
            if (step % 50 == 49) check(grid);
        }
        check(grid);
    }

  private:
    Vec2 random_point() {
        std::uniform_real_distribution<double> pos(-20.0, 120.0);
        std::uniform_int_distribution<int> kind(0, 9), lattice(0, 100);
        switch (kind(rng_)) {
            case 0:
                return Vec2(1e5 * (pos(rng_) - 50.0), 2e5);  // far out
            case 1:
            case 2: {
                const Vec2 on = draw(lattice, lattice);
                return on + Vec2(0.5 * (lattice(rng_) % 2), 0.0);
            }
            default:
                return draw(pos, pos);
        }
    }

    void check(const Grid& grid) {
        std::uniform_real_distribution<double> size(0.0, 30.0), cut(0.0, 10.0);
        for (int q = 0; q < 40; ++q) {
            // Box queries.
            Box2 box;
            const Vec2 c = random_point();
            box.extend(c);
            box.extend(c + draw(size, size));
            std::multiset<std::uint32_t> all;
            grid.query(box, [&](std::uint32_t id) { all.insert(id); });
            std::vector<std::uint32_t> once;
            grid.query_once(
                box, [&](std::uint32_t id) { return live_.at(id).box(); },
                [&](std::uint32_t id) { once.push_back(id); });
            std::sort(once.begin(), once.end());
            std::vector<std::uint32_t> want;
            for (const auto& [id, s] : live_)
                if (s.box().overlaps(box)) want.push_back(id);
            REQUIRE(once == want);  // exactly the meeting ones, each once
            for (std::uint32_t id : want) REQUIRE(all.count(id) > 0);
            for (std::uint32_t id : all) REQUIRE(live_.count(id) == 1);  // nothing stale

            // Nearest queries, without and with a cutoff.
            const Vec2 x = random_point();
            for (const double cutoff : {kInf, cut(rng_)}) {
                Best brute;
                for (const auto& [id, s] : live_) brute.offer(id, dist2(s, x));
                Best got;
                std::set<std::uint32_t> offered;
                grid.nearest(x, cutoff, [&](std::uint32_t id) {
                    offered.insert(id);
                    got.offer(id, dist2(live_.at(id), x));
                    return got.d2;
                });
                if (brute.d2 < cutoff * cutoff) {
                    REQUIRE(got.id == brute.id);
                    REQUIRE(got.d2 == brute.d2);
                } else {
                    REQUIRE(!(got.d2 < cutoff * cutoff));
                }
                ++queries_;
                offered_ += offered.size();
            }
            // nearest_within() from a candidate the caller measured (the brute-force winner
            // or a farther item): the same winner.
            if (!live_.empty()) {
                Best brute;
                for (const auto& [id, s] : live_) brute.offer(id, dist2(s, x));
                auto it = live_.begin();
                std::advance(it, static_cast<long>(rng_() % live_.size()));
                for (const std::uint32_t seed : {brute.id, it->first}) {
                    Best got;
                    got.offer(seed, dist2(live_.at(seed), x));
                    grid.nearest_within(x, std::sqrt(got.d2), [&](std::uint32_t id) {
                        got.offer(id, dist2(live_.at(id), x));
                        return got.d2;
                    });
                    REQUIRE(got.id == brute.id);
                    REQUIRE(got.d2 == brute.d2);
                }
            }
        }
    }

  public:
    std::size_t live() const { return live_.size(); }
    std::size_t queries_ = 0, offered_ = 0;

  private:
    std::mt19937 rng_;
    bool long_outliers_ = false;
    std::map<std::uint32_t, Seg> live_;
    std::uint32_t next_id_ = 0;
};

}  // namespace

TEST_CASE("UniformGrid: box and nearest queries match brute force on random scenes",
          "[uniform_grid]") {
    for (const double cell : {0.37, 2.0, 16.0}) {
        for (int layout = 0; layout < 3; ++layout) {
            strata::detail::UniformGridParams p;
            p.cell = cell;
            p.origin = layout == 2 ? Vec2(-3.25, 7.5) : Vec2(0.0);
            if (layout >= 1) {  // dense over the scene's usual extent, hashed outside
                p.dense_bounds.extend(Vec2(0.0));
                p.dense_bounds.extend(Vec2(100.0));
            }
            if (layout == 2) p.max_item_cells = 64.0;  // long items in the list of large ones
            Grid grid(p);
            Scene scene(
                static_cast<std::uint32_t>(1000 * cell) + static_cast<std::uint32_t>(layout),
                layout == 2);
            INFO("cell " << cell << " layout " << layout);
            if (layout >= 1) scene.build(grid, 300);  // packed, then unpacked by the edits
            scene.run(grid, 1500);
            REQUIRE(scene.live() > 100);
            REQUIRE(grid.memory_bytes() > 0);
            // The search is a search: it offers far fewer items than there are.
            REQUIRE(static_cast<double>(scene.offered_) <
                    0.5 * static_cast<double>(scene.queries_ * scene.live()));
        }
    }
}

TEST_CASE("UniformGrid: clear() and build() refill the same cells", "[uniform_grid]") {
    strata::detail::UniformGridParams p;
    p.cell = 1.0;
    Grid grid(p);
    std::vector<Seg> segs = {
        {Vec2(0.0), Vec2(3.0, 0.5)}, {Vec2(5.0), Vec2(5.0)}, {Vec2(-2.0, 1.0), Vec2(-1.0, 4.0)}};
    std::vector<std::uint32_t> ids = {0, 1, 2};
    grid.build(ids, [&](std::uint32_t i) { return segs[i].box(); });
    std::vector<std::uint32_t> got;
    Box2 all;
    all.extend(Vec2(-10.0));
    all.extend(Vec2(10.0));
    grid.query_once(
        all, [&](std::uint32_t i) { return segs[i].box(); },
        [&](std::uint32_t i) { got.push_back(i); });
    std::sort(got.begin(), got.end());
    REQUIRE(got == ids);
    grid.clear();
    got.clear();
    grid.query(all, [&](std::uint32_t i) { got.push_back(i); });
    REQUIRE(got.empty());
    bool offered = false;
    grid.nearest(Vec2(0.0), kInf, [&](std::uint32_t) {
        offered = true;
        return 0.0;
    });
    REQUIRE(!offered);
}
