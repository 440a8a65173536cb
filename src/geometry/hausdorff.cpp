#include "strata/geometry/hausdorff.h"

#include "geometry/detail/segment_index.h"
#include "strata/core/error.h"
#include "strata/core/format.h"
#include "strata/geometry/predicates.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace strata {

namespace {

using detail::Nearest;
using detail::nearest_on;
using detail::SegmentIndex;

constexpr double kInf = std::numeric_limits<double>::infinity();

// max over the points of `a` of the distance to `b`, by branch and bound (see hausdorff()).
// An interval [p0, p1] of a segment of `a`, with nearest segments s0, s1 of `b` at its ends,
// is bounded above by the 1-Lipschitz bound (d0 + d1 + L) / 2 and, since the distance to one
// segment is convex along a line, by max(d(p0, s), d(p1, s)) for s = s0, s1. The second
// bound settles parallel and receding stretches without splitting them to the tolerance.
double one_sided_hausdorff(const Layer& a, const SegmentIndex& b, double tolerance) {
    struct End {
        Vec2 p;
        double d;
        std::size_t s;
    };
    struct Interval {
        double upper;
        End e0, e1;
        bool operator<(const Interval& other) const { return upper < other.upper; }
    };
    auto evaluate = [&](const Vec2& p, SegmentIndex::Cursor* cursor = nullptr) {
        const Nearest n = nearest_on(b, p, kInf, cursor);
        return End{p, n.distance, n.segment};
    };
    auto to_segment = [&](const Vec2& p, std::size_t s) {
        return point_segment_distance(p, b.start(s), b.end(s));
    };
    double lower = 0.0;
    std::vector<Interval> heap;
    auto push = [&](const End& e0, const End& e1) {
        const double length = std::hypot(e1.p.x - e0.p.x, e1.p.y - e0.p.y);
        double upper = 0.5 * (e0.d + e1.d + length);
        upper = std::min(upper, std::max(e0.d, to_segment(e1.p, e0.s)));
        upper = std::min(upper, std::max(e1.d, to_segment(e0.p, e1.s)));
        if (upper > lower + tolerance) {
            heap.push_back({upper, e0, e1});
            std::push_heap(heap.begin(), heap.end());
        }
    };
    std::vector<End> vertices;
    vertices.reserve(a.points.size());
    SegmentIndex::Cursor cursor;  // the vertices in order: each search starts at the last
    for (const Vec2& p : a.points) {
        vertices.push_back(evaluate(p, &cursor));
        lower = std::max(lower, vertices.back().d);
    }
    const std::size_t count = a.segment_count();
    for (std::size_t s = 0; s < count; ++s) push(vertices[s], vertices[(s + 1) % vertices.size()]);
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end());
        const Interval top = heap.back();
        heap.pop_back();
        if (top.upper <= lower + tolerance) break;  // every other bound is lower still
        const Vec2 mid = 0.5 * (top.e0.p + top.e1.p);
        if (mid == top.e0.p || mid == top.e1.p) continue;  // no finer split in doubles
        const End m = evaluate(mid);
        lower = std::max(lower, m.d);
        push(top.e0, m);
        push(m, top.e1);
    }
    return lower;
}

void check_hausdorff_input(const Layer& layer, const char* which) {
    if (layer.points.empty())
        throw InvalidInput(std::string("hausdorff: layer ") + which + " ('" +
                           shown_text(layer.name) + "') has no points");
    for (std::size_t k = 0; k < layer.points.size(); ++k) {
        const Vec2& p = layer.points[k];
        if (!std::isfinite(p.x) || !std::isfinite(p.y))
            throw InvalidInput(std::string("hausdorff: layer ") + which + " ('" +
                               shown_text(layer.name) + "'): point " + std::to_string(k) +
                               " has a non-finite coordinate (" + format_number(p.x) + ", " +
                               format_number(p.y) + ")");
    }
}

// A layer as seen by the distance queries: a single point becomes one zero-length segment.
Layer as_segments(const Layer& layer) {
    Layer copy;
    copy.name = layer.name;
    copy.closed = layer.closed && layer.points.size() >= 3;
    copy.points = layer.points;
    if (copy.points.size() == 1) copy.points.push_back(copy.points.front());
    return copy;
}

}  // namespace

HausdorffDistance hausdorff(const Layer& a, const Layer& b, double tolerance) {
    if (!std::isfinite(tolerance) || tolerance <= 0.0)
        throw InvalidInput("hausdorff: tolerance must be a finite value > 0 (got " +
                           format_number(tolerance) + ")");
    check_hausdorff_input(a, "a");
    check_hausdorff_input(b, "b");
    const Layer sa = as_segments(a), sb = as_segments(b);
    const SegmentIndex ia(sa), ib(sb);
    HausdorffDistance result;
    result.a_to_b = one_sided_hausdorff(sa, ib, tolerance);
    result.b_to_a = one_sided_hausdorff(sb, ia, tolerance);
    return result;
}

}  // namespace strata
