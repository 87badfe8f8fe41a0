"""Result objects: the CLI's JSON documents with attribute access and numpy
arrays wherever the JSON has numeric lists."""

from __future__ import annotations

import contextlib

from collections.abc import Mapping
from typing import Any, Iterator

import numpy as np


def _number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


# The types a document's plain numbers (and nulls) have: a list of these
# alone is an array, decided without a call per item.
_PLAIN = frozenset((int, float, type(None)))


def _numeric(v: list) -> bool:
    """Whether a list holds only numbers (None, JSON's null, counting as
    NaN), or only equally long non-empty lists of numbers: then it is an
    array."""
    if all(type(x) in _PLAIN for x in v) or all(_number(x) or x is None for x in v):
        return True
    return (
        all(isinstance(x, list) and x and all(_number(y) for y in x) for x in v)
        and len({len(x) for x in v}) == 1
    )


def _convert(v: Any) -> Any:
    if isinstance(v, dict):
        return Result(v)
    if isinstance(v, list):
        if v and all(isinstance(x, dict) for x in v):
            return [Result(x) for x in v]
        if _numeric(v):
            # (None, JSON's null, is NaN in a float array.)
            return np.asarray(v, dtype=float)
        return [_convert(x) for x in v]
    return v


class Result(Mapping):
    """A result: fields carry the names of the CLI's JSON output (see the
    README); read them as attributes (``r.restitution``) or items
    (``r["restitution"]``). Numeric lists are ``numpy`` arrays; lists of
    records (``points``, ``special_points``) are lists of ``Result``, whose
    fields :meth:`column` gathers into one array."""

    __slots__ = ("_fields",)

    def __init__(self, document: Mapping[str, Any]):
        object.__setattr__(
            self, "_fields", {k: _convert(v) for k, v in document.items()}
        )

    def __getattr__(self, name: str) -> Any:
        try:
            return self._fields[name]
        except KeyError:
            raise AttributeError(
                f"no field {name!r} (fields: {', '.join(self._fields)})"
            ) from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("results are read-only")

    def __getitem__(self, key: str) -> Any:
        return self._fields[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._fields)

    def __len__(self) -> int:
        return len(self._fields)

    def __dir__(self):
        return list(self._fields) + ["column", "to_dict"]

    def __repr__(self) -> str:
        parts = []
        for k, v in self._fields.items():
            if isinstance(v, np.ndarray):
                parts.append(f"{k}=array{v.shape}")
            elif isinstance(v, list):
                parts.append(f"{k}=[{len(v)} items]")
            elif isinstance(v, Result):
                parts.append(f"{k}=Result(...)")
            else:
                parts.append(f"{k}={v!r}")
        return "Result(" + ", ".join(parts) + ")"

    def column(self, field: str, records: str = "points") -> np.ndarray:
        """The values of ``field`` over the records ``records`` (default
        ``points``) as one array, e.g. ``branch.column("parameter")`` or
        ``branch.column("max_displacement")`` (one row per point)."""
        rows = self._fields[records]
        return np.asarray([r[field] for r in rows], dtype=float)

    def to_dict(self) -> dict:
        """Plain Python data (arrays as lists), as the CLI's JSON."""

        def plain(v: Any) -> Any:
            if isinstance(v, Result):
                return v.to_dict()
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, list):
                return [plain(x) for x in v]
            return v

        return {k: plain(v) for k, v in self._fields.items()}


@contextlib.contextmanager
def _keeping_on_ctrl_c(raw: bool = False):
    """KeyboardInterrupt keeps the partial result the core attached
    (``.result``) as a :class:`Result`, as the CLI keeps what is done."""
    try:
        yield
    except KeyboardInterrupt as e:
        if not raw and isinstance(getattr(e, "result", None), dict):
            e.result = Result(e.result)
        raise
