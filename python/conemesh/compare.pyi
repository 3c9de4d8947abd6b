"""Type stubs of conemesh.compare (the module is callable as ``compare``)."""

import os
from typing import Any, Iterable, Mapping, Sequence

import pandas

MEASURES: tuple[tuple[str, str, bool], ...]
COLUMNS: tuple[str, ...]
OWN_ARGS: tuple[str, ...]

def compare(
    configs: Mapping[str, str | Sequence[str]] | Iterable[tuple[str, str | Sequence[str]]],
    inputs: str | os.PathLike[str] | Iterable[str | os.PathLike[str]],
    seeds: int | str | Iterable[int] = 1,
    out_dir: str | os.PathLike[str] | None = None,
    client: Any = None,
    *,
    timeout: float | None = 3600.0,
    workers: int | None = None,
) -> pandas.DataFrame: ...
def summary(df: pandas.DataFrame) -> pandas.DataFrame: ...
def paired(df: pandas.DataFrame) -> pandas.DataFrame: ...
def sign_test_p(wins: int, losses: int) -> float: ...
def __call__(
    configs: Mapping[str, str | Sequence[str]] | Iterable[tuple[str, str | Sequence[str]]],
    inputs: str | os.PathLike[str] | Iterable[str | os.PathLike[str]],
    seeds: int | str | Iterable[int] = 1,
    out_dir: str | os.PathLike[str] | None = None,
    client: Any = None,
    **kwargs: Any,
) -> pandas.DataFrame: ...
