"""Type stubs of conemesh (numpy in and out). Docstrings: ``help(conemesh.remesh)``."""

import os
from typing import Any, Literal, Mapping, Sequence

import numpy as np
import numpy.typing as npt

from . import batch as batch
from . import compare as compare
from ._errors import (
    CertificateError as CertificateError,
    Error as Error,
    FileError as FileError,
    InputError as InputError,
    MetricError as MetricError,
    OptionError as OptionError,
    RemeshError as RemeshError,
)

__version__: str

# (n, 3) float64 vertex positions; (m, 3) integer triangles (0-based vertex ids).
Vertices = npt.NDArray[np.float64]
Faces = npt.NDArray[np.int64]
PathLike = str | os.PathLike[str]

def remesh_options() -> list[dict[str, Any]]: ...

# Generated from remesh_options(); tests/test_remesh.py holds it equal to the runtime signature.
def remesh(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    metric: npt.ArrayLike | PathLike | None = None,
    *,
    ltar_factor: float = 1.5,
    ltar: float | None = None,
    seed: int = 1,
    strategy: str = "cone",
    strategy_opt: Sequence[str] | Mapping[str, object] | None = None,
    param: str = "sd",
    param_opt: Sequence[str] | Mapping[str, object] | None = None,
    remesher: str = "lct",
    remesher_opt: Sequence[str] | Mapping[str, object] | None = None,
    expand_rings: int | None = None,
    max_patch_faces: int | None = None,
    max_patches: int | None = None,
    report: str | os.PathLike[str] | None = None,
    plots: str | os.PathLike[str] | None = None,
    write_patches: str | os.PathLike[str] | None = None,
    write_metric: str | os.PathLike[str] | None = None,
    write_input_metric: str | os.PathLike[str] | None = None,
    debug_dir: str | os.PathLike[str] | None = None,
    no_self_intersections: bool = False,
    hausd: float = 0.0035,
    sweeps: int = 1,
    batch: int = 1,
    region_faces: int = 6000,
    threads: int | None = None,
    corner_defect: float = 1.0,
    feature_angle: float | Literal["auto", "off"] = "auto",
    crease_metric: bool = False,
    coarse: Literal["auto", "on", "off"] = "auto",
    hmin: float | None = None,
    hmax: float | None = None,
    hgrad: float | None = None,
    keep_boundary: bool = False,
    boundary_corner_angle: float = 45.0,
    improvers: str | Sequence[str] | None = None,
    improver_opt: Sequence[str] | Mapping[str, object] | None = None,
    repair: bool = False,
    quiet: bool = False,
) -> tuple[Vertices, Faces, dict[str, Any]]: ...
def read(path: PathLike) -> tuple[Vertices, Faces]: ...
def write(path: PathLike, V: npt.ArrayLike, F: npt.ArrayLike) -> None: ...
def evaluate(
    V_in: npt.ArrayLike,
    F_in: npt.ArrayLike,
    V_out: npt.ArrayLike,
    F_out: npt.ArrayLike,
    metric: npt.ArrayLike | PathLike | None = None,
    *,
    ltar_factor: float | None = None,
    ltar: float | None = None,
    samples: int = 100000,
    seed: int = 0,
    self_intersections: bool = True,
    name: str = "output",
) -> dict[str, Any]: ...
def check(V: npt.ArrayLike, F: npt.ArrayLike, *, self_intersections: bool = True) -> dict[str, Any]: ...
def render(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    color: Literal["q", "min-angle", "patch", "distance", "none"] = "q",
    metric: npt.ArrayLike | PathLike | None = None,
    reference: tuple[npt.ArrayLike, npt.ArrayLike] | None = None,
    patches: npt.ArrayLike | None = None,
    width: int = 1500,
    height: int = 600,
    wireframe: Literal["auto", "on", "off"] = "auto",
) -> npt.NDArray[np.uint8]: ...
def patches(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    seed: int = 1,
    strategy: str = "cone",
    strategy_opt: Sequence[str] | Mapping[str, object] | None = None,
    stats: bool = False,
) -> npt.NDArray[np.int64] | tuple[npt.NDArray[np.int64], dict[str, Any]]: ...
def param(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    method: Literal["sd", "tutte"] = "sd",
    report: bool = False,
) -> npt.NDArray[np.float64] | tuple[npt.NDArray[np.float64], dict[str, Any]]: ...
