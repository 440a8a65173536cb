"""strata.batch on a Dask LocalCluster with 2 workers against `strata simplify FOLDER -o OUT`."""

import re
import shutil
import subprocess

import pytest

pytest.importorskip("dask.distributed")
from dask.distributed import Client, LocalCluster  # noqa: E402

import strata  # noqa: E402
import strata.batch  # noqa: E402
from conftest import DATA, SLICES  # noqa: E402


@pytest.fixture(scope="module")
def client():
    # Threads, not processes: the tasks release the GIL, and process workers take seconds to
    # start (the measurement in the README uses processes).
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster) as c:
        yield c


def comparable(table):
    """The table without what depends on where and when it ran: the time column and the
    peak memory."""
    out = []
    for line in table.splitlines():
        line = re.sub(r"peak memory \d+ MiB", "peak memory - MiB", line)
        if re.match(r"\S+\.(json|svg)\s+\d+\s+\d+", line):
            line = line[: line.rstrip().rfind(" ")]
        out.append(line)
    return out


def run_cli(cli, inputs, output, *args):
    run = subprocess.run([cli, "simplify", *map(str, inputs), "-o", str(output), *args],
                         capture_output=True, text=True)
    return run.returncode, run.stdout


def test_same_outputs_and_table_as_the_cli(cli, client, slices_copy, tmp_path):
    code, table = run_cli(cli, [slices_copy], tmp_path / "cli")
    result = strata.batch.simplify_folder(slices_copy, tmp_path / "dask", client=client,
                                          report=tmp_path / "report.json")
    assert code == result.exit_code == 0
    assert comparable(result.table) == comparable(table)
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "dask").iterdir())
    assert len(names) == len(list(SLICES.glob("*.json")))
    for name in names:
        assert (tmp_path / "dask" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert result.slices == len(names) and result.failed == 0
    for entry in result.entries:
        assert entry["collision_free"] and entry["crossings"] == 0
    assert (tmp_path / "report.json").exists()


def test_failures_are_reported_per_slice(cli, client, slices_copy, tmp_path):
    shutil.copy(DATA / "bad" / "syntax_error.json", slices_copy / "broken.json")
    shutil.copy(DATA / "crossing_pair.json", slices_copy / "crossing.json")
    options = dict(input_crossings="skip", remove=0.8, decimator="random")
    code, table = run_cli(cli, [slices_copy], tmp_path / "cli", "--input-crossings", "skip",
                          "--remove", "0.8", "--decimator", "random")
    result = strata.batch.simplify_folder(slices_copy, tmp_path / "dask", client=client, **options)
    assert code == result.exit_code == 1
    assert comparable(result.table) == comparable(table)
    assert result.failed == 1 and result.skipped == 1
    failed = [r for r in result.rows if r["error"]]
    assert failed[0]["input"].endswith("broken.json") and "broken.json" in failed[0]["error"]
    assert "FAILED: " in failed[0]["row"]
    # nothing written for them, everything else written
    written = sorted(p.name for p in (tmp_path / "dask").iterdir())
    assert "broken.json" not in written and "crossing.json" not in written
    assert written == sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert len(written) == result.slices - 2


def test_a_slice_past_the_time_limit_fails_alone(cli, client, slices_copy, tmp_path):
    # This folded stack takes 29 tries to untangle (about a minute): it stops at the limit.
    shutil.copy(DATA / "folded_stack_tangled_95.json", slices_copy / "folded.json")
    code, table = run_cli(cli, [slices_copy], tmp_path / "cli", "--time-limit", "2")
    result = strata.batch.simplify_folder(slices_copy, tmp_path / "dask", client=client,
                                          time_limit=2)
    assert code == result.exit_code == 1
    assert comparable(result.table) == comparable(table)
    failed = [r for r in result.rows if r["error"]]
    assert len(failed) == 1 and "not done within the time limit of 2 s" in failed[0]["error"]
    written = sorted(p.name for p in (tmp_path / "dask").iterdir())
    assert "folded.json" not in written and len(written) == result.slices - 1


def test_bad_options_are_refused_before_any_task(client, tmp_path):
    with pytest.raises(strata.InvalidInput, match="remove"):
        strata.batch.simplify_folder(SLICES, tmp_path / "out", client=client, remove=2.0)
    with pytest.raises(strata.InvalidInput, match=r"time_limit must be a number of seconds >= 0"):
        strata.batch.simplify_folder(SLICES, tmp_path / "out", client=client, time_limit=-1)
    with pytest.raises(TypeError, match="colour"):
        strata.batch.simplify_folder(SLICES, tmp_path / "out", client=client, colour="red")


def test_a_task_that_dies_is_one_failed_line(client, slices_copy, tmp_path, monkeypatch):
    real = strata.batch._run_slice

    def flaky(input_path, output_path, options):
        if input_path[0].endswith("y-0.15.json"):
            raise MemoryError("worker ran out of memory")
        return real(input_path, output_path, options)

    monkeypatch.setattr(strata.batch, "_run_slice", flaky)
    result = strata.batch.simplify_folder(slices_copy, tmp_path / "out", client=client)
    assert result.failed == 1 and result.slices == len(list(SLICES.glob("*.json")))
    line = [l for l in result.table.splitlines() if "FAILED" in l]
    assert len(line) == 1 and "y-0.15.json" in line[0] and "MemoryError" in line[0]
    assert result.exit_code == 1


def test_relative_paths_name_the_files_as_given(cli, client, slices_copy, tmp_path, monkeypatch):
    # the CLI's messages name the input as given; a worker's working folder may differ
    shutil.copy(DATA / "bad" / "syntax_error.json", slices_copy / "broken.json")
    monkeypatch.chdir(tmp_path)
    code, table = run_cli(cli, ["slices"], "cli")
    result = strata.batch.simplify_folder("slices", "dask", client=client)
    assert comparable(result.table) == comparable(table)
    [failed] = [r for r in result.rows if r["error"]]
    assert failed["error"].startswith("slices/broken.json:")
    assert failed["entry"]["input"] == "slices/broken.json"
    ok = [r for r in result.rows if not r["error"]]
    assert ok[0]["entry"]["output"].startswith("dask/")


def free_port():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_scheduler_address_with_worker_processes_elsewhere(cli, slices_copy, tmp_path, monkeypatch):
    """A scheduler and 2 worker processes started as on a cluster (their own working folder),
    reached by address through `python -m strata.batch --scheduler`; relative paths."""
    import sys
    import time

    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    log = open(tmp_path / "dask.log", "w")
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                               "127.0.0.1", "--port", str(port), "--dashboard-address", ":0"],
                              cwd=elsewhere, stdout=log, stderr=log)]
    try:
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address,
                                       "--nworkers", "2", "--nthreads", "1", "--dashboard-address",
                                       ":0"], cwd=elsewhere, stdout=log, stderr=log))
        with Client(address, timeout=60) as c:
            c.wait_for_workers(2, timeout=60)
            assert len(c.scheduler_info()["workers"]) == 2
        monkeypatch.chdir(tmp_path)
        code, table = run_cli(cli, ["slices"], "cli")
        start = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "strata.batch", "slices", "-o", "dask",
                              "--scheduler", address], capture_output=True, text=True, timeout=300)
        assert time.perf_counter() - start < 300
        assert run.returncode == code == 0, run.stderr
        assert comparable(run.stdout) == comparable(table)
        for f in (tmp_path / "cli").iterdir():
            assert (tmp_path / "dask" / f.name).read_bytes() == f.read_bytes(), f.name
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
        log.close()
