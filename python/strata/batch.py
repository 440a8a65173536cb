"""strata.batch: ``strata simplify FOLDER -o OUT`` on a Dask distributed cluster.

One Dask task per slice; each task reads its slice, untangles it first when it already crosses
(``input_crossings``), simplifies it and writes ``OUT/<stem>.json`` atomically (a temporary file
beside it, then a rename), exactly as the CLI's batch does (the same C++ code,
tools/simplify_batch.cpp). A slice that fails (bad file, a worker that dies ...) is one
``FAILED`` line of the table; the others go on. The summary table is the CLI's, line for line
(the time column and the peak memory are measured where the work ran).

The workers must import this package (``pip install .`` on every machine) and see the input and
output folders at the same paths (a shared filesystem), as the CLI does on one machine::

    from dask.distributed import Client
    import strata.batch
    result = strata.batch.simplify_folder("slices/", "out/", client=Client("tcp://scheduler:8786"))
    print(result.table, end="")

or from a shell: ``python -m strata.batch slices/ -o out/ --scheduler tcp://scheduler:8786``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _strata

__all__ = ["BatchResult", "simplify_folder", "main"]


def _run_slice(input_path: Tuple[str, str], output_path: Tuple[str, str], options: Dict[str, Any]) -> Dict[str, Any]:
    """The task of one slice (runs on a worker; never raises for a slice that fails).

    The paths are absolute (a worker's working folder is not the client's); the messages, the
    table row and the report entry name them as the client gave them, as the CLI does."""
    given_in, abs_in = input_path
    given_out, abs_out = output_path
    r = _strata._batch_slice(abs_in, abs_out, options)

    def relabel(text):
        return text.replace(abs_in, given_in).replace(abs_out, given_out)

    r["input"], r["output"] = given_in, given_out
    r["row"] = relabel(r["row"])
    if r["error"] is not None:
        r["error"] = relabel(r["error"])
    entry = r["entry"]
    for key in ("input", "output", "error"):
        if key in entry:
            entry[key] = relabel(entry[key])
    return r


def _failed_row(input_path: str, message: str) -> str:
    # The CLI's "%-40s FAILED: %s\n" for a task that did not return (the worker died ...).
    return "%-40s FAILED: %s\n" % (os.path.basename(input_path), message)


@dataclass
class BatchResult:
    """What :func:`simplify_folder` did."""

    table: str  #: The CLI's summary table: header, one line per slice, the closing line.
    rows: List[Dict[str, Any]] = field(default_factory=list)  #: Per slice, in input order.
    entries: List[Dict[str, Any]] = field(default_factory=list)  #: The CLI's --report entries.
    slices: int = 0
    failed: int = 0  #: Slices that failed (nothing written for them).
    skipped: int = 0  #: Inputs that cross, with input_crossings="skip".
    untangled: int = 0  #: Inputs that crossed and were untangled first.
    tangled: int = 0  #: Results that are not collision-free.
    seconds: float = 0.0  #: Wall time of the whole batch, seconds.

    @property
    def exit_code(self) -> int:
        """The CLI's exit code: 0 when every slice was simplified collision-free, else 1."""
        return 0 if self.failed == 0 and self.tangled == 0 and self.skipped == 0 else 1


def _write_atomic(path: str, text: str) -> None:
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".strata-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def simplify_folder(
    inputs: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    output: Union[str, "os.PathLike[str]"],
    *,
    client: Any = None,
    scheduler: Optional[str] = None,
    report: Optional[Union[str, "os.PathLike[str]"]] = None,
    **options: Any,
) -> BatchResult:
    """Simplifies every slice of ``inputs`` (folders stand for their .json and .svg files,
    sorted by name, as ``strata simplify`` takes them) into the folder ``output``, one Dask
    task per slice.

    ``client``: a ``dask.distributed.Client``; else ``scheduler``, a scheduler address
    (``tcp://host:8786``) to connect to; else a ``LocalCluster`` of this machine, closed at the
    end. ``report``: also write the CLI's ``--report`` JSON (a list, one entry per slice).
    ``options``: the keyword arguments of :func:`strata.simplify` (same names and defaults),
    plus ``compare_naive`` (bool), ``input_crossings="skip"`` and ``time_limit`` (seconds a
    slice may take, 0 = none, as ``--time-limit``: past it the slice fails and nothing is
    written for it). They are validated here, before any task runs (:class:`strata.InvalidInput`).
    """
    from dask.distributed import Client, as_completed

    start = time.perf_counter()
    _strata._validate_options(options)
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    files = _strata._expand_inputs([os.fspath(p) for p in inputs])
    output = os.fspath(output)
    if not os.path.isdir(output):
        os.makedirs(output, exist_ok=True)

    own_client = None
    if client is None:
        own_client = Client(scheduler) if scheduler else Client()
        client = own_client
    try:
        futures = {}
        for i, path in enumerate(files):
            out = _strata._batch_output(output, path)
            f = client.submit(
                _run_slice,
                (path, os.path.abspath(path)),
                (out, os.path.abspath(out)),
                options,
                pure=False,
                key=f"strata-slice-{i}-{os.path.basename(path)}",
            )
            futures[f] = i
        rows: List[Optional[Dict[str, Any]]] = [None] * len(files)
        for f in as_completed(list(futures)):
            i = futures[f]
            try:
                rows[i] = f.result()
            except Exception as e:  # the task itself failed: the worker died, strata missing ...
                message = f"{type(e).__name__}: {e}"
                rows[i] = {
                    "input": files[i],
                    "output": _strata._batch_output(output, files[i]),
                    "row": _failed_row(files[i], message),
                    "error": message,
                    "skipped": False,
                    "untangled": False,
                    "collision_free": False,
                    "entry": {"input": files[i], "error": message},
                    "peak_memory_mib": 0.0,
                }
    finally:
        if own_client is not None:
            cluster = getattr(own_client, "cluster", None)
            own_client.close()
            if cluster is not None and not scheduler:
                cluster.close()

    result = BatchResult(table="", slices=len(files))
    lines = [_strata._batch_header()]
    peak = 0.0
    for r in rows:
        assert r is not None
        lines.append(r["row"])
        result.rows.append(r)
        result.entries.append(r["entry"])
        peak = max(peak, r["peak_memory_mib"])
        if r["error"] is not None:
            result.failed += 1
        elif r["skipped"]:
            result.skipped += 1
        else:
            result.untangled += int(r["untangled"])
            result.tangled += int(not r["collision_free"])
    lines.append(
        _strata._batch_footer(
            result.slices, result.failed, result.skipped, result.untangled, result.tangled, peak
        )
    )
    result.table = "".join(lines)
    if report is not None:
        _write_atomic(os.fspath(report), json.dumps(result.entries, indent=2) + "\n")
    result.seconds = time.perf_counter() - start
    return result


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m strata.batch IN... -o OUT [--scheduler ADDR | --workers N] [--remove F] ...``:
    prints the CLI's table; exit code as ``strata simplify``'s (0 ok, 1 a slice failed, was
    skipped or is not collision-free, 2 bad options)."""
    p = argparse.ArgumentParser(prog="python -m strata.batch", description=main.__doc__)
    p.add_argument("inputs", nargs="+", help="slice files (.json, .svg) or folders")
    p.add_argument("-o", "--output", required=True, help="output folder")
    p.add_argument("--scheduler", help="Dask scheduler address (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (default 2)")
    p.add_argument("--threads", action="store_true", help="LocalCluster workers as threads")
    p.add_argument("--report", help="report as JSON")
    p.add_argument("--remove", type=float, default=0.9)
    p.add_argument("--keep", type=int, default=0)
    p.add_argument("--decimator", default="visvalingam")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--thickness", type=float, default=0.0)
    p.add_argument("--input-crossings", default="untangle")
    p.add_argument("--compare-naive", action="store_true")
    p.add_argument("--time-limit", type=float, default=0.0, help="seconds a slice may take")
    a = p.parse_args(argv)
    from dask.distributed import Client, LocalCluster

    options = dict(
        remove=a.remove,
        keep=a.keep,
        decimator=a.decimator,
        seed=a.seed,
        thickness=a.thickness,
        input_crossings=a.input_crossings,
        compare_naive=a.compare_naive,
        time_limit=a.time_limit,
    )
    try:
        if a.scheduler:
            client = Client(a.scheduler)
            cluster = None
        else:
            cluster = LocalCluster(
                n_workers=a.workers, threads_per_worker=1, processes=not a.threads
            )
            client = Client(cluster)
        try:
            r = simplify_folder(a.inputs, a.output, client=client, report=a.report, **options)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    except _strata.InvalidInput as e:
        print(f"strata: error: {e}", file=sys.stderr)
        return 2
    sys.stdout.write(r.table)
    return r.exit_code


if __name__ == "__main__":
    sys.exit(main())
