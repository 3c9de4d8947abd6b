"""Type stubs of conemesh.batch (the module is callable as ``batch``)."""

import os
from typing import Any, Iterable, Mapping, Sequence

import pandas

MESH_EXTENSIONS: tuple[str, ...]
NONDETERMINISTIC: tuple[str, ...]
COLUMNS: tuple[str, ...]

def batch(
    inputs: str | os.PathLike[str] | Iterable[str | os.PathLike[str]],
    out_dir: str | os.PathLike[str],
    options: Mapping[str, Any] | None = None,
    client: Any = None,
    *,
    table: str | os.PathLike[str] | None = "table.csv",
    timeout: float | None = 3600.0,
    workers: int | None = None,
    args: Sequence[str] = (),
) -> pandas.DataFrame: ...
def run_one(job: Mapping[str, Any]) -> dict[str, Any]: ...
def main(argv: Sequence[str] | None = None) -> int: ...
def __call__(
    inputs: str | os.PathLike[str] | Iterable[str | os.PathLike[str]],
    out_dir: str | os.PathLike[str],
    options: Mapping[str, Any] | None = None,
    client: Any = None,
    **kwargs: Any,
) -> pandas.DataFrame: ...
