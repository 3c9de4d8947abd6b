"""read / write: bit-exact round trips, any integer dtype in, int64 out."""

from __future__ import annotations

import numpy as np
import pytest

import conemesh


@pytest.mark.parametrize("ext", ["obj", "off", "ply", "mesh"])
def test_round_trip_is_bit_exact(bumpy, tmp_path, ext):
    V, F = bumpy
    p = tmp_path / f"m.{ext}"
    conemesh.write(p, V, F)
    V2, F2 = conemesh.read(p)
    assert V2.dtype == np.float64 and V2.shape == V.shape
    assert F2.dtype == np.int64 and F2.shape == F.shape
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_any_integer_dtype_and_layout_gives_the_same_bytes(bumpy, tmp_path):
    V, F = bumpy
    conemesh.write(tmp_path / "ref.obj", V, F)
    ref = (tmp_path / "ref.obj").read_bytes()
    for i, (VV, FF) in enumerate(
        [
            (V, F.astype(np.int32)),
            (V, F.astype(np.uint16)),
            (np.asfortranarray(V), np.asfortranarray(F)),
            (V.tolist(), F.tolist()),
            (np.ascontiguousarray(np.hstack([V, V]))[:, :3], F[:, :]),
        ]
    ):
        conemesh.write(tmp_path / f"{i}.obj", VV, FF)
        assert (tmp_path / f"{i}.obj").read_bytes() == ref, i


def test_read_names_the_file_and_line(tmp_path):
    p = tmp_path / "bad.off"
    p.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    with pytest.raises(conemesh.FileError) as e:
        conemesh.read(p)
    assert "bad.off" in str(e.value)
    with pytest.raises(OSError):  # FileError is an OSError
        conemesh.read(tmp_path / "missing.off")


def test_write_refuses_bad_arrays_and_leaves_no_file(bumpy, tmp_path):
    V, F = bumpy
    bad = F.copy()
    bad[7, 2] = len(V)
    with pytest.raises(conemesh.InputError) as e:
        conemesh.write(tmp_path / "x.obj", V, bad)
    assert e.value.faces == [7] and e.value.index == len(V)
    assert not (tmp_path / "x.obj").exists()
