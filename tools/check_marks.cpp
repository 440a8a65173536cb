#include "check_marks.h"

#include "cli_util.h"

#include <cmath>
#include <cstdio>

namespace strata::cli {

std::string short_number(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::vector<SvgMark> contact_marks(const Scene& scene, const CheckReport& report) {
    std::vector<SvgMark> marks;
    auto name = [&](std::size_t layer) { return shown_name(scene.layer(layer).name); };
    for (const Crossing& c : report.crossings)
        marks.push_back({c.point, c.point,
                         std::string(c.is_touch ? "touch" : "crossing") + ": " + name(c.layer_a) +
                             " segment " + std::to_string(c.segment_a) + ", " + name(c.layer_b) +
                             " segment " + std::to_string(c.segment_b)});
    for (const Crossing& c : report.self_crossings)
        marks.push_back({c.point, c.point,
                         "self-crossing: " + name(c.layer_a) + " segments " +
                             std::to_string(c.segment_a) + " and " + std::to_string(c.segment_b)});
    return marks;
}

SvgWriteParams check_marks(const Scene& scene, const CheckReport& report,
                           double separation_tolerance) {
    SvgWriteParams svg;
    svg.marks = contact_marks(scene, report);
    auto name = [&](std::size_t layer) { return shown_name(scene.layer(layer).name); };
    auto at = [&](std::size_t layer, std::size_t vertex) {
        return scene.layer(layer).points[vertex];
    };
    for (const NestingViolation& v : report.nesting_violations)
        svg.marks.push_back({at(v.layer, v.vertex), at(v.layer, v.vertex),
                             "wrong side: " + name(v.layer) + " vertex " +
                                 std::to_string(v.vertex) + " against " + name(v.other)});
    for (const SeparationViolation& v : report.separation_violations)
        svg.marks.push_back({at(v.layer, v.vertex), at(v.layer, v.vertex),
                             "too close: " + name(v.layer) + " vertex " + std::to_string(v.vertex) +
                                 " is " + short_number(v.distance) + " from " + name(v.other) +
                                 ", required " + short_number(v.required)});
    for (const PairSeparation& p : report.pairs)
        if (p.required > 0.0 && p.gap < p.required * (1.0 - separation_tolerance))
            svg.marks.push_back({p.at_a, p.at_b,
                                 "closest: " + name(p.layer_a) + " and " + name(p.layer_b) +
                                     ", gap " + short_number(p.gap) + ", required " +
                                     short_number(p.required)});
    return svg;
}

}  // namespace strata::cli
