"""Overhead of strata.batch (Dask) against `strata simplify FOLDER -o OUT` (TBB), per slice.

    python bench/dask_batch.py build/tools/strata tests/data/slices [--copies 10] [--repeat 3]

Both run on the same slices (the folder's files, each copied `copies` times under new names
so that there is enough work); the CLI with all cores, Dask on LocalClusters of 2 workers of
one thread (processes; threads), started before the clock; the runs are interleaved. Prints
the median wall times, the overhead per slice ((dask - cli) / slices) and checks that both
wrote the same files.
"""

import argparse
import filecmp
import os
import shutil
import statistics
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
    print(f"{n} slices ({len(files)} files x {a.copies} copies), {a.repeat} interleaved runs")

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

    def dask_run(client):
        out = os.path.join(work, "dask")
        shutil.rmtree(out, ignore_errors=True)
        t = time.perf_counter()
        r = strata.batch.simplify_folder(src, out, client=client)
        dt = time.perf_counter() - t
        assert r.exit_code == cli_code[0], r.table
        same = sorted(os.listdir(os.path.join(work, "cli"))) == sorted(os.listdir(out)) and all(
            filecmp.cmp(os.path.join(work, "cli", f), os.path.join(out, f), shallow=False)
            for f in os.listdir(os.path.join(work, "cli")))
        return dt, same

    # Both clusters stay up; the runs are interleaved (CLI, Dask processes, Dask threads) so
    # that the load of a shared machine falls on all three alike.
    clusters, starts = {}, {}
    for kind in ("processes", "threads"):
        t = time.perf_counter()
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=kind == "processes",
                               dashboard_address=None)
        client = Client(cluster)
        client.submit(lambda: 0).result()  # workers up
        starts[kind] = time.perf_counter() - t
        clusters[kind] = (cluster, client)
    times = {"cli": [], "processes": [], "threads": []}
    identical = True
    for _ in range(a.repeat):
        times["cli"].append(cli_run())
        for kind in ("processes", "threads"):
            dt, same = dask_run(clusters[kind][1])
            times[kind].append(dt)
            identical = identical and same
    for cluster, client in clusters.values():
        client.close()
        cluster.close()
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"CLI (TBB, all cores): median {med['cli']:.3f} s (best {min(times['cli']):.3f}), "
          f"{1000 * med['cli'] / n:.2f} ms per slice")
    for kind in ("processes", "threads"):
        print(f"Dask, 2 workers ({kind}): median {med[kind]:.3f} s (best {min(times[kind]):.3f}), "
              f"{1000 * med[kind] / n:.2f} ms per slice; overhead "
              f"{1000 * (med[kind] - med['cli']) / n:+.2f} ms per slice (medians); cluster start "
              f"{starts[kind]:.2f} s")
    print(f"outputs identical to the CLI's in every run: {identical}")
    shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
