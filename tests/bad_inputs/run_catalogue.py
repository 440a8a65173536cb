#!/usr/bin/env python3
"""Bad-input catalogue: runs every cases/*.expect against the strata CLI.

A case file holds lines `args: ...` (the command line; {out} is the output path), `exit: N`
(default 2) and `expect: TEXT` (substrings of the one `strata: error:` line; with exit 0 or 1,
of the whole stderr). For exit 2 each case asserts: exactly one error line holding every
expected substring, no output file created, an output that already exists left byte-equal,
and an end within the time limit. Usage: run_catalogue.py STRATA [CASES_DIR] [NAME_FILTER]
"""
import os
import shutil
import subprocess
import sys
import tempfile

TIMEOUT = 60  # seconds per run


def parse(path):
    case = {"args": None, "exit": 2, "expect": []}
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if not line or line.startswith("#"):
                continue
            key, _, value = line.partition(": ")
            if key == "args":
                case["args"] = value.split()
            elif key == "exit":
                case["exit"] = int(value)
            elif key == "expect":
                case["expect"].append(value)
            else:
                raise ValueError(f"{path}: unknown key {key!r}")
    if case["args"] is None:
        raise ValueError(f"{path}: no args")
    return case


def run(strata, cases_dir, args, out):
    argv = [strata] + [a.replace("{out}", out) for a in args]
    return subprocess.run(argv, cwd=cases_dir, capture_output=True, timeout=TIMEOUT)


def check(strata, cases_dir, name, case, work):
    problems = []
    out = os.path.join(work, name + ".out.json")
    try:
        p = run(strata, cases_dir, case["args"], out)
    except subprocess.TimeoutExpired:
        return [f"no end within {TIMEOUT} s"]
    stderr = p.stderr.decode("utf-8", "replace")
    if p.returncode != case["exit"]:
        problems.append(f"exit {p.returncode}, expected {case['exit']}")
    errors = [l for l in stderr.splitlines() if l.startswith("strata: error:")]
    if case["exit"] == 2:
        if len(errors) != 1:
            problems.append(f"{len(errors)} 'strata: error:' lines, expected 1")
        text = errors[0] if errors else ""
    else:
        if errors:
            problems.append("an error line on a run expected to succeed")
        text = stderr + p.stdout.decode("utf-8", "replace")
    for e in case["expect"]:
        if e not in text:
            problems.append(f"missing {e!r}")
    if case["exit"] == 2:
        if os.path.exists(out):
            problems.append("an output file was created")
        old = b"previous output\n"
        with open(out, "wb") as f:
            f.write(old)
        try:
            run(strata, cases_dir, case["args"], out)
        except subprocess.TimeoutExpired:
            problems.append(f"second run: no end within {TIMEOUT} s")
        with open(out, "rb") as f:
            if f.read() != old:
                problems.append("an existing output was changed")
    if problems:
        problems.append("stderr: " + stderr.strip()[:400])
    return problems


def main():
    strata = os.path.abspath(sys.argv[1])
    here = os.path.dirname(os.path.abspath(__file__))
    cases_dir = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "cases")
    only = sys.argv[3] if len(sys.argv) > 3 else ""
    names = sorted(f[:-7] for f in os.listdir(cases_dir) if f.endswith(".expect"))
    names = [n for n in names if only in n]
    work = tempfile.mkdtemp(prefix="strata-bad-inputs-")
    failed = 0
    try:
        for name in names:
            problems = check(strata, cases_dir, name, parse(os.path.join(cases_dir, name + ".expect")), work)
            print(("FAIL " if problems else "ok   ") + name)
            for pr in problems:
                print("     " + pr)
            failed += bool(problems)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{len(names) - failed} of {len(names)} cases passed")
    return 1 if failed or not names else 0


if __name__ == "__main__":
    sys.exit(main())
