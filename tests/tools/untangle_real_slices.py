#!/usr/bin/env python3
"""`strata untangle` on real garment slices whose input already crosses.

Usage: untangle_real_slices.py STRATA FOLDER WORK MIN_CLEAN

For every scene of FOLDER (tests/data/crossing_slices) that `strata check` calls tangled:
`strata untangle IN -o OUT`, then `strata check OUT`. The untangler's exit code must agree with
the exact check of what it wrote (0 and a clean check, or 1 and the check finding what is
left, named on stderr) and nothing may crash; where untangle says it kept the sides inferred
per region of the input (it has rolled regions), the check takes the input as its reference.
At least MIN_CLEAN of them must come out clean: the number measured last (16 of 16 since the
untangling keeps an input's rolled regions; 15 since the finishing stage takes pokes out of
side-by-side open layers; 12 when the cases were added; docs/untangle.md), so that a drop
fails here.
"""
import pathlib
import subprocess
import sys


def run(args):
    return subprocess.run(args, capture_output=True, text=True, timeout=120)


def main():
    strata, folder, work, min_clean = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3]), int(sys.argv[4])
    work.mkdir(parents=True, exist_ok=True)
    clean, tangled, failures = 0, 0, []
    for scene in sorted(folder.glob("*.json")):
        if run([strata, "check", str(scene)]).returncode != 1:
            failures.append(f"{scene.name}: expected a tangled input (check exit 1)")
            continue
        tangled += 1
        out = work / scene.name
        out.unlink(missing_ok=True)
        u = run([strata, "untangle", str(scene), "-o", str(out)])
        if u.returncode not in (0, 1) or not out.exists():
            failures.append(f"{scene.name}: untangle exit {u.returncode}, output written: {out.exists()}\n{u.stderr}")
            continue
        # Where untangle kept the sides inferred per region of the input (a suit piece folded
        # over another), the check judges by the input's sides.
        inferred = "(the input has rolled regions)" in u.stdout
        c = run([strata, "check", str(out)] + (["--reference", str(scene)] if inferred else []))
        if u.returncode == 0:
            if c.returncode != 0:
                failures.append(f"{scene.name}: untangle said clean, check exit {c.returncode}\n{c.stdout}")
            else:
                clean += 1
        else:
            if c.returncode != 1:
                failures.append(f"{scene.name}: untangle said NOT clean, check exit {c.returncode}")
            if "NOT collision-free" not in u.stderr:
                failures.append(f"{scene.name}: untangle exit 1 without saying why:\n{u.stderr}")
    print(f"{clean} of {tangled} crossing slices untangled clean")
    if clean < min_clean:
        failures.append(f"only {clean} clean, expected at least {min_clean}")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
