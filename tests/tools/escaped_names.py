#!/usr/bin/env python3
"""Layer names and units holding control bytes or broken UTF-8 reach the terminal escaped.

Usage: escaped_names.py STRATA WORK

Scenes whose layer names hold ESC ("\\u001b[1m", which would turn a terminal bold), the C1
control U+009B (a one-character CSI) and, in an SVG, a lone byte 0x9b (broken UTF-8): the text
reports of `strata check`, `strata simplify` and `strata grid --info` must show them as \\xNN
(shown_text()) and hold no raw ESC, C1 or broken byte; `strata check --json` keeps the names as
they are (JSON escapes them itself; a stray byte, which JSON cannot hold, becomes U+FFFD); the
SVGs `strata simplify` writes are well-formed XML and read back to the same names; a scene
whose name is not UTF-8 is refused as JSON output, naming it.
"""
import json
import math
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ET

BOLD = "\u001b[1mbold"  # shown as \x1b[1mbold
CSI = "c1\u009b2"  # U+009B is C2 9B in UTF-8: shown as c1\xc2\x9b2
SLASH = "back\\slash"  # shown as back\\slash
BOLD_SHOWN = "\\x1b[1mbold"
CSI_SHOWN = "c1\\xc2\\x9b2"
SLASH_SHOWN = "back\\\\slash"
FAILURES = []


def run(args):
    return subprocess.run(args, capture_output=True, timeout=300)


def expect(condition, what, out=b""):
    if not condition:
        shown = out.decode("utf-8", "replace")
        shown = shown if len(shown) <= 3000 else shown[:3000] + " ..."
        FAILURES.append(what + ("\n--- output:\n" + shown if out else ""))


def expect_escaped(out, shown, what):
    """`out` (bytes) shows every name of `shown` and holds no raw control or broken byte."""
    for name in shown:
        expect(name.encode() in out, f"{what}: '{name}' not in the output", out)
    expect(b"\x1b" not in out, f"{what}: a raw ESC byte in the output", out)
    expect(b"\x9b" not in out, f"{what}: a raw 0x9b byte in the output", out)
    try:
        out.decode("utf-8")
    except UnicodeDecodeError as e:
        expect(False, f"{what}: the output is not UTF-8 ({e})", out)


def circle(radius, n):
    return [[radius * math.cos(2 * math.pi * k / n), radius * math.sin(2 * math.pi * k / n)]
            for k in range(n)]


def main():
    strata, work = sys.argv[1], pathlib.Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)

    # Two open layers that cross (the crossing lines and near pairs name both), units with ESC.
    crossing = work / "escaped_crossing.json"
    crossing.write_text(json.dumps({"strata": 1, "units": "\u001b[31mcm", "layers": [
        {"name": BOLD, "closed": False, "thickness": 0.1,
         "points": [[0, 0], [1, 0], [2, 0], [3, 0], [4, 0]]},
        {"name": CSI, "closed": False, "thickness": 0.1,
         "points": [[0, 0.5], [1, -0.5], [2, 0.5], [3, -0.5], [4, 0.5]]}]}))
    r = run([strata, "check", str(crossing)])
    expect(r.returncode == 1, f"check of a crossing scene: exit {r.returncode}, expected 1", r.stderr)
    expect_escaped(r.stdout, [BOLD_SHOWN, CSI_SHOWN, "units \\x1b[31mcm"], "check")
    expect(f"'{BOLD_SHOWN}' segment".encode() in r.stdout and
           f"'{CSI_SHOWN}' segment".encode() in r.stdout,
           "check: the crossing lines do not name both layers escaped", r.stdout)
    # JSON: the names as they are, escaped by the JSON writer.
    r = run([strata, "check", "--json", str(crossing)])
    expect(r.returncode == 1, f"check --json: exit {r.returncode}, expected 1", r.stderr)
    expect(b"\x1b" not in r.stdout, "check --json: a raw ESC byte in the output", r.stdout)
    try:
        report = json.loads(r.stdout)
        expect([l["name"] for l in report["layers"]] == [BOLD, CSI],
               "check --json: the names are not the file's", r.stdout)
        expect(report["crossings"][0]["layer_a"] in (BOLD, CSI),
               "check --json: a crossing does not name a layer as it is", r.stdout)
    except (ValueError, KeyError, IndexError) as e:
        expect(False, f"check --json: not the expected JSON ({e})", r.stdout)

    # Two nested circles that do not cross: simplify's table and grid --info name them.
    nested = work / "escaped_nested.json"
    nested.write_text(json.dumps({"strata": 1, "layers": [
        {"name": BOLD, "closed": True, "points": circle(1.0, 64)},
        {"name": SLASH, "closed": True, "points": circle(1.3, 64)},
        {"name": CSI, "closed": True, "points": circle(1.6, 64)}]}))
    svg, panels = work / "escaped_nested.svg", work / "escaped_panels.svg"
    svg.unlink(missing_ok=True)
    panels.unlink(missing_ok=True)
    r = run([strata, "simplify", str(nested), "-o", str(svg), "--svg", str(panels)])
    expect(r.returncode == 0, f"simplify: exit {r.returncode}, expected 0", r.stderr)
    expect_escaped(r.stdout, [BOLD_SHOWN, CSI_SHOWN, SLASH_SHOWN], "simplify")
    r = run([strata, "grid", "--info", str(nested)])
    expect(r.returncode == 0, f"grid --info: exit {r.returncode}, expected 0", r.stderr)
    expect_escaped(r.stdout, [BOLD_SHOWN + ": ", CSI_SHOWN + ": ", SLASH_SHOWN + ": "], "grid --info")

    # The SVGs written for those names (the scene, the panels of --svg): well-formed XML (ESC
    # has no place in XML 1.0, not even as &#27;); strata reads the scene back to the same names.
    for path in (svg, panels):
        if not path.exists():
            expect(False, f"simplify wrote no {path.name}")
            continue
        text = path.read_bytes()
        expect(b"\x1b" not in text and b"&#27;" not in text, f"{path.name}: ESC written into it", text)
        try:
            ET.fromstring(text)
        except ET.ParseError as e:
            expect(False, f"{path.name}: not well-formed XML ({e})")
    if svg.exists():
        r = run([strata, "check", "--json", str(svg)])
        try:
            names = [l["name"] for l in json.loads(r.stdout)["layers"]]
            expect(names == [BOLD, SLASH, CSI], f"svg: read back as {names!r}", r.stdout)
        except (ValueError, KeyError) as e:
            expect(False, f"svg: check --json of it failed ({e})", r.stdout + r.stderr)

    # Broken UTF-8: a lone byte 0x9b in an SVG id (the SVG reader keeps the bytes of an id).
    broken = work / "escaped_broken.svg"
    broken.write_bytes(b'<svg xmlns="http://www.w3.org/2000/svg">\n'
                       b'<polygon id="a\x9bz" points="0,0 1,0 1,1 0,1"/>\n'
                       b'<polygon id="b" points="-1,-1 2,-1 2,2 -1,2"/>\n</svg>\n')
    r = run([strata, "check", str(broken)])
    expect(r.returncode == 0, f"check of broken UTF-8: exit {r.returncode}, expected 0", r.stderr)
    expect_escaped(r.stdout, ["a\\x9bz"], "check (broken UTF-8)")
    # JSON holds UTF-8 only: the report has U+FFFD for the stray byte (nlohmann would throw, an
    # "internal" error); a scene written as JSON is refused naming the name, nothing written.
    r = run([strata, "check", "--json", str(broken)])
    expect(r.returncode == 0, f"check --json of broken UTF-8: exit {r.returncode}, expected 0",
           r.stdout + r.stderr)
    try:
        names = [l["name"] for l in json.loads(r.stdout)["layers"]]
        expect(names == ["a\ufffdz", "b"], f"check --json of broken UTF-8: names {names!r}")
    except (ValueError, KeyError) as e:
        expect(False, f"check --json of broken UTF-8: not the expected JSON ({e})", r.stdout)
    never = work / "escaped_never.json"
    never.unlink(missing_ok=True)
    r = run([strata, "untangle", str(broken), "-o", str(never)])
    expect(r.returncode == 2 and b"'a\\x9bz' is not UTF-8" in r.stderr and not never.exists(),
           f"untangle to JSON of broken UTF-8: exit {r.returncode}, expected 2 naming 'a\\x9bz'",
           r.stderr)
    expect(b"\x9b" not in r.stderr, "untangle: a raw 0x9b byte in the message", r.stderr)

    for failure in FAILURES:
        print("FAIL:", failure)
    print(f"{len(FAILURES)} failures")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
