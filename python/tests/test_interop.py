"""The README's interop snippets (trimesh, pyvista), run where those packages are installed; they
are not dependencies of conemesh, so the tests skip without them."""

from __future__ import annotations

import numpy as np
import pytest

import conemesh


def test_trimesh_round_trip(meshes, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    V, F = conemesh.read(meshes / "bumpy.off")
    conemesh.write(tmp_path / "bumpy.obj", V, F)
    m = trimesh.load(tmp_path / "bumpy.obj", process=False)
    U, G, _ = conemesh.remesh(m.vertices, m.faces, quiet=True)
    out = trimesh.Trimesh(U, G, process=False)
    assert out.is_watertight and len(out.faces) == len(G)
    U0, G0, _ = conemesh.remesh(V, F, quiet=True)
    assert np.array_equal(U, U0) and np.array_equal(G, G0), "trimesh kept the arrays as read"


def test_pyvista_round_trip(meshes, tmp_path):
    pv = pytest.importorskip("pyvista")
    V, F = conemesh.read(meshes / "bumpy.off")
    conemesh.write(tmp_path / "bumpy.ply", V, F)
    mesh = pv.read(tmp_path / "bumpy.ply").triangulate()
    U, G, _ = conemesh.remesh(mesh.points, mesh.faces.reshape(-1, 4)[:, 1:], quiet=True)
    out = pv.PolyData(U, np.hstack([np.full((len(G), 1), 3), G]).ravel())
    assert out.n_cells == len(G) and out.is_manifold
