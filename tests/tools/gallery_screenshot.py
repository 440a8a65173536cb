#!/usr/bin/env python3
"""Screenshot test of bench/gallery.py: renders a two-slice gallery in headless Chromium and
checks the picture: two tiles side by side, the result's layer colours, the amber border of the
skipped slice and red rings on its crossings.

    gallery_screenshot.py STRATA GALLERY_PY WORK_DIR

Exit 77 (CTest: skipped) when no chromium is installed.
"""
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib


def read_png(path):
    """(width, height, rows of (r, g, b)) of an 8-bit RGB or RGBA, non-interlaced PNG."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and colour in (2, 6) and interlace == 0, "unsupported PNG"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def near(pixel, colour, tol=40):
    return sum(abs(p - c) for p, c in zip(pixel, colour)) <= tol


def main():
    strata, gallery, work = sys.argv[1:4]
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("no chromium: skipped")
        return 77
    os.makedirs(work, exist_ok=True)
    square = lambda name, c, r: {"name": name, "closed": True,
                                 "points": [[c - r, c - r], [c + r, c - r], [c + r, c + r], [c - r, c + r]]}
    clean_in = {"layers": [square("inner", 0, 1), square("outer", 0, 2)]}
    clean_out = clean_in
    # Two squares crossing each other: the skipped slice, with crossings to ring.
    tangled = {"layers": [square("a", 0, 1), square("b", 1, 1)]}
    files = {}
    for name, scene in (("s_y+1.00", clean_in), ("s_y+0.00", tangled)):
        files[name] = os.path.join(work, name + ".json")
        json.dump(scene, open(files[name], "w"))
    out = os.path.join(work, "s_y+1.00.out.json")
    json.dump(clean_out, open(out, "w"))
    report = [
        {"input": files["s_y+1.00"], "output": out, "crossings": 0, "refused": 0,
         "collision_free": True, "min_separation_ratio": 1.0,
         "layers": [{"before": 4, "after": 4}, {"before": 4, "after": 4}]},
        {"input": files["s_y+0.00"], "error": "the input already crosses"},
    ]
    report_path = os.path.join(work, "report.json")
    json.dump(report, open(report_path, "w"))
    page = os.path.join(work, "gallery.html")
    subprocess.run([sys.executable, gallery, "--title", "test", "--report", report_path, "--out",
                    page, "--strata", strata], check=True)
    text = open(page).read()
    assert text.count("<figure") == 2, "expected 2 tiles"
    assert 'class="crossing"' in text, "no crossing marked"
    png = os.path.join(work, "gallery.png")
    if os.path.exists(png):
        os.remove(png)
    subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    "--window-size=800,500", "--screenshot=" + png, "file://" + page],
                   check=True, capture_output=True, timeout=120)
    width, height, rows = read_png(png)
    assert (width, height) == (800, 500), (width, height)
    colours = {p for row in rows[::4] for p in row[::4]}
    assert len(colours) > 20, "blank picture: %d colours" % len(colours)
    count = lambda colour, tol=40: sum(1 for row in rows for p in row if near(p, colour, tol))
    blue, orange, red, amber = (0x1f, 0x77, 0xb4), (0xff, 0x7f, 0x0e), (0xe0, 0, 0), (0xf0, 0xa0, 0)
    counts = {"blue": count(blue), "orange": count(orange), "red": count(red),
              "amber": count(amber, 10)}
    print("pixels:", counts)
    assert counts["blue"] > 100 and counts["orange"] > 100, "layer colours missing"
    assert counts["red"] > 50, "crossing rings missing"
    assert counts["amber"] > 500, "skipped tile border missing"
    # Tiles: runs of non-background pixels wider than 200 px along a row through the tiles.
    background = (0xf4, 0xf4, 0xf4)
    y = next(y for y in range(height) if sum(1 for p in rows[y] if p == (255, 255, 255)) > 400)
    runs, length = 0, 0
    for p in rows[y + 40] + [background]:
        if p != background:
            length += 1
        else:
            runs += length > 200
            length = 0
    assert runs == 2, "expected 2 tiles in a row, found %d" % runs
    print("gallery screenshot ok: 2 tiles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
