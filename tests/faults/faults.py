#!/usr/bin/env python3
"""Fault tests of the strata CLI (issue 16, item 4).

  faults.py STRATA kill   SIGKILL during the write: the output is the old file or a complete
                          new one (never partial), over many kills timed around the write.
  faults.py STRATA batch  a batch goes on past a slice that fails, names it, and writes the
                          others.
  faults.py STRATA memory an input too large for the memory the process may use (RLIMIT_AS)
                          ends with one "out of memory" error, exit 1, nothing written, an
                          existing output untouched, in bounded time (no hang, no abort).

Exit 0 when the property held; prints what it saw (kills, how many landed in the write).
"""
import json
import math
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time


def big_scene(path, layers=4, points=60000):
    """Concentric circles, `points` vertices each: an output of a few MB takes a while to write."""
    out = []
    for k in range(layers):
        r = 1.0 + 0.05 * k
        pts = [[r * math.cos(2 * math.pi * i / points), r * math.sin(2 * math.pi * i / points)]
               for i in range(points)]
        out.append({"name": "c%d" % k, "closed": True, "thickness": 0.001, "points": pts})
    with open(path, "w") as f:
        json.dump({"strata": 1, "layers": out}, f)


def complete_scene(path, layers):
    """True when `path` holds a whole scene JSON with every layer."""
    try:
        with open(path) as f:
            scene = json.load(f)
    except (OSError, ValueError):
        return False
    return len(scene.get("layers", [])) == layers


def kill_test(strata):
    work = tempfile.mkdtemp(prefix="strata-faults-")
    src = os.path.join(work, "big.json")
    out = os.path.join(work, "out.json")
    big_scene(src, layers=2, points=50000)
    old = b'{"strata": 1, "layers": [{"name": "old", "points": [[0, 0], [1, 0]]}]}\n'
    # --remove 0: no decimation, so that the run is mostly reading, checking and writing.
    cmd = [strata, "simplify", src, "-o", out, "--remove", "0", "--threads", "1"]

    def temps():
        return [n for n in os.listdir(work) if n.startswith(".out.json.tmp")]

    def reset():
        with open(out, "wb") as f:
            f.write(old)
        for name in temps():
            os.remove(os.path.join(work, name))

    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    total = time.monotonic() - t0
    if not complete_scene(out, 2):
        print("kill: an uninterrupted run did not write a complete scene")
        return 1
    # Three kills in four are aimed at the write: the parent watches for the temporary file
    # beside the output and kills as soon as it appears, or up to 0.6 ms later. The others fall
    # at times spread over the run.
    trials, as_old, as_new, in_write, bad = 16, 0, 0, 0, 0
    for t in range(trials):
        reset()
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if t % 4 != 3:
            deadline = time.monotonic() + 10 * total + 30
            while not temps() and p.poll() is None and time.monotonic() < deadline:
                time.sleep(0.0002)
            time.sleep(0.0003 * (t % 4))
        else:
            time.sleep(total * t / trials)
        p.send_signal(signal.SIGKILL)
        p.wait()
        if temps():
            in_write += 1  # killed between creating the temporary file and renaming it
        with open(out, "rb") as f:
            content = f.read()
        if content == old:
            as_old += 1
        elif complete_scene(out, 2):
            as_new += 1
        else:
            bad += 1
            print("kill %d: out.json is neither the old file nor a complete scene (%d bytes)"
                  % (t, len(content)))
    print("kill: run %.2f s; %d SIGKILLs: %d left the old output, %d the complete new one, "
          "%d a partial one; %d landed inside the write (the temporary file was left behind: "
          "a stale .out.json.tmp* beside the output, never the output itself)"
          % (total, trials, as_old, as_new, bad, in_write))
    if in_write == 0:
        print("kill: no kill landed inside the write; the test proved nothing")
        return 1
    return 0 if bad == 0 else 1


def batch_test(strata):
    work = tempfile.mkdtemp(prefix="strata-faults-")
    def scene(name, pts, closed=False):
        return {"name": name, "closed": closed, "points": pts}
    good = {"strata": 1, "layers": [scene("a", [[0, 0], [1, 0.1], [2, 0], [3, 0.1], [4, 0]]),
                                    scene("b", [[0, 1], [1, 1.1], [2, 1], [3, 1.1], [4, 1]])]}
    files = {
        "s1_good.json": json.dumps(good),
        "s2_syntax.json": '{"layers": [',
        "s3_good.json": json.dumps(good),
        "s4_bowtie.json": json.dumps({"layers": [scene("x", [[0, 0], [1, 1], [1, 0], [0, 1]],
                                                       True)]}),
        "s5_good.json": json.dumps(good),
    }
    for name, text in files.items():
        with open(os.path.join(work, name), "w") as f:
            f.write(text)
    outdir = os.path.join(work, "out")
    inputs = [os.path.join(work, n) for n in sorted(files)]
    r = subprocess.run([strata, "simplify", *inputs, "-o", outdir, "--remove", "0.5"],
                       capture_output=True, text=True, timeout=300)
    text = r.stdout + r.stderr
    failures = []
    if r.returncode == 0:
        failures.append("exit 0 although two slices failed")
    for name in ("s1_good", "s3_good", "s5_good"):
        if not complete_scene(os.path.join(outdir, name + ".json"), 2):
            failures.append("%s.json not written" % name)
    for name in ("s2_syntax", "s4_bowtie"):
        if os.path.exists(os.path.join(outdir, name + ".json")):
            failures.append("%s.json written for a failing slice" % name)
        lines = [l for l in text.splitlines() if name in l and "FAILED" in l]
        if not lines:
            failures.append("no FAILED line names %s" % name)
    if "2 failed" not in text:
        failures.append("the summary does not count 2 failed slices")
    print(text.rstrip())
    for f in failures:
        print("batch: " + f)
    print("batch: exit %d, %s" % (r.returncode, "ok" if not failures else "FAILED"))
    return 0 if not failures else 1

def run_limited(cmd, limit, timeout=120):
    """Runs cmd with its address space limited to `limit` bytes."""
    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          preexec_fn=cap, timeout=timeout)


def memory_test(strata):
    work = tempfile.mkdtemp(prefix="strata-faults-")
    small = os.path.join(work, "small.json")
    big = os.path.join(work, "big.json")
    out = os.path.join(work, "out.json")
    big_scene(small, layers=2, points=200)
    # The smallest address space (to 16 MiB) in which strata checks and simplifies a small
    # scene: what it needs to start (libraries, threads) and a little work.
    def works(limit):
        return all(run_limited([strata, verb, small, "-o", out] if verb == "simplify" else
                               [strata, verb, small], limit).returncode == 0
                   for verb in ("check", "simplify"))
    low, high = 16 << 20, 4096 << 20
    if not works(high):
        print("memory: strata does not run in 4 GiB of address space here; skipped")
        return 77
    while high - low > (16 << 20):
        mid = (low + high) // 2
        if works(mid):
            high = mid
        else:
            low = mid
    limit = high + (64 << 20)
    # A scene whose text alone is about 90 MB: it cannot be read in 64 MiB more.
    big_scene(big, layers=8, points=250000)
    failures = []
    old = b'{"strata": 1, "layers": [{"name": "old", "points": [[0, 0], [1, 0]]}]}\n'
    for verb in ("check", "simplify"):
        with open(out, "wb") as f:
            f.write(old)
        cmd = [strata, verb, big] + (["-o", out] if verb == "simplify" else [])
        t = time.monotonic()
        try:
            r = run_limited(cmd, limit)
        except subprocess.TimeoutExpired:
            failures.append("%s: no end within 120 s" % verb)
            continue
        seconds = time.monotonic() - t
        errors = [l for l in r.stderr.splitlines() if l.startswith("strata: error:")]
        print("memory: %s under %d MiB: exit %d in %.2f s: %s" %
              (verb, limit >> 20, r.returncode, seconds, r.stderr.strip()[:200]))
        if r.returncode != 1:
            failures.append("%s: exit %d (expected 1)" % (verb, r.returncode))
        if len(errors) != 1 or "out of memory" not in errors[0]:
            failures.append("%s: not one 'out of memory' error line" % verb)
        with open(out, "rb") as f:
            if f.read() != old:
                failures.append("%s: the existing output was changed" % verb)
    leftovers = [n for n in os.listdir(work) if n not in ("small.json", "big.json", "out.json")]
    if leftovers:
        failures.append("files left behind: %s" % leftovers)
    for f in failures:
        print("memory: " + f)
    print("memory: %s" % ("ok" if not failures else "FAILED"))
    return 0 if not failures else 1


if __name__ == "__main__":
    tests = {"kill": kill_test, "batch": batch_test, "memory": memory_test}
    if len(sys.argv) != 3 or sys.argv[2] not in tests:
        print(__doc__)
        sys.exit(2)
    sys.exit(tests[sys.argv[2]](sys.argv[1]))
