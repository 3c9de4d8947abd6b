"""Shared fixtures: the shared meshes (``../shared/meshes`` beside the repository, as the Rust
tests find them) and the release CLI (``CONEMESH_BIN`` or ``target/release/conemesh``)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("CONEMESH_MESHES", REPO.parent / "shared" / "meshes"))


@pytest.fixture(scope="session")
def meshes() -> Path:
    assert MESHES.is_dir(), f"expected the shared meshes in {MESHES} (or set CONEMESH_MESHES)"
    return MESHES


@pytest.fixture(scope="session")
def cli() -> Path:
    p = Path(os.environ.get("CONEMESH_BIN", REPO / "target" / "release" / "conemesh"))
    assert p.is_file(), f"expected the release CLI at {p}: run `cargo build --release` (or set CONEMESH_BIN)"
    return p


@pytest.fixture(scope="session")
def bumpy(meshes):
    import conemesh

    return conemesh.read(meshes / "bumpy.off")


def grid_disk(n: int = 8):
    """A flat n×n grid of the unit square, triangulated counter-clockwise (a disk)."""
    xs, ys = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="xy")
    V = np.stack([xs.ravel(), ys.ravel(), 0.1 * np.sin(3 * xs.ravel()) * ys.ravel()], axis=1)
    F = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            F += [[a, b, c], [a, c, d]]
    return V, np.array(F, dtype=np.int32)
