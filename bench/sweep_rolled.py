#!/usr/bin/env python3
"""Issue 19's targets for `strata simplify` on the rolled families, over a sweep.

    bench/sweep_rolled.py BUILD_DIR WORK_DIR [--families rolled,...] [--points 300,600,...]
                          [--gaps 2] [--removes 0.9,0.95] [--seeds 1,2,3] [--time-runs 3]
                          [--min-time 0.1] [--lock FILE]

For every family x points x gap, the un-decimated input of the family and of its unrolled
counterpart (FamilyParams::unrolled) are written by `BUILD_DIR/bench/strata_bench_untangle
--family F --points N --gap G --write` into WORK_DIR; then `strata simplify IN --remove R
--decimator D --schedule S [--seed K] -o OUT --report OUT.report.json` runs for every R, every
decimator (random with each seed) and both schedules, and each run is judged on:
  exit      simplify's exit code is 0
  check     `strata check OUT --reference IN` exits 0 (clean with the input's sides)
  crossings no crossing or self-crossing (check --json)
  nesting   no nesting violation against the input's sides (check --json)
  sep       every separation >= 0.9 x required (check's min_separation_ratio)
  hausdorff every layer's symmetric Hausdorff distance to the input <= 2 gaps (gap = twice
            the largest layer thickness, FamilyParams: thickness is half the gap)
  budget    every layer at its target (the report's targets_met)
  time      the whole call (wall, best of --time-runs) within 2x of the unrolled
            counterpart's with the same options, judged only where that takes >= --min-time s
The same targets are judged on the unrolled counterpart, for comparison (a target both miss
comes from the decimator or the budget, not from the roll). Prints one line per run and the
counts of each failing target. --lock FILE: every simplify and check runs holding an flock on
FILE (taken before the clock starts: waits for it are not timed).
"""
import argparse
import collections
import contextlib
import fcntl
import glob
import json
import os
import subprocess
import time

FAMILIES = "rolled,rolled_twice,rolled_both,shirt_roll,collar_wrap"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("work")
    ap.add_argument("--families", default=FAMILIES)
    ap.add_argument("--points", default="300,600,1200,2400")
    ap.add_argument("--gaps", default="2")
    ap.add_argument("--removes", default="0.9,0.95")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--time-runs", type=int, default=3)
    ap.add_argument("--min-time", type=float, default=0.1)
    ap.add_argument("--lock", default="")
    a = ap.parse_args()
    strata = os.path.join(a.build, "tools", "strata")
    bench = os.path.join(a.build, "bench", "strata_bench_untangle")
    lock = ["flock", a.lock] if a.lock else []

    @contextlib.contextmanager
    def locked():
        if not a.lock:
            yield
            return
        with open(a.lock, "a") as f:
            fcntl.flock(f, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(f, fcntl.LOCK_UN)

    def generate(family, points, gap, unrolled):
        d = os.path.join(a.work, f"{family}-{points}-g{gap}" + ("-unrolled" if unrolled else ""))
        os.makedirs(d, exist_ok=True)
        found = glob.glob(os.path.join(d, "*.input.json"))
        if not found:
            subprocess.run(lock + [bench, "--family", family, "--points", str(points), "--gap",
                                   str(gap), "--tangle", "naive90", "--slices", "none",
                                   "--write", d] + (["--unrolled"] if unrolled else []),
                           check=True, capture_output=True)
            found = glob.glob(os.path.join(d, "*.input.json"))
        return found[0]

    def run(inp, opts, runs):
        out = inp.replace(".input.json", "") + "-" + "-".join(opts).replace("--", "") + ".out"
        cmd = [strata, "simplify", inp] + opts + ["-o", out + ".json", "--report",
                                                  out + ".report.json"]
        walls, rc = [], None
        for _ in range(runs):
            with locked():
                start = time.perf_counter()
                rc = subprocess.run(cmd, capture_output=True).returncode
                walls.append(time.perf_counter() - start)
        r = {"cmd": " ".join(cmd), "rc": rc, "wall": min(walls)}
        fails = [] if rc == 0 else ["exit"]
        try:
            report = json.load(open(out + ".report.json"))
            if not report["targets_met"]:
                fails.append("budget")
        except (OSError, ValueError, KeyError):
            return r, fails + ["budget", "check"]
        with locked():
            c = subprocess.run([strata, "check", out + ".json", "--reference", inp, "--json"],
                               capture_output=True, text=True)
        if c.returncode != 0:
            fails.append("check")
        cj = json.loads(c.stdout)
        gap = 2.0 * max(layer["thickness"] for layer in cj["layers"])
        r["hausdorff_gaps"] = max(l["hausdorff"]["symmetric"] for l in cj["layers"]) / gap
        r["ratio"] = cj["min_separation_ratio"]
        if cj["crossing_count"] + cj["self_crossing_count"] > 0:
            fails.append("crossings")
        if cj["nesting_violation_count"] > 0:
            fails.append("nesting")
        if r["ratio"] < 0.9:
            fails.append("sep")
        if r["hausdorff_gaps"] > 2.0:
            fails.append("hausdorff")
        return r, fails

    counts, counts_unrolled, total = collections.Counter(), collections.Counter(), 0
    for family in a.families.split(","):
        for points in [int(p) for p in a.points.split(",")]:
            for gap in a.gaps.split(","):
                rolled = generate(family, points, gap, False)
                unrolled = generate(family, points, gap, True)
                for remove in a.removes.split(","):
                    for dec in ("random", "visvalingam", "max-error"):
                        for seed in (a.seeds.split(",") if dec == "random" else ["1"]):
                            for sched in ("deferred", "immediate"):
                                opts = ["--remove", remove, "--decimator", dec, "--seed", seed,
                                        "--schedule", sched]
                                r, fails = run(rolled, opts, a.time_runs)
                                u, ufails = run(unrolled, opts, a.time_runs)
                                if u["wall"] >= a.min_time and r["wall"] > 2.0 * u["wall"]:
                                    fails.append("time")
                                total += 1
                                counts.update(fails)
                                counts_unrolled.update(ufails)
                                print(f"{family:12s} {points:6d} gap {gap:4s} {remove:5s} "
                                      f"{dec:11s} s{seed} {sched:9s} "
                                      f"H {r.get('hausdorff_gaps', float('nan')):6.2f} "
                                      f"({u.get('hausdorff_gaps', float('nan')):6.2f}) gaps, "
                                      f"ratio {r.get('ratio', float('nan')):.3f}, "
                                      f"wall {r['wall']:.3f} ({u['wall']:.3f}) s: "
                                      + (",".join(fails) if fails else "ok")
                                      + (f"  [unrolled: {','.join(ufails)}]" if ufails else ""),
                                      flush=True)
    print(f"runs {total}; failing targets {dict(counts)}; "
          f"the unrolled counterparts' {dict(counts_unrolled)}")


if __name__ == "__main__":
    main()
