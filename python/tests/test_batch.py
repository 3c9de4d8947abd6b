"""conemesh.batch on a local Dask cluster: the table, its determinism, rows for failures, and
the command line."""

from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

import conemesh
from conemesh.batch import COLUMNS, NONDETERMINISTIC

THREE = ["bumpy.off", "3holes.off", "spot.obj"]


@pytest.fixture(scope="module")
def first_run(meshes, tmp_path_factory):
    out = tmp_path_factory.mktemp("batch1")
    df = conemesh.batch([meshes / m for m in THREE], out, {"seed": 1}, workers=2)
    return out, df


def test_batch_writes_the_table_with_three_ok_rows(first_run, meshes):
    out, df = first_run
    assert list(df.columns) == list(COLUMNS)
    assert list(df["status"]) == ["ok"] * 3, df[["input", "status", "error"]]
    assert list(df["input"]) == sorted(str(meshes / m) for m in THREE)
    for _, row in df.iterrows():
        assert 0 < row["q_min"] <= row["q_avg"] <= row["q_max"] <= 1
        assert 0 < row["theta_min"] <= row["theta_avg"]
        assert 0 < row["hausdorff_rel"] < 0.05 and row["topology_kept"]
        assert row["cert_manifold"] >= row["patches"] > 0
        assert row["seconds"] > 0 and row["peak_rss_mib"] > 0
        # The row is the mesh that was written.
        V, F = conemesh.read(row["output"])
        assert len(F) == row["faces_out"] and len(V) == row["vertices_out"]
    table = pd.read_csv(out / "table.csv")
    assert list(table["status"]) == ["ok"] * 3
    assert list(table["faces_out"]) == list(df["faces_out"])


def test_batch_is_deterministic_but_for_time_and_memory(first_run, meshes, tmp_path):
    _, df1 = first_run
    # Another order of the inputs, the same table.
    df2 = conemesh.batch([meshes / m for m in reversed(THREE)], tmp_path, {"seed": 1}, workers=2)
    det = [c for c in COLUMNS if c not in NONDETERMINISTIC and c != "output"]
    pd.testing.assert_frame_equal(df1[det], df2[det])


def test_batch_rows_for_refusals_timeouts_and_bad_options(meshes, tmp_path):
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n")
    df = conemesh.batch([bad], tmp_path / "out", table="t.parquet")
    assert df.loc[0, "status"] == "refused" and "FileError" in df.loc[0, "error"]
    assert (tmp_path / "out" / "t.parquet").is_file()
    df = conemesh.batch([meshes / "bumpy.off"], tmp_path / "out2", timeout=0.05, table=None)
    assert df.loc[0, "status"] == "timeout"
    with pytest.raises(TypeError, match="seeed"):
        conemesh.batch([meshes / "bumpy.off"], tmp_path / "out3", {"seeed": 2})
    with pytest.raises(conemesh.OptionError):
        conemesh.batch([meshes / "bumpy.off"], tmp_path / "out3", {"sweeps": -1})


def test_the_command_line(meshes, tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "conemesh.batch", str(meshes / "bumpy.off"), "--out", str(tmp_path), "--", "--seed", "2"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    table = pd.read_csv(tmp_path / "table.csv")
    assert list(table["status"]) == ["ok"]
    # The same mesh as conemesh.remesh with that seed.
    V, F = conemesh.read(meshes / "bumpy.off")
    _, G, _ = conemesh.remesh(V, F, seed=2, quiet=True)
    assert table.loc[0, "faces_out"] == len(G)
