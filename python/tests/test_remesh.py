"""remesh: the CLI's bytes for the same seed, its keywords and defaults, the report, errors,
the GIL and Ctrl-C."""

from __future__ import annotations

import ast
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import conemesh


@pytest.mark.parametrize("seed", [1, 2])
def test_same_seed_gives_the_cli_bytes(meshes, cli, tmp_path, seed):
    mesh = meshes / "bumpy.off"
    subprocess.run(
        [str(cli), "remesh", str(mesh), "-o", str(tmp_path / "cli.obj"), "--seed", str(seed), "-q"],
        check=True,
        capture_output=True,
    )
    V, F = conemesh.read(mesh)
    U, G, _ = conemesh.remesh(V, F, seed=seed, quiet=True)
    conemesh.write(tmp_path / "py.obj", U, G)
    assert (tmp_path / "py.obj").read_bytes() == (tmp_path / "cli.obj").read_bytes()


def test_another_seed_gives_another_mesh(bumpy):
    V, F = bumpy
    a = conemesh.remesh(V, F, seed=1, quiet=True)
    b = conemesh.remesh(V, F, seed=2, quiet=True)
    assert a[0].shape != b[0].shape or not np.array_equal(a[0], b[0])


def _help_options(cli) -> dict[str, str | None]:
    """`conemesh remesh --help`'s options (as keywords) and their `[default: X]`."""
    text = subprocess.run([str(cli), "remesh", "--help"], capture_output=True, text=True, check=True).stdout
    out: dict[str, str | None] = {}
    current = None
    for line in text.splitlines():
        m = re.match(r"^\s+(?:-\w, )?--([a-z0-9-]+)", line)
        if m:
            current = m.group(1).replace("-", "_")
            out[current] = None
        d = re.search(r"\[default: ([^\]]+)\]", line)
        if d and current:
            out[current] = d.group(1)
    return out


def test_keywords_are_the_cli_options_with_the_cli_defaults(cli):
    help_opts = _help_options(cli)
    for not_a_keyword in ("help", "output", "metric"):  # metric is the third parameter
        help_opts.pop(not_a_keyword)
    opts = {o["name"]: o for o in conemesh.remesh_options()}
    assert set(opts) == set(help_opts)
    for name, default in help_opts.items():
        assert opts[name]["default"] == default, name
    import inspect

    sig = inspect.signature(conemesh.remesh)
    assert list(sig.parameters)[:3] == ["V", "F", "metric"]
    assert set(list(sig.parameters)[3:]) == set(help_opts)
    assert sig.parameters["ltar_factor"].default == 1.5
    assert sig.parameters["seed"].default == 1
    assert sig.parameters["strategy"].default == "cone"


def test_the_stub_lists_every_keyword_with_its_default():
    stub = Path(conemesh.__file__).with_name("__init__.pyi")
    tree = ast.parse(stub.read_text())
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "remesh")
    stub_defaults = {
        a.arg: ast.literal_eval(d) for a, d in zip(fn.args.kwonlyargs, fn.args.kw_defaults)
    }
    import inspect

    sig = inspect.signature(conemesh.remesh)
    runtime = {n: p.default for n, p in list(sig.parameters.items())[3:]}
    assert stub_defaults == runtime


def test_report_is_the_cli_report(bumpy):
    V, F = bumpy
    U, G, r = conemesh.remesh(V, F, quiet=True)
    assert U.dtype == np.float64 and U.shape[1] == 3
    assert G.dtype == np.int64 and G.shape[1] == 3
    assert set(r) >= {"seconds", "peak_rss_mib", "run", "eval", "table_row"}
    q = r["eval"]["output_quality"]
    assert q["faces"] == len(G) and 0 < q["q_min"] <= q["q_avg"] <= q["q_max"] <= 1
    assert 0 < q["theta_min"] <= q["theta_avg"] <= 60 <= q["theta_max"]
    run = r["run"]
    assert run["faces_out"] == len(G) and run["patches"] > 0
    assert run["certificate"]["manifold"] >= run["patches"]
    assert r["eval"]["topology_kept"] is True
    assert conemesh.check(U, G)["valid"] is True


def test_options_reach_the_run(bumpy):
    V, F = bumpy
    _, G1, r1 = conemesh.remesh(V, F, quiet=True, ltar_factor=3.0, improvers="surface", hausd=0)
    assert r1["run"]["improvers"] == ["surface"]
    _, G2, _ = conemesh.remesh(V, F, quiet=True, ltar_factor=1.5, improvers="surface", hausd=0)
    assert len(G1) < len(G2)  # a longer target edge gives fewer faces
    _, _, r3 = conemesh.remesh(V, F, quiet=True, improvers=["surface"], strategy="kring", strategy_opt={"rings": 3})
    assert r3["run"]["improvers"] == ["surface"]


def test_bad_keywords_and_values():
    V, F = np.eye(3), np.array([[0, 1, 2]])
    with pytest.raises(TypeError, match="ltar_fator.*did you mean 'ltar_factor'"):
        conemesh.remesh(V, F, ltar_fator=2)
    with pytest.raises(conemesh.OptionError, match="ltar_factor"):
        conemesh.remesh(V, F, ltar_factor="big")
    with pytest.raises(conemesh.OptionError, match="cannot be used with"):
        conemesh.remesh(V, F, ltar_factor=2.0, ltar=0.1)
    with pytest.raises(conemesh.OptionError, match="True or False"):
        conemesh.remesh(V, F, keep_boundary=1)
    with pytest.raises(conemesh.OptionError, match="coarse"):
        conemesh.remesh(V, F, coarse="sometimes")


def test_bad_strategy_is_an_option_error(bumpy):
    V, F = bumpy
    with pytest.raises(conemesh.OptionError, match="unknown patch strategy `nope`"):
        conemesh.remesh(V, F, strategy="nope", quiet=True)
    assert issubclass(conemesh.OptionError, ValueError)


def test_bad_arrays_name_the_element(bumpy):
    V, F = bumpy
    bad = V.copy()
    bad[5, 2] = np.nan
    with pytest.raises(conemesh.InputError) as e:
        conemesh.remesh(bad, F, quiet=True)
    assert e.value.vertices == [5]
    bad = F.copy()
    bad[3, 1] = -2
    with pytest.raises(conemesh.InputError) as e:
        conemesh.remesh(V, bad, quiet=True)
    assert e.value.faces == [3] and e.value.index == -2
    bad = F.copy()
    bad[4, 0] = bad[4, 1]
    with pytest.raises(conemesh.InputError, match="repeats") as e:
        conemesh.remesh(V, bad, quiet=True)
    assert e.value.faces == [4]
    with pytest.raises(conemesh.InputError, match=r"shape \(n, 3\)"):
        conemesh.remesh(V[:, :2], F)
    with pytest.raises(conemesh.InputError, match="integer dtype"):
        conemesh.remesh(V, F.astype(float))
    with pytest.raises(conemesh.InputError, match="empty"):
        conemesh.remesh(V, np.zeros((0, 3), dtype=int))


def test_non_manifold_input_names_the_edge():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=float)
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.raises(conemesh.InputError) as e:
        conemesh.remesh(V, F, quiet=True)
    assert e.value.invariant == "non_manifold_edges"
    assert e.value.edges == [(0, 1)]


def test_bad_metrics_name_the_vertex(bumpy):
    V, F = bumpy
    n = len(V)
    with pytest.raises(conemesh.MetricError, match=r"shape"):
        conemesh.remesh(V, F, np.tile(np.eye(3), (n - 1, 1, 1)), quiet=True)
    M = np.tile(np.eye(3), (n, 1, 1))
    M[17] = -np.eye(3)
    with pytest.raises(conemesh.MetricError) as e:
        conemesh.remesh(V, F, M, quiet=True)
    assert e.value.vertices == [17]
    M = np.tile(np.eye(3), (n, 1, 1))
    M[9, 0, 1] = 0.5
    with pytest.raises(conemesh.MetricError, match="not symmetric") as e:
        conemesh.remesh(V, F, M, quiet=True)
    assert e.value.vertices == [9]
    with pytest.raises(conemesh.FileError):
        conemesh.remesh(V, F, "/nonexistent/metric.sol", quiet=True)


def test_a_user_metric_runs_and_is_written(bumpy, tmp_path):
    V, F = bumpy
    n = len(V)
    h = 0.1  # edge length in file units: M = I / h²
    M = np.tile(np.eye(3) / h**2, (n, 1, 1))
    U, G, r = conemesh.remesh(V, F, M, ltar=1.0, quiet=True, write_metric=tmp_path / "out.sol")
    assert r["eval"]["metric_source"] == "user"
    assert (tmp_path / "out.sol").stat().st_size > 0
    # The file holds one tensor per output vertex: it scores the output in the same metric.
    e = conemesh.evaluate(U, G, U, G, tmp_path / "out.sol", ltar=1.0, samples=1000)
    assert e["metric_source"] == "user"
    assert e["output_quality"]["faces"] == len(G)
    assert 0.5 < e["output_conformity"]["mean"] < 2.0


def _read_ascii_sol(path: Path) -> np.ndarray:
    """The tensors of an ASCII Medit ``.sol`` (``m11 m12 m22 m13 m23 m33`` per vertex)."""
    words = path.read_text().split()
    i = words.index("SolAtVertices")
    n = int(words[i + 1])
    assert words[i + 2 : i + 4] == ["1", "3"], "one symmetric tensor per vertex"
    x = np.array(words[i + 4 : i + 4 + 6 * n], dtype=float).reshape(n, 6)
    m11, m12, m22, m13, m23, m33 = x.T
    return np.stack(
        [np.stack([m11, m12, m13], -1), np.stack([m12, m22, m23], -1), np.stack([m13, m23, m33], -1)],
        -2,
    )


def test_write_input_metric_is_the_users_metric_over_ltar_squared(bumpy, tmp_path):
    V, F = bumpy
    h, ltar = 0.1, 2.0
    M = np.tile(np.eye(3) / h**2, (len(V), 1, 1))
    path = tmp_path / "in.sol"
    conemesh.remesh(V, F, M, ltar=ltar, hausd=0.0, quiet=True, write_input_metric=path)
    W = _read_ascii_sol(path)
    # One tensor per input vertex; an isotropic metric restricted to the tangent plane and
    # completed along the normal by its tangent eigenvalue is isotropic again, over L_tar².
    assert W.shape == (len(V), 3, 3)
    np.testing.assert_allclose(W, np.tile(np.eye(3) / (h * ltar) ** 2, (len(V), 1, 1)), rtol=1e-9, atol=1e-9)


def test_the_gil_is_released(meshes):
    V, F = conemesh.read(meshes / "3holes.off")
    done = threading.Event()
    result = {}

    def work():
        result["out"] = conemesh.remesh(V, F, quiet=True)
        done.set()

    t = threading.Thread(target=work)
    ticks = 0
    t.start()
    while not done.is_set():
        ticks += 1  # Python bytecode: runs only while the remesh does not hold the GIL
        time.sleep(0.005)
    t.join()
    assert result["out"][1].shape[1] == 3
    assert ticks >= 20, ticks


def test_ctrl_c_stops_a_run_cleanly(meshes):
    script = textwrap.dedent(
        f"""
        import signal, sys, time, conemesh
        # Python's own Ctrl-C handler, as in a terminal: a process started in the background
        # by a non-interactive shell (CI) inherits SIGINT ignored, and Python then installs none.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        V, F = conemesh.read({str(meshes / "decimated-knight.off")!r})
        print("started", flush=True)
        t = time.monotonic()
        try:
            conemesh.remesh(V, F, quiet=True)
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted", round(time.monotonic() - t, 2), flush=True)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    time.sleep(1.0)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 0
    assert out.startswith("interrupted"), out
    assert time.monotonic() - t0 < 4.0  # the full run takes ~8 s


def test_a_flipped_face_names_its_edges_and_an_unused_vertex_is_dropped(bumpy):
    V, F = bumpy
    flipped = F.copy()
    flipped[10] = flipped[10][::-1]
    with pytest.raises(conemesh.InputError) as e:
        conemesh.remesh(V, flipped, quiet=True)
    assert e.value.invariant == "inconsistent_orientation"
    assert sorted(e.value.edges) == sorted(
        tuple(sorted((int(a), int(b)))) for a, b in [F[10][[0, 1]], F[10][[1, 2]], F[10][[2, 0]]]
    )
    # A vertex no face uses changes nothing (the CLI drops it too).
    U, G, _ = conemesh.remesh(np.vstack([V, [[5.0, 5.0, 5.0]]]), F, quiet=True)
    U0, G0, _ = conemesh.remesh(V, F, quiet=True)
    assert np.array_equal(U, U0) and np.array_equal(G, G0)


def test_repair_orients_the_input_and_lists_every_flip(bumpy):
    V, F = bumpy
    flipped = F.copy()
    flipped[1::4] = flipped[1::4][:, ::-1]
    U, G, r = conemesh.remesh(V, flipped, repair=True, quiet=True)
    assert sorted(r["repair"]["flipped_faces"]) == list(range(1, len(F), 4))
    assert conemesh.check(U, G)["valid"]
    # Without it, the keyword is named in the refusal.
    with pytest.raises(conemesh.InputError, match="repair=True"):
        conemesh.remesh(V, flipped, quiet=True)
    # On a valid input the repair changes nothing: the same bytes as without it.
    U1, G1, r1 = conemesh.remesh(V, F, repair=True, quiet=True)
    U0, G0, r0 = conemesh.remesh(V, F, quiet=True)
    assert r0["repair"] is None and r1["repair"]["flipped_faces"] == []
    assert np.array_equal(U0, U1) and np.array_equal(G0, G1)


def test_output_paths_are_checked_before_the_run_and_written_together(bumpy, tmp_path):
    V, F = bumpy
    t0 = time.monotonic()
    with pytest.raises(conemesh.FileError, match="does not exist"):
        conemesh.remesh(V, F, report=tmp_path / "missing" / "r.json", quiet=True)
    (tmp_path / "plots-file").write_text("a file")
    with pytest.raises(conemesh.FileError, match="not a folder"):
        conemesh.remesh(V, F, plots=tmp_path / "plots-file", write_metric=tmp_path / "m.sol", quiet=True)
    with pytest.raises(conemesh.FileError, match="same path"):
        conemesh.remesh(V, F, report=tmp_path / "x", write_metric=tmp_path / "x", quiet=True)
    assert time.monotonic() - t0 < 2.0, "refused before remeshing (a run takes seconds)"
    assert not (tmp_path / "m.sol").exists() and not (tmp_path / "x").exists()
    U, G, _ = conemesh.remesh(
        V, F, report=tmp_path / "r.json", plots=tmp_path / "plots", write_metric=tmp_path / "m.sol", quiet=True
    )
    assert (tmp_path / "r.json").is_file() and (tmp_path / "m.sol").is_file()
    assert any((tmp_path / "plots").glob("*.png"))
