"""Storeys that yield: :func:`hysteresis`, a storey law (elastic,
bilinear, Bouc–Wen) under a cyclic drift protocol or a drift history
(``vibroimpact hysteresis``).
"""

from __future__ import annotations

import os
from typing import Any, Optional, Sequence

import numpy as np

from . import _core
from ._checks import _count, _floats, _method, _real
from ._results import Result


def _drift_history(drift: Any) -> Optional[np.ndarray]:
    """The drifts of ``drift``: an array, or a file of one drift a line (a
    header line and ``#`` comments skipped), read as ``--drift FILE`` reads
    it."""
    if drift is None:
        return None
    if isinstance(drift, (str, os.PathLike)):
        path = os.fspath(drift)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise OSError(f"drift: {path}: cannot read: {e.strerror}") from None
        return _core.parse_drifts(text, path)
    d = _floats(drift, "drift", allow_scalar=False)
    if d.size == 0:
        raise ValueError("drift: no drifts")
    return d


def hysteresis(
    *,
    stiffness: float,
    law: str = "bilinear",
    yield_drift: Optional[float] = None,
    post_yield_ratio: float = 0.05,
    exponent: float = 2.0,
    beta: float = 0.5,
    gamma: float = 0.5,
    degradation_a: float = 0.0,
    degradation_nu: float = 0.0,
    degradation_eta: float = 0.0,
    cap_ratio: Optional[float] = None,
    plastic_drift: Optional[float] = None,
    post_capping_drift: Optional[float] = None,
    residual_ratio: Optional[float] = None,
    ultimate_drift: Optional[float] = None,
    lambda_s: Optional[float] = None,
    lambda_c: Optional[float] = None,
    lambda_k: Optional[float] = None,
    c_s: float = 1.0,
    c_c: float = 1.0,
    c_k: float = 1.0,
    amplitudes: Optional[Sequence[float]] = None,
    cycles: int = 2,
    points: int = 200,
    drift: Any = None,
    rtol: float = 1e-10,
) -> Result:
    """A storey law under cyclic drift (``vibroimpact hysteresis``).

    ``law``: ``"elastic"``, ``"bilinear"`` (kinematic hardening, OpenSees
    Steel01 without isotropic terms), ``"bouc-wen"`` (OpenSees BoucWen in
    yield-drift form, docs/theory.md §11) or ``"imk"`` (the modified
    Ibarra–Medina–Krawinkler storey, OpenSees IMKBilin, symmetric:
    ``cap_ratio``, ``plastic_drift``, ``post_capping_drift``,
    ``residual_ratio``, ``ultimate_drift``; ``lambda_s``, ``lambda_c``,
    ``lambda_k`` (m, none: no such deterioration) and ``c_s``, ``c_c``,
    ``c_k``). ``stiffness`` (N/m),
    ``yield_drift`` (m), ``post_yield_ratio`` in [0, 1); Bouc–Wen's
    ``exponent``, ``beta``, ``gamma`` and degradation ``degradation_a``,
    ``degradation_nu``, ``degradation_eta`` (1/J). The drift: the protocol
    of ``amplitudes`` (m) held ``cycles`` sine cycles each, ``points``
    samples a cycle (a multiple of 4), or ``drift``, an array or a file of
    drifts (m, linear between them, from rest). Bouc–Wen is integrated
    along the drift to ``rtol``.

    Returns ``law`` (its parameters), ``units``, ``peak_force`` (N),
    ``total_dissipated`` (J) and the arrays ``drift``, ``force`` and
    ``dissipated`` (the energy dissipated up to each drift)."""
    history = _drift_history(drift)
    amps = [] if amplitudes is None else [float(a) for a in _floats(amplitudes, "amplitudes")]
    if history is None and not amps:
        raise ValueError("amplitudes: give the protocol's drift amplitudes (m), or drift=")
    if history is not None and amps:
        raise ValueError("drift: give drift= or amplitudes=, not both")
    spec = (
        _method(law, ("elastic", "bilinear", "bouc-wen", "imk"), "law"),
        _real(stiffness, "stiffness"),
        _real(yield_drift, "yield_drift", optional=True),
        _real(post_yield_ratio, "post_yield_ratio"),
        _real(exponent, "exponent"),
        _real(beta, "beta"),
        _real(gamma, "gamma"),
        _real(degradation_a, "degradation_a"),
        _real(degradation_nu, "degradation_nu"),
        _real(degradation_eta, "degradation_eta"),
    )
    imk = (
        [_real(v, k, optional=True) for k, v in (
            ("cap_ratio", cap_ratio), ("plastic_drift", plastic_drift),
            ("post_capping_drift", post_capping_drift), ("residual_ratio", residual_ratio),
            ("ultimate_drift", ultimate_drift))],
        [_real(v, k, optional=True) for k, v in (
            ("lambda_s", lambda_s), ("lambda_c", lambda_c), ("lambda_k", lambda_k))],
        [_real(v, k) for k, v in (("c_s", c_s), ("c_c", c_c), ("c_k", c_k))],
    )
    return Result(
        _core.hysteresis(
            spec,
            amps,
            _count(cycles, "cycles", minimum=1, maximum=10**6),
            _count(points, "points", minimum=4, maximum=10**7),
            history,
            _real(rtol, "rtol", positive=True),
            imk,
        )
    )
