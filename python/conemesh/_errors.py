"""The exceptions of conemesh, one per kind of failure of the library (its typed errors).

Every class derives from :class:`Error`. Attributes that a failure does not have are
``None``; element ids are 0-based, in the numbering of the arrays (or file) you gave.
"""

from __future__ import annotations


class Error(Exception):
    """Base class of every conemesh error.

    Attributes
    ----------
    vertices : list of int or None
        Offending vertex ids.
    faces : list of int or None
        Offending face ids.
    edges : list of (int, int) or None
        Offending edges, as vertex-id pairs.
    face_pairs : list of (int, int) or None
        Pairs of intersecting faces.
    invariant : str or None
        The certificate that failed (``"non_manifold_edges"``, ``"self_intersections"``, ...).
    patch : int or None
        The patch of Algorithm 1 during which the failure happened.
    seed : int or None
        That patch's seed vertex.
    stage : str or None
        That patch's stage (``"parameterization"``, ``"planar remeshing"``, ...).
    index : int or None
        A bad vertex index in ``F``.
    kind : str or None
        A short name of a file error (``"parse"``, ``"os"``, ...).
    """

    vertices: list[int] | None = None
    faces: list[int] | None = None
    edges: list[tuple[int, int]] | None = None
    face_pairs: list[tuple[int, int]] | None = None
    invariant: str | None = None
    patch: int | None = None
    seed: int | None = None
    stage: str | None = None
    index: int | None = None
    kind: str | None = None


class InputError(Error, ValueError):
    """The mesh is not one conemesh can work on: wrong shape or dtype, NaN, an index out of
    range, a repeated vertex, or (for ``remesh``) not an oriented manifold; ``param``: not a
    disk. ``vertices``/``faces``/``edges`` name the elements."""


class OptionError(Error, ValueError):
    """An option's value is refused (an unknown keyword is a ``TypeError``)."""


class MetricError(Error, ValueError):
    """A user metric of the wrong shape, not symmetric, NaN, or not positive definite on the
    surface's tangent plane; ``vertices`` names the vertex."""


class FileError(Error, OSError):
    """A mesh or ``.sol`` file that cannot be read or written; ``kind`` says why."""


class CertificateError(Error):
    """A certified invariant does not hold (``invariant`` names it, the element attributes the
    offenders; ``patch``/``seed`` where Algorithm 1 was)."""


class RemeshError(Error):
    """A stage of Algorithm 1 (or of ``patches``/``param``) failed otherwise; ``patch``,
    ``seed`` and ``stage`` say where."""


__all__ = [
    "Error",
    "InputError",
    "OptionError",
    "MetricError",
    "FileError",
    "CertificateError",
    "RemeshError",
]
