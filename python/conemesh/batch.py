"""Corpus runs on Dask: many meshes × options × seeds, one process per mesh.

``conemesh.batch(inputs, out_dir, options)`` (this module is callable) or
``python -m conemesh.batch DIR --out OUT [--scheduler ADDRESS] [-- REMESH FLAGS...]``.

Each task runs ``python -m conemesh._one`` in a subprocess on a Dask worker, so a crash or a
timeout is a row of the table with its cause, never a lost run. With ``client=None`` a local
``dask.distributed`` cluster is started (threads that each wait on their subprocess); with a
``Client`` of a real cluster the same tasks run there unchanged, provided the workers have
conemesh installed and see the input and output paths (a shared file system).

The table has one row per input, sorted by input path. For the same inputs and options
(seed included) every column is the same from run to run except ``seconds`` and
``peak_rss_mib`` (:data:`NONDETERMINISTIC`), which measure the machine.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import types
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

#: The file extensions a folder is searched for.
MESH_EXTENSIONS = (".obj", ".off", ".ply", ".stl", ".mesh")

#: Columns that measure the machine rather than the result.
NONDETERMINISTIC = ("seconds", "peak_rss_mib")

#: The columns of the table, in order.
COLUMNS = (
    "input",
    "status",
    "error",
    "output",
    "output_sha256",
    "faces_in",
    "vertices_out",
    "faces_out",
    "patches",
    # Table 1
    "q_min",
    "q_max",
    "q_avg",
    "theta_min",
    "theta_max",
    "theta_avg",
    "pct_min_angle_lt_10",
    "pct_min_angle_lt_20",
    "pct_min_angle_lt_30",
    "pct_max_angle_gt_120",
    # distances (relative: to the input's bounding-box diagonal)
    "hausdorff",
    "hausdorff_rel",
    "rms_rel",
    "flips",
    "topology_kept",
    # certificates: how often each held
    "cert_disk",
    "cert_bijective",
    "cert_planar",
    "cert_manifold",
    "cert_oriented",
    "cert_same_topology",
    "cert_boundary_preserved",
    "cert_no_degenerate",
    "cert_no_flips",
    "cert_no_self_intersections",
    "warnings",
    "seconds",
    "peak_rss_mib",
)


def _inputs(inputs: str | os.PathLike | Iterable[str | os.PathLike]) -> list[str]:
    if isinstance(inputs, (str, os.PathLike)) and Path(inputs).is_dir():
        found = [p for p in Path(inputs).iterdir() if p.suffix.lower() in MESH_EXTENSIONS]
        return sorted(str(p) for p in found)
    if isinstance(inputs, (str, os.PathLike)):
        return [os.fspath(inputs)]
    return sorted(os.fspath(p) for p in inputs)


def _output_names(paths: Sequence[str]) -> list[str]:
    """One output name per input: its stem, with the extension added where two stems agree."""
    stems = [Path(p).stem for p in paths]
    return [
        f"{s}-remeshed.obj" if stems.count(s) == 1 else f"{s}-{Path(p).suffix[1:]}-remeshed.obj"
        for s, p in zip(stems, paths)
    ]


def run_one(job: Mapping[str, Any]) -> dict[str, Any]:
    """One task: remesh ``job["input"]`` in a subprocess and return its row.

    ``job`` holds ``input``, ``output``, ``result`` (paths), ``args`` (``conemesh remesh``
    flags) and ``timeout`` (seconds or ``None``).
    """
    row: dict[str, Any] = {c: None for c in COLUMNS}
    row.update(input=job["input"], output=job["output"], error="")
    cmd = [sys.executable, "-m", "conemesh._one", job["input"], job["output"], job["result"]]
    cmd += list(job["args"])
    t0 = time.monotonic()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=job["timeout"])
    except subprocess.TimeoutExpired:
        row.update(status="timeout", error=f"no result after {job['timeout']} s")
        row["seconds"] = time.monotonic() - t0
        return row
    row["seconds"] = time.monotonic() - t0
    if proc.returncode == 0:
        with open(job["result"]) as fh:
            _fill(row, json.load(fh))
        row["status"] = "ok"
    elif proc.returncode == 3:
        with open(job["result"]) as fh:
            row["error"] = json.load(fh)["error"]
        row["status"] = "refused"
    else:
        cause = (
            f"killed by signal {-proc.returncode}"
            if proc.returncode < 0
            else f"exit code {proc.returncode}"
        )
        tail = proc.stderr.strip().splitlines()[-1:] if proc.stderr else []
        row.update(status="crashed", error="; ".join([cause] + tail))
    return row


def _fill(row: dict[str, Any], rep: Mapping[str, Any]) -> None:
    run, ev = rep["run"], rep["eval"]
    q, d, c = ev["output_quality"], ev["distance"], run["certificate"]
    row.update(
        output_sha256=rep.get("output_sha256"),
        faces_in=run.get("faces_in"),
        vertices_out=ev["output"]["vertices"],
        faces_out=ev["output"]["faces"],
        patches=run.get("patches"),
        hausdorff=ev["hausdorff_file_units"],
        hausdorff_rel=d["hausdorff_rel"],
        rms_rel=d["rms_rel"],
        flips=len(ev["flips"]),
        topology_kept=ev["topology_kept"],
        warnings=len(run.get("warnings", [])),
        seconds=rep["seconds"],
        peak_rss_mib=rep["peak_rss_mib"],
    )
    for k in (
        "q_min",
        "q_max",
        "q_avg",
        "theta_min",
        "theta_max",
        "theta_avg",
        "pct_min_angle_lt_10",
        "pct_min_angle_lt_20",
        "pct_min_angle_lt_30",
        "pct_max_angle_gt_120",
    ):
        row[k] = q[k]
    for k in (
        "disk",
        "bijective",
        "planar",
        "manifold",
        "oriented",
        "same_topology",
        "boundary_preserved",
        "no_degenerate",
        "no_flips",
        "no_self_intersections",
    ):
        row[f"cert_{k}"] = c.get(k)


def batch(
    inputs,
    out_dir,
    options: Mapping[str, Any] | None = None,
    client=None,
    *,
    table: str | os.PathLike | None = "table.csv",
    timeout: float | None = 3600.0,
    workers: int | None = None,
    args: Sequence[str] = (),
):
    """Remesh a list of meshes (or a folder) on Dask, one process per mesh.

    Parameters
    ----------
    inputs : str, os.PathLike or iterable of them
        Mesh files, or a folder (its ``.obj``, ``.off``, ``.ply``, ``.stl``, ``.mesh`` files).
    out_dir : str or os.PathLike
        Created if missing: ``NAME-remeshed.obj`` per input and the table.
    options : mapping, optional
        Keywords of :func:`conemesh.remesh` (``{"seed": 2, "hausd": 0}``), the same for
        every mesh; checked before any task starts.
    client : distributed.Client, optional
        Where to run. Default: a local ``dask.distributed`` cluster for this call.
    table : str or os.PathLike or None, default "table.csv"
        The table's file in ``out_dir`` (or an absolute path); ``.parquet`` writes Parquet
        (needs pyarrow), anything else CSV; ``None`` writes none.
    timeout : float or None, default 3600
        Seconds a mesh may take; then its row says ``timeout``.
    workers : int, optional
        Tasks at once on the local cluster (default: the number of cores).
    args : sequence of str, optional
        Further ``conemesh remesh`` flags, after those of ``options``.

    Returns
    -------
    pandas.DataFrame
        One row per input, sorted by input, with the columns :data:`COLUMNS`: ``status``
        (``ok``, ``refused`` (conemesh said why: ``error``), ``crashed``, ``timeout``),
        sizes, the Table-1 row (q_min, q_max, q_avg, theta_min, theta_max, theta_avg, and
        the angle percentages), distances (``hausdorff`` in file units, ``hausdorff_rel``
        and ``rms_rel`` relative to the input's diagonal), flips, topology, how many times
        each certificate held, the output's SHA-256, ``seconds`` and ``peak_rss_mib`` (the
        task's process). Only ``seconds`` and ``peak_rss_mib`` differ between runs of the
        same inputs and seed.
    """
    import pandas as pd

    from . import _conemesh, _remesh_args

    flags = _remesh_args(options or {}, caller="batch") + list(args)
    _conemesh.check_remesh_args(flags)
    paths = [os.path.abspath(p) for p in _inputs(inputs)]
    out = Path(out_dir).absolute()
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=".conemesh-batch-", dir=out))
    jobs = [
        {
            "input": p,
            "output": str(out / name),
            "result": str(work / f"{i}.json"),
            "args": flags,
            "timeout": timeout,
        }
        for i, (p, name) in enumerate(zip(paths, _output_names(paths)))
    ]
    rows = _run(jobs, client, workers)
    for f in work.iterdir():
        f.unlink()
    work.rmdir()
    df = pd.DataFrame(sorted(rows, key=lambda r: r["input"]), columns=list(COLUMNS))
    if table is not None:
        t = out / table
        if t.suffix == ".parquet":
            df.to_parquet(t, index=False)
        else:
            df.to_csv(t, index=False)
    return df


def _run(
    jobs: list[dict[str, Any]], client, workers: int | None, task=None
) -> list[dict[str, Any]]:
    """``task`` (default :func:`run_one`) of every job on ``client`` or a local cluster."""
    task = task or run_one
    if not jobs:
        return []
    if client is not None:
        return client.gather(client.map(task, jobs, pure=False))
    from distributed import Client, LocalCluster

    n = workers or os.cpu_count() or 1
    # Threads are enough: each task only waits on its own subprocess, which does the work.
    with LocalCluster(
        n_workers=1,
        threads_per_worker=min(n, len(jobs)),
        processes=False,
        dashboard_address=None,
    ) as cluster, Client(cluster) as c:
        return c.gather(c.map(task, jobs, pure=False))


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m conemesh.batch``."""
    p = argparse.ArgumentParser(
        prog="python -m conemesh.batch",
        description="Remesh every mesh of a folder on Dask, one process per mesh, and write "
        "the table. Flags after `--` are passed to every `conemesh remesh`.",
    )
    p.add_argument("inputs", nargs="+", help="mesh files or a folder")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--scheduler", help="address of a Dask scheduler (default: a local cluster)")
    p.add_argument("--table", default="table.csv", help="table file in OUT (.csv or .parquet)")
    p.add_argument("--timeout", type=float, default=3600.0, help="seconds per mesh")
    p.add_argument("--workers", type=int, help="tasks at once on the local cluster")
    argv = list(sys.argv[1:] if argv is None else argv)
    extra: list[str] = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1 :]
    a = p.parse_args(argv)
    inputs = a.inputs[0] if len(a.inputs) == 1 else a.inputs
    client = None
    if a.scheduler:
        from distributed import Client

        client = Client(a.scheduler)
    df = batch(
        inputs,
        a.out,
        client=client,
        table=a.table,
        timeout=a.timeout,
        workers=a.workers,
        args=extra,
    )
    cols = ["input", "status", "faces_out", "q_min", "q_avg", "theta_min", "hausdorff_rel", "seconds"]
    print(df[cols].to_string(index=False))
    print(f"wrote {Path(a.out) / a.table}")
    return 0 if (df["status"] == "ok").all() else 1


class _CallableModule(types.ModuleType):
    """``conemesh.batch`` is this module and the function at once."""

    def __call__(self, *args, **kwargs):
        return batch(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

if __name__ == "__main__":
    sys.exit(main())
