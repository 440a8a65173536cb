#!/usr/bin/env python3
"""Draws docs/figures/composition_1d.svg: the composition operator along a line crossing two
tangled layers (docs/composition.md). Standard library only.

Along the line, layer 1 (inner) occupies [-1, 1] and layer 2 (outer) [-0.8, 1.6]: on the left
the outer layer's boundary lies inside the inner one (tangled), on the right the order holds.
f_k is the signed distance (> 0 outside). The two-layer composition is the closed form
fhat_1 = max(f_1, m + s), fhat_2 = min(f_2, m), m = (w_1 (f_1 - s) + w_2 f_2) / (w_1 + w_2).

Usage: python3 docs/figures/composition_1d.py [OUT.svg]
"""
import sys

S = 0.1  # separation required between the layers
X0, X1 = -2.0, 2.4
Y0, Y1 = -1.3, 1.5


def f1(x):
    return abs(x) - 1.0


def f2(x):
    return abs(x - 0.4) - 1.2


def compose(x, w1, w2):
    a, b = f1(x), f2(x)
    m = (w1 * (a - S) + w2 * b) / (w1 + w2)
    return max(a, m + S), min(b, m)


def panel(ox, oy, width, height, w1, w2, title):
    """SVG elements of one panel whose top-left corner is (ox, oy)."""
    def px(x):
        return ox + (x - X0) / (X1 - X0) * width

    def py(y):
        return oy + (Y1 - y) / (Y1 - Y0) * height

    def path(fn, colour, dash=""):
        n = 440
        pts = []
        for i in range(n + 1):
            x = X0 + (X1 - X0) * i / n
            pts.append(f"{px(x):.2f},{py(fn(x)):.2f}")
        extra = f' stroke-dasharray="{dash}"' if dash else ""
        return (f'<polyline points="{" ".join(pts)}" fill="none" stroke="{colour}" '
                f'stroke-width="{1.4 if dash else 2.2}"{extra}/>')

    out = [f'<g font-family="sans-serif" font-size="12">']
    # Where the order fails (f_1 < f_2 + s) the layers are pooled: shade it.
    n = 880
    inside = False
    start = 0.0
    for i in range(n + 1):
        x = X0 + (X1 - X0) * i / n
        bad = f1(x) < f2(x) + S
        if bad and not inside:
            inside, start = True, x
        if inside and (not bad or i == n):
            inside = False
            out.append(f'<rect x="{px(start):.2f}" y="{oy}" width="{px(x) - px(start):.2f}" '
                       f'height="{height}" fill="#f3e3c3"/>')
    out.append(f'<rect x="{ox}" y="{oy}" width="{width}" height="{height}" fill="none" '
               f'stroke="#444"/>')
    out.append(f'<line x1="{ox}" y1="{py(0):.2f}" x2="{ox + width}" y2="{py(0):.2f}" '
               f'stroke="#888"/>')
    for t in range(-2, 3):
        out.append(f'<line x1="{px(t):.2f}" y1="{oy + height}" x2="{px(t):.2f}" '
                   f'y2="{oy + height + 4}" stroke="#444"/>')
        out.append(f'<text x="{px(t):.2f}" y="{oy + height + 17}" text-anchor="middle">{t}</text>')
    out.append(path(f1, "#1f5fbf", "6,4"))
    out.append(path(f2, "#c0392b", "6,4"))
    out.append(path(lambda x: compose(x, w1, w2)[0], "#1f5fbf"))
    out.append(path(lambda x: compose(x, w1, w2)[1], "#c0392b"))
    # Zero sets of the composed fields: the new layer positions on this line.
    for k, colour in ((0, "#1f5fbf"), (1, "#c0392b")):
        for i in range(n):
            xa = X0 + (X1 - X0) * i / n
            xb = X0 + (X1 - X0) * (i + 1) / n
            ya, yb = compose(xa, w1, w2)[k], compose(xb, w1, w2)[k]
            if (ya < 0) != (yb < 0):
                xz = xa + (xb - xa) * ya / (ya - yb)
                out.append(f'<circle cx="{px(xz):.2f}" cy="{py(0):.2f}" r="4" fill="{colour}"/>')
    out.append(f'<text x="{ox + width / 2}" y="{oy - 8}" text-anchor="middle" '
               f'font-size="13">{title}</text>')
    out.append('</g>')
    return out


def main():
    target = sys.argv[1] if len(sys.argv) > 1 else "docs/figures/composition_1d.svg"
    width, height, margin = 380, 260, 40
    total_w = 2 * width + 3 * margin
    total_h = height + 2 * margin + 80
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{total_w}" height="{total_h}" '
           f'viewBox="0 0 {total_w} {total_h}">',
           f'<rect width="{total_w}" height="{total_h}" fill="white"/>']
    svg += panel(margin, margin, width, height, 1.0, 1.0, "w1 = w2 = 1")
    svg += panel(2 * margin + width, margin, width, height, 1.0, 4.0,
                 "w1 = 1, w2 = 4 (outer layer heavier)")
    ly = margin + height + 42
    legend = [("#1f5fbf", "6,4", "f1 (inner layer)"), ("#c0392b", "6,4", "f2 (outer layer)"),
              ("#1f5fbf", "", "fhat1"), ("#c0392b", "", "fhat2")]
    x = margin
    for colour, dash, label in legend:
        extra = f' stroke-dasharray="{dash}"' if dash else ""
        svg.append(f'<line x1="{x}" y1="{ly}" x2="{x + 30}" y2="{ly}" stroke="{colour}" '
                   f'stroke-width="2"{extra}/>')
        svg.append(f'<text x="{x + 36}" y="{ly + 4}" font-family="sans-serif" '
                   f'font-size="12">{label}</text>')
        x += 150
    ly += 22
    svg.append(f'<rect x="{margin}" y="{ly - 7}" width="30" height="14" fill="#f3e3c3"/>')
    svg.append(f'<text x="{margin + 36}" y="{ly + 4}" font-family="sans-serif" font-size="12">'
               f'order fails (f1 &lt; f2 + s, s = {S}): the layers are pooled and meet at the '
               'weighted mean shifted by s; elsewhere nothing changes</text>')
    svg.append(f'<text x="{margin}" y="{ly + 24}" font-family="sans-serif" font-size="12">'
               'dots: zero crossings of fhat1, fhat2 (the layers\' new positions on the line); '
               'x along the line, scene units</text>')
    svg.append('</svg>')
    with open(target, "w", encoding="utf-8") as out:
        out.write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main()
