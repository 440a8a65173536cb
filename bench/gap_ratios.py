#!/usr/bin/env python3
"""Smallest gap of every near pair of layers before and after a simplification.

    bench/gap_ratios.py INPUT_DIR OUTPUT_DIR      (scenes of the same names in both)

For each pair of layers whose smallest gap in the input is > 0 and below 5% of the input's
bounding-box diagonal (the near pairs of `strata check`), prints the worst ratio
gap after / gap before per slice, and a summary line: the smallest ratio over all slices, and
the slices and pairs whose ratio is below 0.9. The gap is the smallest distance from a vertex
of one layer to the other layer (both ways), as in `strata check`. A pair whose segments
cross in the input has a gap of 0 there (the vertex distance would miss the crossing): it is
left out of the ratios and counted apart, with its smallest gap after.
"""
import json
import math
import os
import sys


def seg_dist(p, a, b):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    L = dx * dx + dy * dy
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / L))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def segments(layer):
    p = layer["points"]
    s = list(zip(p, p[1:]))
    if layer.get("closed"):
        s.append((p[-1], p[0]))
    return s


def box(layer):
    xs = [q[0] for q in layer["points"]]
    ys = [q[1] for q in layer["points"]]
    return min(xs), min(ys), max(xs), max(ys)


def box_gap(a, b):
    dx = max(0.0, a[0] - b[2], b[0] - a[2])
    dy = max(0.0, a[1] - b[3], b[1] - a[3])
    return math.hypot(dx, dy)


def gap(la, lb, cutoff):
    best = cutoff
    for x, y in ((la, lb), (lb, la)):
        segs = segments(y)
        for p in x["points"]:
            for a, b in segs:
                # cheap reject by the segment's box
                if min(a[0], b[0]) - best > p[0] or max(a[0], b[0]) + best < p[0]:
                    continue
                if min(a[1], b[1]) - best > p[1] or max(a[1], b[1]) + best < p[1]:
                    continue
                best = min(best, seg_dist(p, a, b))
    return best


def orient(a, b, c):
    v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (v > 0) - (v < 0)


def on_segment(a, b, p):
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


def segments_meet(a, b, c, d):
    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    if o1 != o2 and o3 != o4:
        return True
    return ((o1 == 0 and on_segment(a, b, c)) or (o2 == 0 and on_segment(a, b, d)) or
            (o3 == 0 and on_segment(c, d, a)) or (o4 == 0 and on_segment(c, d, b)))


def layers_cross(la, lb):
    sb = [(a, b, box({"points": [a, b]})) for a, b in segments(lb)]
    for a, b in segments(la):
        ba = box({"points": [a, b]})
        for c, d, bb in sb:
            if box_gap(ba, bb) == 0 and segments_meet(a, b, c, d):
                return True
    return False


def pair_gaps(scene, near, only=None):
    layers = scene["layers"]
    boxes = [box(l) for l in layers]
    out = {}
    for i in range(len(layers)):
        for j in range(i + 1, len(layers)):
            key = (layers[i]["name"], layers[j]["name"])
            if only is not None and key not in only:
                continue
            if box_gap(boxes[i], boxes[j]) >= near:
                continue
            out[key] = gap(layers[i], layers[j], near)
    return out


def main():
    src, dst = sys.argv[1], sys.argv[2]
    worst_all, bad = math.inf, []
    crossing, crossing_after = [], []  # pairs that cross in the input; their gaps after
    for name in sorted(os.listdir(src)):
        if not name.endswith(".json") or not os.path.exists(os.path.join(dst, name)):
            continue
        before = json.load(open(os.path.join(src, name)))
        after = json.load(open(os.path.join(dst, name)))
        b = [box(l) for l in before["layers"]]
        diag = math.hypot(max(q[2] for q in b) - min(q[0] for q in b),
                          max(q[3] for q in b) - min(q[1] for q in b))
        near = 0.05 * diag
        g0 = {k: v for k, v in pair_gaps(before, near).items() if 0 < v < near}
        by_name = {l["name"]: l for l in before["layers"]}
        for k in [k for k in g0 if layers_cross(by_name[k[0]], by_name[k[1]])]:
            del g0[k]
            crossing.append((name, k))
        g1 = pair_gaps(after, math.inf, set(g0) | {k for n, k in crossing if n == name})
        for n, k in crossing:
            if n == name:
                crossing_after.append((name, k, g1.get(k)))
                del g1[k]
        worst, worst_pair = math.inf, None
        for k, v in g0.items():
            r = g1.get(k, math.inf) / v
            if r < worst:
                worst, worst_pair = r, k
            if r < 0.9:
                bad.append((name, k, v, g1.get(k)))
        worst_all = min(worst_all, worst)
        print("%-36s pairs %3d  worst gap after/before %.3f %s" % (name, len(g0), worst,
              "" if worst_pair is None else "(%s, %s)" % worst_pair))
    print("smallest ratio %.3f; pairs below 0.9: %d; pairs crossing in the input: %d" %
          (worst_all, len(bad), len(crossing)))
    for name, k, v, w in bad[:20]:
        print("  %s %s x %s: %.3g -> %.3g" % (name, k[0], k[1], v, w))
    for name, k, w in crossing_after[:20]:
        print("  crossing in %s: %s x %s, gap after %.3g" % (name, k[0], k[1], w))


if __name__ == "__main__":
    main()
