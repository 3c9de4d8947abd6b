"""Comparisons of configurations on Dask: the grid of ``conemesh compare`` as a DataFrame.

``conemesh.compare(configs, inputs, seeds, out_dir)`` (this module is callable) runs every
(configuration, input, seed) as its own process on :mod:`conemesh.batch`'s Dask engine (a
local cluster by default, a ``Client`` of a real cluster unchanged) and returns one row per
run with the measures of ``conemesh compare`` under the same keys, so that the tables agree.
:func:`summary` gives the per-input mean ± sd over the seeds and :func:`paired` each
configuration against the first (mean difference, wins/ties/losses, exact sign test), as in
``compare.json``. The bootstrap interval is the CLI's alone (its seeded ChaCha stream).
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import types
import sys
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from . import _conemesh
from . import batch as _batch

#: The measures of ``conemesh compare`` (``src/compare/measures.rs``): key, which way is
#: better ("higher" or "lower"), and whether the output's bytes fix it.
MEASURES = (
    ("q_min", "higher", True),
    ("q_max", "higher", True),
    ("q_avg", "higher", True),
    ("theta_min", "higher", True),
    ("theta_max", "lower", True),
    ("theta_avg", "higher", True),
    ("hausdorff_pct", "lower", True),
    ("flips", "lower", True),
    ("cert_retries", "lower", True),
    ("faces_out", "lower", True),
    ("seconds", "lower", False),
    ("peak_mib", "lower", False),
)

#: The columns of the table, in order.
COLUMNS = ("config", "mesh", "seed", "status", "error", "output", "output_sha256") + tuple(
    m[0] for m in MEASURES
)

#: The arguments compare sets for every run (as ``conemesh compare`` refuses them): the
#: library's list.
OWN_ARGS = tuple(_conemesh.compare_own_args())


def _configs(configs) -> list[tuple[str, list[str]]]:
    items = list(configs.items()) if isinstance(configs, Mapping) else list(configs)
    if not items:
        raise ValueError("compare: no configuration")
    out: list[tuple[str, list[str]]] = []
    for name, args in items:
        args = args.split() if isinstance(args, str) else [str(a) for a in args]
        if any(a.split("=")[0] in OWN_ARGS for a in args):
            raise ValueError(
                f"compare: configuration {name!r} sets an argument compare sets: {args}"
            )
        if name in (n for n, _ in out):
            raise ValueError(f"compare: two configurations are named {name!r}")
        out.append((str(name), args))
    return out


def _seeds(seeds) -> list[int]:
    if isinstance(seeds, int):
        return [seeds]
    if isinstance(seeds, str):
        out: list[int] = []
        for part in seeds.split(","):
            a, _, b = part.partition("-")
            lo, hi = int(a), int(b or a)
            if lo > hi:
                raise ValueError(f"compare: the seed range {part!r} is empty")
            out.extend(range(lo, hi + 1))
        return sorted(set(out))
    return sorted(set(int(s) for s in seeds))


def _run_cell(job: Mapping[str, Any]) -> dict[str, Any]:
    """One cell: :func:`conemesh.batch.run_one`, then the measures by compare's keys."""
    row = _batch.run_one(job)
    out = {c: None for c in COLUMNS}
    out.update(
        config=job["config"],
        mesh=job["mesh"],
        seed=job["seed"],
        status=row["status"],
        error=row["error"],
        output=row["output"],
    )
    if row["status"] != "ok":
        return out
    with open(job["result"]) as fh:
        rep = json.load(fh)
    q = rep["eval"]["output_quality"]
    out.update(
        output_sha256=rep.get("output_sha256"),
        hausdorff_pct=100.0 * rep["eval"]["distance"]["hausdorff_rel"],
        flips=float(len(rep["eval"]["flips"])),
        cert_retries=float(len(rep["run"]["fallbacks"]["failures"])),
        faces_out=float(rep["run"]["faces_out"]),
        seconds=rep["seconds"],
        peak_mib=rep["peak_rss_mib"],
    )
    for k in ("q_min", "q_max", "q_avg", "theta_min", "theta_max", "theta_avg"):
        out[k] = q[k]
    return out


def compare(
    configs: Mapping[str, str | Sequence[str]] | Iterable[tuple[str, str | Sequence[str]]],
    inputs,
    seeds: int | str | Iterable[int] = 1,
    out_dir: str | os.PathLike | None = None,
    client=None,
    *,
    timeout: float | None = 3600.0,
    workers: int | None = None,
):
    """Run every (configuration, input, seed) in its own process on Dask.

    Parameters
    ----------
    configs : mapping or iterable of (name, args)
        Named ``conemesh remesh`` flags (a string split at white space, or a list), the first
        the baseline: ``{"cone": "", "kring": "--strategy kring --strategy-opt rings=4"}``.
    inputs : str, os.PathLike or iterable of them
        Mesh files, or a folder (as :func:`conemesh.batch`).
    seeds : int, str or iterable of int, default 1
        ``"1-3"``, ``"1,4"``, ``3`` or a list.
    out_dir : str or os.PathLike, optional
        Where the outputs go (``CONFIG--MESH--sSEED.obj``, as the CLI names them); default a
        temporary folder, removed afterwards.
    client : distributed.Client, optional
        Where to run. Default: a local ``dask.distributed`` cluster for this call.
    timeout : float or None, default 3600
        Seconds a run may take; then its row says ``timeout``.
    workers : int, optional
        Tasks at once on the local cluster (default: the number of cores).

    Returns
    -------
    pandas.DataFrame
        One row per run, by input, configuration, seed (the CLI's order), with the columns
        :data:`COLUMNS`: ``status`` (``ok``, ``refused``, ``crashed``, ``timeout``), the
        output's SHA-256 and the measures under ``conemesh compare``'s keys.
    """
    import pandas as pd

    cfgs = _configs(configs)
    for name, args in cfgs:
        try:
            _conemesh.check_remesh_args(list(args))
        except Exception as e:  # the option error, named by configuration
            raise type(e)(f"configuration {name!r}: {e}") from e
    seed_list = _seeds(seeds)
    paths = [os.path.abspath(p) for p in _batch._inputs(inputs)]
    if not paths:
        raise ValueError(f"compare: no mesh in {inputs!r}")
    tmp = None
    if out_dir is None:
        tmp = tempfile.TemporaryDirectory(prefix="conemesh-compare-")
        out = Path(tmp.name)
    else:
        out = Path(out_dir).absolute()
        out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=".conemesh-compare-", dir=out))
    jobs = []
    for p in paths:
        mesh = Path(p).stem
        clean = "".join(c if c.isalnum() or c in "-_" else "_" for c in mesh)
        for name, args in cfgs:
            for s in seed_list:
                base = f"{name}--{clean}--s{s}"
                jobs.append(
                    {
                        "config": name,
                        "mesh": mesh,
                        "seed": s,
                        "input": p,
                        "output": str(out / f"{base}.obj"),
                        "result": str(work / f"{base}.json"),
                        "args": list(args) + ["--seed", str(s)],
                        "timeout": timeout,
                    }
                )
    try:
        rows = _batch._run(jobs, client, workers, _run_cell)
    finally:
        for f in work.iterdir():
            f.unlink()
        work.rmdir()
        if tmp is not None:
            tmp.cleanup()
    return pd.DataFrame(rows, columns=list(COLUMNS))


def summary(df):
    """Per input and configuration (in the table's order): runs, ok runs, and each measure's
    mean and sample sd over the ok runs (columns ``KEY_mean``, ``KEY_sd``), as
    ``compare.json``'s ``summary``."""
    import pandas as pd

    rows = []
    for (mesh, config), g in df.groupby(["mesh", "config"], sort=False):
        ok = g[g["status"] == "ok"]
        row: dict[str, Any] = {"mesh": mesh, "config": config, "runs": len(g), "ok": len(ok)}
        for key, _, _ in MEASURES:
            xs = [float(x) for x in ok[key]]
            row[f"{key}_mean"] = sum(xs) / len(xs) if xs else math.nan
            row[f"{key}_sd"] = _sd(xs)
        rows.append(row)
    return pd.DataFrame(rows)


def _sd(xs: list[float]) -> float:
    if not xs:
        return math.nan
    if len(xs) == 1:
        return 0.0
    m = sum(xs) / len(xs)
    return math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1))


def sign_test_p(wins: int, losses: int) -> float:
    """Two-sided exact sign test of wins against losses (ties left out)."""
    n = wins + losses
    if n == 0:
        return 1.0
    k = min(wins, losses)
    return min(1.0, 2.0 * sum(math.comb(n, i) for i in range(k + 1)) / 2.0**n)


def paired(df):
    """Each configuration after the first against the first, per measure, over the (input,
    seed) pairs where both ran: ``n``, ``mean_diff``, ``ci_low``, ``ci_high`` (the 95 %
    bootstrap interval), ``wins``, ``ties``, ``losses``, ``p_sign`` and ``significant``, as
    ``compare.json``'s ``paired`` (computed by the same code, with the same streams)."""
    import json

    import pandas as pd

    configs = list(dict.fromkeys(df["config"]))
    ok = df[df["status"] == "ok"]
    base = ok[ok["config"] == configs[0]]
    rows = []
    for mi, (key, better, _) in enumerate(MEASURES):
        for ci, c in enumerate(configs[1:], start=1):
            other = ok[ok["config"] == c]
            both = other.merge(base, on=["mesh", "seed"], suffixes=("", "_base"), sort=False)
            pairs = [
                (float(b), float(a))
                for a, b in zip(both[key], both[f"{key}_base"])
                if not (math.isnan(float(a)) or math.isnan(float(b)))
            ]
            st = json.loads(_conemesh.paired_stats(pairs, better == "higher", ci, mi))
            lo, hi = st["ci"] if st["ci"] is not None else (math.nan, math.nan)
            rows.append(
                {
                    "measure": key,
                    "config": c,
                    "against": configs[0],
                    "n": st["n"],
                    "mean_diff": st["mean_diff"],
                    "ci_low": lo,
                    "ci_high": hi,
                    "wins": st["wins"],
                    "ties": st["ties"],
                    "losses": st["losses"],
                    "p_sign": st["p_sign"],
                    "significant": st["significant"],
                }
            )
    return pd.DataFrame(rows)


class _CallableModule(types.ModuleType):
    """``conemesh.compare`` is this module and the function at once."""

    def __call__(self, *args, **kwargs):
        return compare(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
