"""evaluate, check, patches, param: shapes and properties."""

from __future__ import annotations

import numpy as np
import pytest

import conemesh
from conftest import grid_disk


def test_evaluate_gives_the_table_1_row(bumpy):
    V, F = bumpy
    U, G, r = conemesh.remesh(V, F, quiet=True)
    e = conemesh.evaluate(V, F, U, G, samples=20_000)
    q = e["output_quality"]
    assert set(q) >= {"q_min", "q_max", "q_avg", "theta_min", "theta_max", "theta_avg"}
    assert q["faces"] == len(G) and e["output"]["vertices"] == len(U)
    assert 0 < e["distance"]["hausdorff_rel"] < 0.05
    assert e["self_intersections_checked"] and e["self_intersections"] == []
    assert e["topology_kept"] is True
    assert e["table_row"].split()[0] == "output"
    # The remesh report's yardstick used the same measure of quality.
    assert q["q_min"] == r["eval"]["output_quality"]["q_min"]
    same = conemesh.evaluate(V, F, V, F, samples=1000)
    assert same["distance"]["hausdorff_rel"] < 1e-12  # rounding of closest points only
    with pytest.raises(conemesh.OptionError):
        conemesh.evaluate(V, F, U, G, ltar=-1.0)


def test_check_reports_validity_and_the_offenders(bumpy):
    V, F = bumpy
    ok = conemesh.check(V, F)
    assert ok["valid"] and ok["components"] == 1 and ok["euler"] == 2
    Vn = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=float)
    Fn = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    bad = conemesh.check(Vn, Fn)
    assert not bad["valid"] and bad["non_manifold_edges"] == 1
    assert bad["non_manifold_edge_ids"] == [[0, 1]]
    assert conemesh.check(V, F, self_intersections=False)["self_intersections"] is None


def test_patches_cover_every_face(bumpy):
    V, F = bumpy
    ids, info = conemesh.patches(V, F, seed=3, stats=True)
    assert ids.shape == (len(F),) and ids.dtype == np.int64
    assert ids.min() == 0 and ids.max() == len(info["stats"]) - 1
    assert np.array_equal(ids, conemesh.patches(V, F, seed=3))  # seeded
    k = conemesh.patches(V, F, strategy="kring", strategy_opt={"rings": 2})
    assert k.shape == (len(F),)
    with pytest.raises(conemesh.OptionError):
        conemesh.patches(V, F, strategy="kring", strategy_opt={"no_such_option": 1})


@pytest.mark.parametrize("method", ["sd", "tutte"])
def test_param_is_bijective(method):
    V, F = grid_disk(8)
    uv = conemesh.param(V, F, method=method)
    assert uv.shape == (len(V), 2) and uv.dtype == np.float64
    a, b, c = uv[F[:, 0]], uv[F[:, 1]], uv[F[:, 2]]
    signed = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (signed > 0).all()


def test_param_refuses_a_closed_surface(bumpy):
    V, F = bumpy
    with pytest.raises(conemesh.InputError, match="disk"):
        conemesh.param(V, F)
