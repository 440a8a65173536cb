"""Overhead of strata.batch (Dask) against `strata simplify FOLDER -o OUT` (TBB), per slice.

    python bench/dask_batch.py build/tools/strata tests/data/slices [--copies 10] [--repeat 3]

Both run on the same slices (the folder's files, each copied `copies` times under new names
so that there is enough work); the CLI with all cores, Dask on a LocalCluster of 2 workers of
one thread (processes, then threads), started before the clock. Prints the wall times, the
overhead per slice ((dask - cli) / slices) and checks that both wrote the same files.
"""

import argparse
import filecmp
import os
import shutil
import subprocess
import sys
import tempfile
import time

from dask.distributed import Client, LocalCluster

import strata.batch


def main():
    p = argparse.ArgumentParser()
    p.add_argument("cli")
    p.add_argument("folder")
    p.add_argument("--copies", type=int, default=10)
    p.add_argument("--repeat", type=int, default=3)
    a = p.parse_args()
    work = tempfile.mkdtemp(prefix="strata-dask-bench-")
    src = os.path.join(work, "in")
    os.makedirs(src)
    files = sorted(f for f in os.listdir(a.folder) if f.endswith((".json", ".svg")))
    for k in range(a.copies):
        for f in files:
            shutil.copy(os.path.join(a.folder, f), os.path.join(src, f"c{k:03d}_{f}"))
    n = len(files) * a.copies
    print(f"{n} slices ({len(files)} files x {a.copies} copies), best of {a.repeat}")

    def cli_run():
        out = os.path.join(work, "cli")
        shutil.rmtree(out, ignore_errors=True)
        t = time.perf_counter()
        run = subprocess.run([a.cli, "simplify", src, "-o", out], capture_output=True)
        if run.returncode not in (0, 1):
            sys.exit(run.stderr.decode())
        cli_code[0] = run.returncode
        return time.perf_counter() - t

    cli_code = [0]
    cli = min(cli_run() for _ in range(a.repeat))
    print(f"CLI (TBB, all cores): {cli:.3f} s, {1000 * cli / n:.2f} ms per slice")
    for processes in (True, False):
        t = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=processes,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.submit(lambda: 0).result()  # workers up
            startup = time.perf_counter() - t
            best = None
            for _ in range(a.repeat):
                out = os.path.join(work, "dask")
                shutil.rmtree(out, ignore_errors=True)
                t = time.perf_counter()
                r = strata.batch.simplify_folder(src, out, client=client)
                dt = time.perf_counter() - t
                assert r.exit_code == cli_code[0], r.table
                best = dt if best is None else min(best, dt)
            same = sorted(os.listdir(os.path.join(work, "cli"))) == sorted(os.listdir(out)) and all(filecmp.cmp(os.path.join(work, "cli", f), os.path.join(out, f), shallow=False)
                       for f in os.listdir(os.path.join(work, "cli")))
            kind = "processes" if processes else "threads"
            print(f"Dask, 2 workers ({kind}): {best:.3f} s, {1000 * best / n:.2f} ms per slice; "
                  f"overhead {1000 * (best - cli) / n:+.2f} ms per slice; cluster start {startup:.2f} s; "
                  f"outputs identical: {same}")
    shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
