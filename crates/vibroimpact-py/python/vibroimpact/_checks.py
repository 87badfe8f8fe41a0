"""Argument checks shared by the topic modules: every public function turns
its arguments into what the compiled extension takes (float64 arrays,
finite floats, bounded counts, flags, masses, a :class:`Model`, a method
name among its choices, a progress callable), raising ``ValueError`` or
``TypeError`` that name the argument. Also the type aliases of the public
signatures (``Progress``, ``ArrayLike``, ``ModelLike``).
"""

from __future__ import annotations

import math
import os
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from ._core import Model


Progress = Optional[Callable[[int, int], Any]]
ArrayLike = Union[Sequence[float], np.ndarray, float]
# `os.PathLike[str]` evaluated here, not as a string, so that the signatures
# using ModelLike resolve (typing.get_type_hints) in any module.
ModelLike = Union[Model, str, os.PathLike[str]]


def _floats(x: Any, name: str, *, allow_scalar: bool = True) -> np.ndarray:
    """A contiguous, aligned float64 1-D array from any array-like; NaN and
    infinities are rejected with the argument's name."""
    if (
        type(x) is np.ndarray
        and x.dtype == np.float64
        and x.ndim == 1
        and x.flags.c_contiguous
        and x.flags.aligned
    ):
        # The usual case (a record's samples): nothing to convert.
        a = x
    else:
        a = _converted(x, name, allow_scalar)
    if not np.isfinite(a).all():
        bad = np.flatnonzero(~np.isfinite(a))
        raise ValueError(f"{name}[{bad[0]}] = {a[bad[0]]}: must be finite")
    return a


def _converted(x: Any, name: str, allow_scalar: bool) -> np.ndarray:
    """`x` as a contiguous, aligned float64 1-D array (not yet checked
    for finiteness)."""
    if isinstance(x, (str, bytes)):
        raise TypeError(f"{name}: expected numbers, got {type(x).__name__}")
    try:
        raw = np.asarray(x)
    except Exception as e:  # ragged lists and the like
        raise ValueError(f"{name}: not an array of numbers ({e})") from None
    if np.iscomplexobj(raw):
        raise ValueError(f"{name}: complex values are not accepted")
    if raw.dtype == object or raw.dtype.kind not in "biuf":
        raise ValueError(f"{name}: expected numbers, got dtype {raw.dtype}")
    a = np.asarray(raw, dtype=np.float64)
    if a.ndim == 0 and allow_scalar:
        a = a.reshape(1)
    if a.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {a.shape}")
    return np.require(a, np.float64, ["C", "A"])


def _real(x: Any, name: str, *, positive: bool = False, optional: bool = False):
    """A finite float (or None if optional)."""
    if x is None and optional:
        return None
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(x).__name__}")
    v = float(x)
    if not math.isfinite(v) or (positive and v <= 0.0):
        raise ValueError(f"{name} = {v}: must be finite{' and > 0' if positive else ''}")
    return v


def _count(x: Any, name: str, *, minimum: int = 0, maximum: int = 10**9) -> int:
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
        raise TypeError(f"{name}: expected a whole number, got {type(x).__name__}")
    if not minimum <= x <= maximum:
        raise ValueError(f"{name} = {x}: must be from {minimum} to {maximum}")
    return int(x)


def _flag(x: Any, name: str) -> bool:
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(x).__name__}")
    return bool(x)


def _mass(x: Any, name: str) -> float:
    if isinstance(x, str):
        if x.strip() in ("wall", "inf", "infinity"):
            return math.inf
        raise ValueError(f"{name} = {x!r}: a mass in kg or 'wall'")
    if isinstance(x, float) and math.isinf(x) and x > 0:
        return math.inf
    return _real(x, name, positive=True)


def _model(model: Any) -> Model:
    if isinstance(model, Model):
        return model
    if isinstance(model, (str, os.PathLike)):
        return Model.load(os.fspath(model))
    if isinstance(model, dict):
        return Model.from_dict(model)
    raise TypeError(
        f"model: expected a vibroimpact.Model, a path or a dict, got {type(model).__name__}"
    )


def _with_impacts(m: Model, impacts: Optional[str], restitution: Any) -> Model:
    """``m`` with the ``impacts`` and ``restitution`` arguments applied
    (``--impacts``, ``--restitution``): every model a study builds has
    them."""
    if impacts is None and restitution is None:
        return m
    return m.with_impacts(
        None if impacts is None else _method(impacts, ("soft", "rigid"), "impacts"),
        _real(restitution, "restitution", optional=True),
    )


def _method(name: str, choices: Sequence[str], arg: str = "method") -> str:
    if name not in choices:
        raise ValueError(f"{arg} = {name!r}: give one of {', '.join(map(repr, choices))}")
    return name


def _progress(progress: Progress) -> Progress:
    if progress is not None and not callable(progress):
        raise TypeError("progress: expected a callable progress(done, total)")
    return progress
