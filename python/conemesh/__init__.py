"""conemesh: anisotropic surface remeshing by locally isometric embedding (cone patches).

numpy in and out, in the style of libigl and gpytoolbox: a mesh is a pair ``(V, F)`` of a
float64 array of shape ``(n, 3)`` (vertex positions) and an integer array of shape
``(m, 3)`` (triangles as 0-based vertex ids, counter-clockwise seen from outside).

Functions: :func:`remesh`, :func:`read`, :func:`write`, :func:`evaluate`, :func:`check`,
:func:`patches`, :func:`param`, :func:`remesh_options`, :func:`batch` (corpus runs on
Dask, in :mod:`conemesh.batch`) and :func:`compare` (configurations × inputs × seeds on the
same engine, in :mod:`conemesh.compare`). Errors are :class:`Error` and its subclasses.
"""

from __future__ import annotations

import difflib
import inspect
import json
import os
import warnings
from typing import Any, Mapping

import numpy as np

from . import _conemesh
from ._errors import (
    CertificateError,
    Error,
    FileError,
    InputError,
    MetricError,
    OptionError,
    RemeshError,
)

__version__ = _conemesh.__version__

__all__ = [
    "remesh",
    "remesh_options",
    "read",
    "write",
    "evaluate",
    "check",
    "patches",
    "param",
    "render",
    "batch",
    "compare",
    "Error",
    "InputError",
    "OptionError",
    "MetricError",
    "FileError",
    "CertificateError",
    "RemeshError",
]


# ------------------------------------------------------------------ arrays


def _vertices(V: Any, name: str = "V") -> np.ndarray:
    """``V`` as a C-contiguous float64 (n, 3) array (a copy only when needed)."""
    try:
        a = np.asarray(V)
    except Exception as e:  # ragged lists and the like
        raise InputError(f"{name} is not an array: {e}") from None
    if a.dtype.kind not in "fiu":
        raise InputError(f"{name} must hold numbers, got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"{name} must have shape (n, 3), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _faces(F: Any, name: str = "F") -> np.ndarray:
    """``F`` as a C-contiguous int64 (m, 3) array; any integer dtype is accepted."""
    try:
        a = np.asarray(F)
    except Exception as e:
        raise InputError(f"{name} is not an array: {e}") from None
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"{name} must have shape (m, 3), got {a.shape}")
    if a.dtype.kind not in "iu":
        raise InputError(f"{name} must have an integer dtype, got {a.dtype}")
    if a.dtype.kind == "u" and a.size and a.max() > np.iinfo(np.int64).max:
        bad = int(np.argmax(a.max(axis=1) > np.iinfo(np.int64).max))
        err = InputError(f"face f{bad} references a vertex index beyond int64")
        err.faces = [bad]
        raise err
    return np.ascontiguousarray(a, dtype=np.int64)


def _metric(metric: Any) -> tuple[np.ndarray | None, str | None]:
    """A user metric as ``(array, None)`` or ``(None, path)``."""
    if metric is None:
        return None, None
    if isinstance(metric, (str, os.PathLike)):
        return None, os.fspath(metric)
    a = np.asarray(metric)
    if a.dtype.kind not in "fiu":
        raise MetricError(f"metric must hold numbers, got dtype {a.dtype}")
    if a.ndim != 3 or a.shape[1:] != (3, 3):
        raise MetricError(
            f"metric must have shape (n, 3, 3), one tensor per vertex, got {a.shape}"
        )
    return np.ascontiguousarray(a, dtype=np.float64), None


# ------------------------------------------------------------------ options


def remesh_options() -> list[dict[str, Any]]:
    """The keywords of :func:`remesh`: every option of ``conemesh remesh``.

    Returns
    -------
    list of dict
        One dict per keyword, in the CLI's order: ``name`` (the keyword), ``flag`` (the CLI
        flag), ``kind`` (``"flag"``: a bool; ``"value"``: one value; ``"list"``: repeatable),
        ``type`` (``"bool"``, ``"int"``, ``"float"``, ``"str"``, as the CLI's parser takes it),
        ``default`` (as the CLI prints it, a string, or ``None`` when the option is off
        unless given), ``choices`` and ``help`` (the CLI's text). ``--metric`` is not
        among them: it is :func:`remesh`'s third parameter, ``metric``.
    """
    return [dict(o) for o in _OPTIONS]


# `--metric` is the third parameter, which also takes an array.
_OPTIONS = [o for o in _conemesh.remesh_options() if o["name"] != "metric"]
_BY_NAME = {o["name"]: o for o in _OPTIONS}


def _value(v: Any) -> str:
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    if isinstance(v, (float, np.floating)):
        return repr(float(v))  # shortest text that parses back to the same float64
    return str(v)


def _remesh_args(options: Mapping[str, Any], caller: str = "remesh") -> list[str]:
    """Keywords → ``conemesh remesh`` flags (``--name=value``), checked by name here and
    by value by the CLI's own parser, so that no default is restated in Python."""
    args: list[str] = []
    for name, value in options.items():
        opt = _BY_NAME.get(name)
        if opt is None:
            near = difflib.get_close_matches(name, list(_BY_NAME), n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise TypeError(f"{caller}() got an unexpected keyword argument {name!r}{hint}")
        if value is None:
            continue
        flag = opt["flag"]
        if opt["kind"] == "flag":
            if not isinstance(value, (bool, np.bool_)):
                raise OptionError(f"{name} takes True or False, got {value!r}")
            if value:
                args.append(flag)
        elif opt["kind"] == "list":
            if isinstance(value, (str, os.PathLike)):
                items = [value]
            elif isinstance(value, Mapping):
                items = [f"{k}={_value(v)}" for k, v in value.items()]
            else:
                items = list(value)
            args.extend(f"{flag}={_value(x)}" for x in items)
        else:
            if isinstance(value, (bool, np.bool_)):
                raise OptionError(f"{name} takes a value, not {value!r}")
            if name == "improvers" and not isinstance(value, str):
                value = ",".join(value)
            args.append(f"{flag}={_value(value)}")
    return args


def _typed_default(o: Mapping[str, Any]) -> Any:
    """The CLI default as a Python value (for the signature shown by ``help``)."""
    d = o["default"]
    if o["kind"] == "flag":
        return False
    if d is None:
        return None
    return {"int": int, "float": float}.get(o["type"], str)(d)


# ------------------------------------------------------------------ functions


def remesh(V, F, metric=None, **options):
    """Remesh a surface anisotropically (Algorithm 1), as ``conemesh remesh``.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions (any real dtype; used as float64).
    F : array_like, shape (m, 3)
        Triangles, 0-based vertex ids (any integer dtype), counter-clockwise.
    metric : array_like of shape (n, 3, 3), str or os.PathLike, optional
        A user metric: one symmetric tensor per vertex of ``V`` (file units), or the path of
        a Medit ``.sol`` file. Default: the curvature metric (Sec. 3.1).
    **options
        Every option of ``conemesh remesh``, as a keyword named like the flag
        (``--ltar-factor`` is ``ltar_factor``) with the same default; see
        :func:`remesh_options` or ``conemesh remesh --help`` for all of them. The most used:
        ``ltar_factor=1.5`` (target edge length as a multiple of the mean metric edge
        length), ``ltar=None`` (absolute target), ``seed=1``, ``strategy="cone"``,
        ``strategy_opt=None`` (a mapping ``{"rings": 4}`` or a list of ``"KEY=VALUE"``),
        ``param="sd"``, ``remesher="lct"``, ``hausd=0.0035``, ``sweeps=1``,
        ``corner_defect=1.0``, ``feature_angle="off"`` (or ``"auto"``, or degrees),
        ``crease_metric=False``, ``coarse="auto"``, ``hmin``,
        ``hmax``, ``hgrad`` (``None``), ``keep_boundary=False``,
        ``boundary_corner_angle=45.0``, ``improvers=None`` (``"surface,eq5"``; a list is
        joined; ``"surface"`` leaves Algorithm 2 out), ``improver_opt=None`` (a list of
        ``"NAME.KEY=VALUE"``, e.g. ``"eq5.q=0.7"``), ``max_patches=None``,
        ``no_self_intersections=False``,
        ``repair=False`` (weld, drop zero-area faces, orient, split non-manifold elements
        first; the report's ``repair`` lists every change), ``quiet=False`` (no progress
        bar on stderr). Files: ``report``, ``plots`` (with ``mesh.png``, the output coloured
        by q), ``write_patches`` (the patch of each output face), ``write_metric``,
        ``write_input_metric``, ``debug_dir`` (``None``: an array has no folder to write
        offending patches into); checked before the run and written together (all or none).

    Returns
    -------
    V : numpy.ndarray of float64, shape (n', 3)
        The remeshed surface's vertices (file units).
    F : numpy.ndarray of int64, shape (m', 3)
        Its triangles.
    report : dict
        The JSON report of ``conemesh remesh --report``: ``repair`` (with ``repair=True``:
        welded vertices, dropped/flipped faces, cut edges, split vertices; else ``None``),
        ``run`` (options, certificates, per-stage times, warnings), ``eval`` (the yardstick of ``conemesh eval``: Table-1
        statistics, distances, flips, topology), ``seconds``, ``peak_rss_mib`` (of this
        process), and ``table_row`` (the Table-1 line).

    Raises
    ------
    TypeError
        An unknown keyword.
    OptionError
        A refused option value (the CLI's own parser and registries decide).
    InputError
        Bad arrays, or a mesh that is not an oriented manifold (``edges``, ``vertices``).
    MetricError
        A metric of the wrong shape, not symmetric or not positive definite (``vertices``).
    CertificateError, RemeshError
        A certificate or stage failed (``patch``, ``seed``, ``stage``, element ids).
    KeyboardInterrupt
        Ctrl-C: the run stops after the current patch (the improvers after the loop are
        not interrupted once started).

    Notes
    -----
    The work runs with the GIL released. For the same seed the output is the CLI's byte
    for byte: ``write("out.obj", *remesh(*read("in.off"))[:2])`` writes what
    ``conemesh remesh in.off -o out.obj`` writes.
    """
    args = _remesh_args(options)
    Va, Fa = _vertices(V), _faces(F)
    m_arr, m_path = _metric(metric)
    (U, G), report = _conemesh.remesh(Va, Fa, m_arr, m_path, args)
    return U, G, json.loads(report)


remesh.__signature__ = inspect.Signature(  # type: ignore[attr-defined]
    [
        inspect.Parameter("V", inspect.Parameter.POSITIONAL_OR_KEYWORD),
        inspect.Parameter("F", inspect.Parameter.POSITIONAL_OR_KEYWORD),
        inspect.Parameter("metric", inspect.Parameter.POSITIONAL_OR_KEYWORD, default=None),
    ]
    + [
        inspect.Parameter(o["name"], inspect.Parameter.KEYWORD_ONLY, default=_typed_default(o))
        for o in _OPTIONS
    ]
)


def read(path):
    """Read a mesh file (OBJ, OFF, PLY, STL, Medit ``.mesh``; by extension).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    V : numpy.ndarray of float64, shape (n, 3)
        Vertex positions, bit for bit as in the file.
    F : numpy.ndarray of int64, shape (m, 3)
        Triangles (polygons are cut into triangles inside them, with a warning;
        a polygon that is not simple or too far from planar is refused).

    Raises
    ------
    FileError
        The file cannot be read, or is malformed (the message names the line and element).

    Notes
    -----
    What the reader had to fix or skip is issued as ``UserWarning``.
    """
    (V, F), notes = _conemesh.read(os.fspath(path))
    for n in notes:
        warnings.warn(f"{os.fspath(path)}: {n}", stacklevel=2)
    return V, F


def write(path, V, F):
    """Write a mesh file, the format by extension; atomic (no partial file on error).

    Parameters
    ----------
    path : str or os.PathLike
        ``.obj``, ``.off``, ``.ply``, ``.stl`` or ``.mesh``.
    V : array_like, shape (n, 3)
        Vertex positions (written so that they read back bit for bit, except binary STL).
    F : array_like, shape (m, 3)
        Triangles, any integer dtype.

    Raises
    ------
    InputError
        Bad arrays (shape, NaN, index out of range).
    FileError
        The file cannot be written.
    """
    _conemesh.write(os.fspath(path), _vertices(V), _faces(F))


def evaluate(
    V_in,
    F_in,
    V_out,
    F_out,
    metric=None,
    *,
    ltar_factor=None,
    ltar=None,
    samples=100_000,
    seed=0,
    self_intersections=True,
    name="output",
):
    """Score a remeshed surface against its input, as ``conemesh eval`` (Sec. 4.1, Table 1).

    Parameters
    ----------
    V_in : array_like, shape (n, 3)
        The input (reference) surface's vertices; its bounding-box diagonal is the unit.
    F_in : array_like, shape (m, 3)
        Its triangles.
    V_out : array_like, shape (n', 3)
        The surface to score.
    F_out : array_like, shape (m', 3)
        Its triangles.
    metric : array_like of shape (n, 3, 3), str or os.PathLike, optional
        Per-input-vertex tensors (or a ``.sol`` path); default the curvature metric.
    ltar_factor : float, optional
        L_tar = ltar_factor · L_avg (default 1.5 when ``ltar`` is not given).
    ltar : float, optional
        Absolute target edge length (metric length, file units).
    samples : int, default 100000
        Random samples per surface for the Hausdorff and RMS distances.
    seed : int, default 0
        Seed of the sampling.
    self_intersections : bool, default True
        Search for self-intersections of the output (exact).
    name : str, default "output"
        The first column of ``table_row``.

    Returns
    -------
    dict
        ``conemesh eval --json``'s ``report`` (``output_quality`` with q_min, q_max, q_avg,
        theta_min, theta_max, theta_avg: the Table-1 row; ``distance`` with hausdorff,
        rms and their ``_rel`` forms; ``flips``, ``self_intersections``, ``topology_kept``,
        ...), plus ``table_header`` and ``table_row`` (the Table-1 line).
    """
    m_arr, m_path = _metric(metric)
    out = _conemesh.evaluate(
        _vertices(V_in, "V_in"),
        _faces(F_in, "F_in"),
        _vertices(V_out, "V_out"),
        _faces(F_out, "F_out"),
        m_arr,
        m_path,
        None if ltar_factor is None else float(ltar_factor),
        None if ltar is None else float(ltar),
        int(samples),
        int(seed),
        bool(self_intersections),
        str(name),
    )
    doc = json.loads(out)
    report = doc["report"]
    report["table_header"] = doc["table_header"]
    report["table_row"] = doc["table_row"]
    return report


def check(V, F, *, self_intersections=True):
    """Check a mesh: topology, manifoldness, orientation, degenerate faces,
    self-intersections (exact), as ``conemesh check --json``.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions.
    F : array_like, shape (m, 3)
        Triangles.
    self_intersections : bool, default True
        Search for self-intersecting face pairs.

    Returns
    -------
    dict
        ``valid``, ``components``, ``euler``, ``boundary_loops``, ``non_manifold_edges``
        and ``non_manifold_edge_ids`` (the first few), the same for vertices, orientation and
        degenerate faces, and ``self_intersections`` (``None`` when not searched).
    """
    return json.loads(_conemesh.check(_vertices(V), _faces(F), bool(self_intersections)))


def patches(V, F, *, seed=1, strategy="cone", strategy_opt=None, stats=False):
    """Cover a mesh with certified disk patches (Sec. 3.2, no remeshing), as
    ``conemesh patches``.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions.
    F : array_like, shape (m, 3)
        Triangles.
    seed : int, default 1
        Seed of the seed-vertex choice.
    strategy : str, default "cone"
        Patch strategy by registry name (``conemesh stages`` lists them).
    strategy_opt : mapping or list of str, optional
        Its options, ``{"rings": 4}`` or ``["rings=4"]``.
    stats : bool, default False
        Also return the per-patch statistics.

    Returns
    -------
    ids : numpy.ndarray of int64, shape (m,)
        The patch of each face (0-based, in order of creation).
    stats : dict
        Only with ``stats=True``: ``strategy``, ``seed`` and ``stats`` (one dict per patch).
    """
    if strategy_opt is None:
        opts: list[str] = []
    elif isinstance(strategy_opt, Mapping):
        opts = [f"{k}={_value(v)}" for k, v in strategy_opt.items()]
    elif isinstance(strategy_opt, str):
        opts = [strategy_opt]
    else:
        opts = [str(x) for x in strategy_opt]
    ids, info = _conemesh.patches(_vertices(V), _faces(F), int(seed), str(strategy), opts)
    return (ids, json.loads(info)) if stats else ids


def param(V, F, *, method="sd", report=False):
    """Map a disk-topology mesh bijectively into the plane (Sec. 3.3), as ``conemesh param``.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions.
    F : array_like, shape (m, 3)
        Triangles of a topological disk (one boundary loop).
    method : {"sd", "tutte"}, default "sd"
        Symmetric Dirichlet (projected Newton, free boundary) or Tutte's embedding.
    report : bool, default False
        Also return the distortion report.

    Returns
    -------
    uv : numpy.ndarray of float64, shape (n, 2)
        Planar coordinates per vertex, certified bijective (exact orientation tests);
        NaN for vertices no face uses.
    report : dict
        Only with ``report=True``: ``method`` and ``distortion``.

    Raises
    ------
    InputError
        The mesh is not a disk.
    """
    uv, info = _conemesh.param(_vertices(V), _faces(F), str(method))
    return (uv, json.loads(info)) if report else uv


# `conemesh.batch` is the module `conemesh/batch.py`, which is also callable as the function
# `conemesh.batch.batch`: importing the module must not shadow the function.
def render(
    V,
    F,
    *,
    color="q",
    metric=None,
    reference=None,
    patches=None,
    width=1500,
    height=600,
    wireframe="auto",
):
    """Draw a mesh as ``conemesh render`` does: the front, side and iso views side by side,
    faces coloured by ``color``, above a colour bar.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions.
    F : array_like, shape (m, 3)
        Triangles.
    color : {"q", "min-angle", "patch", "distance", "none"}, default "q"
        ``q`` (2√3·a/(p·h) in the metric) or ``min-angle`` (the smallest angle in the
        metric), both with the faces whose smallest angle is below 20° in magenta (the
        paper's Fig. 6); ``patch`` (needs ``patches``; neighbouring patches in different
        colours, Fig. 3); ``distance`` (to ``reference``, in % of its bounding-box diagonal);
        ``none``.
    metric : array_like of shape (n, 3, 3) or (n_ref, 3, 3), str or os.PathLike, optional
        The metric of ``q`` and ``min-angle``: one tensor per vertex of ``V`` (as
        ``remesh --write-metric`` writes), or per vertex of the reference, or a ``.sol``
        path. Default: the curvature metric of the reference, or of ``(V, F)`` without one.
    reference : tuple (V_ref, F_ref), optional
        The reference (input) surface.
    patches : array_like of int, shape (m,), optional
        The patch of each face; negative for none.
    width, height : int, default 1500, 600
        Picture size in pixels.
    wireframe : {"auto", "on", "off"}, default "auto"
        The faces' edges; ``auto`` draws them when the visible triangles are large enough.

    Returns
    -------
    numpy.ndarray of uint8, shape (height, width, 3)
        The RGB picture, row by row from the top.
    """
    m_arr, m_path = _metric(metric)
    v_ref = f_ref = None
    if reference is not None:
        try:
            v_ref, f_ref = reference
        except (TypeError, ValueError):
            raise InputError("reference must be a pair (V_ref, F_ref)") from None
        v_ref, f_ref = _vertices(v_ref, "V_ref"), _faces(f_ref, "F_ref")
    ids = None
    if patches is not None:
        ids = np.asarray(patches)
        if ids.ndim != 1 or ids.dtype.kind not in "iu":
            raise InputError(
                f"patches must be a 1-D integer array, got shape {ids.shape}, dtype {ids.dtype}"
            )
        ids = np.ascontiguousarray(ids, dtype=np.int64)
    for name, value in (("width", width), ("height", height)):
        if not isinstance(value, (int, np.integer)) or not 0 < value < 2**32:
            raise OptionError(f"{name} must be a positive integer, got {value!r}")
    return _conemesh.render(
        _vertices(V),
        _faces(F),
        str(color),
        m_arr,
        m_path,
        v_ref,
        f_ref,
        ids,
        int(width),
        int(height),
        str(wireframe),
    )


from . import batch  # noqa: E402
from . import compare  # noqa: E402
