"""render: an (H, W, 3) uint8 picture, its properties and its errors."""

from __future__ import annotations

import numpy as np
import pytest

import conemesh
from conftest import grid_disk

MAGENTA = np.array([255, 0, 255])


def _magenta(img):
    """Pixels drawn magenta (shaded): red equals blue, no green."""
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return (r > 80) & (abs(r - b) <= 2) & (g == 0)


def test_render_returns_the_picture_of_the_shape_asked_for(bumpy):
    V, F = bumpy
    img = conemesh.render(V, F, width=600, height=260)
    assert img.shape == (260, 600, 3) and img.dtype == np.uint8
    drawn = (img != 255).any(axis=2).mean()
    assert 0.15 < drawn < 0.8
    # Each third holds a view.
    for k in range(3):
        assert (img[:200, 200 * k : 200 * (k + 1)] != 255).any()
    # The same arrays, the same pixels.
    assert np.array_equal(img, conemesh.render(V, F, width=600, height=260))


def test_a_sliver_is_magenta_and_the_metric_and_reference_are_used():
    h = np.sqrt(3) / 2
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, h, 0], [2, 0, 0], [4, 0, 0], [2.2, 0.3, 0]], float)
    F = np.array([[0, 1, 2], [3, 4, 5]])
    eye = np.tile(np.eye(3), (6, 1, 1))
    img = conemesh.render(V, F, metric=eye, width=900, height=400, wireframe="off")
    # The front view is the left third; the sliver is its right part.
    front = img[:, :300]
    assert _magenta(front[:, 150:]).sum() > 50
    assert _magenta(front[:, :100]).sum() == 0
    # Stretched along x by 9 in the metric, the equilateral triangle is flagged too.
    stretched = np.tile(np.diag([81.0, 1.0, 1.0]), (6, 1, 1))
    img2 = conemesh.render(V, F, metric=stretched, width=900, height=400, wireframe="off")
    assert _magenta(img2[:, :100]).sum() > 50
    # Distance to itself: the pale end of the map everywhere.
    d = conemesh.render(V, F, color="distance", reference=(V, F), width=900, height=400)
    assert not _magenta(d).any()


def test_patches_and_errors():
    V, F = grid_disk(8)
    ids = np.arange(len(F)) // 20
    img = conemesh.render(V, F, color="patch", patches=ids, width=600, height=260)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 10
    with pytest.raises(conemesh.OptionError, match="patch"):
        conemesh.render(V, F, color="patch", patches=ids[1:])
    with pytest.raises(conemesh.OptionError, match="distance"):
        conemesh.render(V, F, color="distance")
    with pytest.raises(conemesh.OptionError, match="color"):
        conemesh.render(V, F, color="quality")
    with pytest.raises(conemesh.OptionError, match="picture size"):
        conemesh.render(V, F, width=10)
    bad = np.tile(np.eye(3), (len(V), 1, 1))
    bad[3] = np.diag([1.0, -1.0, 1.0])
    with pytest.raises(conemesh.MetricError) as e:
        conemesh.render(V, F, metric=bad)
    assert e.value.vertices == [3]
    with pytest.raises(conemesh.InputError):
        conemesh.render(V, np.array([[0, 1, 99]]))
