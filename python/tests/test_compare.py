"""conemesh.compare on a local Dask cluster gives the same table as ``conemesh compare`` for
the same grid: the same runs, output bytes, measures, per-input mean ± sd and paired
counts, bootstrap intervals and sign-test p-values; failures are rows; bad seeds are refused."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest

import conemesh
from conemesh.compare import MEASURES, paired, sign_test_p, summary

CONFIGS = {"cone": "", "kring": "--strategy kring --strategy-opt rings=4"}


def torus(nu: int, nv: int, r: float):
    u, v = np.meshgrid(
        np.arange(nu) * 2 * np.pi / nu, np.arange(nv) * 2 * np.pi / nv, indexing="ij"
    )
    V = np.stack(
        [(1 + r * np.cos(v)) * np.cos(u), (1 + r * np.cos(v)) * np.sin(u), r * np.sin(v)], axis=-1
    ).reshape(-1, 3)
    F = []
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            F += [[a, b, c], [a, c, d]]
    return V, np.array(F, dtype=np.int32)


@pytest.fixture(scope="module")
def both(cli, tmp_path_factory):
    meshes = tmp_path_factory.mktemp("meshes")
    conemesh.write(meshes / "thin.obj", *torus(24, 10, 0.35))
    conemesh.write(meshes / "fat.obj", *torus(20, 10, 0.5))
    out = tmp_path_factory.mktemp("cli") / "cmp"
    cmd = [str(cli), "compare", str(meshes), "--seeds", "1-2", "-j", "2", "-q", "-o", str(out)]
    for name, args in CONFIGS.items():
        cmd += ["-c", f"{name}={args}"]
    subprocess.run(cmd, check=True, capture_output=True)
    doc = json.loads((out / "compare.json").read_text())
    snap = json.loads((out / "snapshot.json").read_text())
    df = conemesh.compare(CONFIGS, meshes, "1-2", tmp_path_factory.mktemp("py"), workers=2)
    return doc, snap, df


def test_python_runs_the_same_grid_to_the_same_bytes_and_measures(both):
    doc, snap, df = both
    keys = [m[0] for m in MEASURES]
    assert sorted(keys) == sorted(doc["runs"][0]["result"]["measures"]), "the CLI's measures"
    assert [(r["config"], r["mesh"], r["seed"]) for r in doc["runs"]] == list(
        zip(df["config"], df["mesh"], df["seed"])
    )
    assert list(df["status"]) == ["ok"] * 8
    assert list(df["output_sha256"]) == [r["output_sha256"] for r in snap["runs"]]
    for (_, row), run in zip(df.iterrows(), doc["runs"]):
        for key, _, deterministic in MEASURES:
            if deterministic:
                want = run["result"]["measures"][key]
                assert row[key] == pytest.approx(want, rel=1e-12, abs=0), key


def test_python_summary_and_paired_are_the_cli_tables(both):
    doc, _, df = both
    s = summary(df)
    assert list(zip(s["mesh"], s["config"])) == [(r["mesh"], r["config"]) for r in doc["summary"]]
    for (_, row), cli_row in zip(s.iterrows(), doc["summary"]):
        assert (row["runs"], row["ok"]) == (cli_row["runs"], cli_row["ok"])
        for key, _, deterministic in MEASURES:
            if deterministic:
                m = cli_row["measures"][key]
                assert row[f"{key}_mean"] == pytest.approx(m["mean"], rel=1e-12, abs=1e-12)
                assert row[f"{key}_sd"] == pytest.approx(m["sd"], rel=1e-9, abs=1e-12)
    p = paired(df)
    for _, row in p.iterrows():
        key = row["measure"]
        if not dict((m[0], m[2]) for m in MEASURES)[key]:
            continue
        cli_row = next(
            r for r in doc["paired"] if r["measure"] == key and r["config"] == row["config"]
        )
        assert (row["n"], row["wins"], row["ties"], row["losses"]) == (
            cli_row["n"],
            cli_row["wins"],
            cli_row["ties"],
            cli_row["losses"],
        ), key
        assert row["p_sign"] == pytest.approx(cli_row["p_sign"], rel=1e-12)
        assert row["mean_diff"] == pytest.approx(cli_row["mean_diff"], rel=1e-9, abs=1e-12)
        # The same bootstrap stream over the same pairs in the same order: the same interval.
        assert cli_row["ci"] is not None, key
        assert (row["ci_low"], row["ci_high"]) == pytest.approx(
            tuple(cli_row["ci"]), rel=1e-9, abs=1e-12
        ), key
        assert row["significant"] == cli_row["significant"], key


def test_sign_test_is_exact():
    assert sign_test_p(5, 0) == 2 / 32
    assert math.isclose(sign_test_p(8, 2), 112 / 1024)
    assert sign_test_p(0, 0) == 1.0


def test_failures_are_rows_and_bad_seeds_are_refused(tmp_path):
    conemesh.write(tmp_path / "t.obj", *torus(24, 10, 0.35))
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n")
    df = conemesh.compare({"a": ""}, [tmp_path / "t.obj", bad], 1, workers=2)
    status = dict(zip(df["mesh"], df["status"]))
    assert status == {"broken": "refused", "t": "ok"}
    assert "FileError" in df.loc[df["mesh"] == "broken", "error"].iloc[0]
    df = conemesh.compare({"a": ""}, tmp_path / "t.obj", 1, timeout=0.02)
    assert list(df["status"]) == ["timeout"]
    with pytest.raises(ValueError, match="empty"):
        conemesh.compare({"a": ""}, tmp_path / "t.obj", "5-1")
    with pytest.raises(ValueError, match="--seed"):
        conemesh.compare({"a": "--seed 3"}, tmp_path / "t.obj")
