"""Two-body impacts and contact laws: :func:`impact` (``vibroimpact
impact``), :func:`contact_force` (a law's force and derivatives) and
:func:`identify` (``vibroimpact identify``, the exponential law's a/b and
alpha from measured impacts), with the contact-law specification they share
(``_law_spec``, written as the model-file schema does) and the reading of
measured (impact velocity, value) pairs.
"""

from __future__ import annotations

import json
import os
from typing import Any, Optional, Union

import numpy as np

from . import _core
from ._checks import ArrayLike, Progress, _flag, _floats, _mass, _method, _progress, _real
from ._results import Result


_LAW_KEYS = (
    "law", "a_over_b", "alpha", "a", "stiffness", "exponent", "damping", "chi",
    "law_restitution", "min_impact_velocity", "form",
)


def _law_spec(
    law: str,
    *,
    a_over_b=None,
    alpha=None,
    a=1.0,
    stiffness=None,
    exponent=None,
    damping=None,
    chi=None,
    law_restitution=None,
    min_impact_velocity=1e-3,
    form="published",
) -> str:
    """The contact law as the model-file schema writes it (JSON)."""
    _method(form, ("published", "non-negative"), "form")
    uses = {
        "exponential": {"a_over_b", "alpha", "a", "form"},
        "hertz": {"stiffness", "exponent"},
        "kelvin-voigt": {"stiffness", "damping", "form"},
        "hunt-crossley": {"stiffness", "exponent", "chi", "form"},
        "lankarani-nikravesh": {"stiffness", "exponent", "law_restitution", "min_impact_velocity", "form"},
    }.get(law, set())
    given = {
        "a_over_b": a_over_b, "alpha": alpha, "stiffness": stiffness, "exponent": exponent,
        "damping": damping, "chi": chi, "law_restitution": law_restitution,
        "a": None if a == 1.0 else a, "form": None if form == "published" else form,
        "min_impact_velocity": None if min_impact_velocity == 1e-3 else min_impact_velocity,
    }
    unused = sorted(k for k, v in given.items() if v is not None and k not in uses)
    if uses and unused:
        raise ValueError(f"{', '.join(unused)}: not a parameter of law={law!r}")

    def need(v, key):
        if v is None:
            raise ValueError(f"law={law!r} needs {key}")
        return _real(v, key)

    n = 1.5 if exponent is None else _real(exponent, "exponent")
    if law == "exponential":
        spec = {
            "law": law,
            "a_over_b": 1.2 if a_over_b is None else _real(a_over_b, "a_over_b"),
            "alpha": 1.3e5 if alpha is None else _real(alpha, "alpha"),
            "a": _real(a, "a"),
            "form": form,
        }
    elif law == "hertz":
        spec = {"law": law, "stiffness": need(stiffness, "stiffness"), "exponent": n}
    elif law == "kelvin-voigt":
        spec = {
            "law": law,
            "stiffness": need(stiffness, "stiffness"),
            "damping": need(damping, "damping"),
            "form": form,
        }
    elif law == "hunt-crossley":
        spec = {
            "law": law,
            "stiffness": need(stiffness, "stiffness"),
            "exponent": n,
            "chi": need(chi, "chi"),
            "form": form,
        }
    elif law == "lankarani-nikravesh":
        spec = {
            "law": law,
            "stiffness": need(stiffness, "stiffness"),
            "exponent": n,
            "restitution": need(law_restitution, "law_restitution"),
            "min_impact_velocity": _real(min_impact_velocity, "min_impact_velocity"),
            "form": form,
        }
    else:
        raise ValueError(
            f"law = {law!r}: give 'exponential', 'hertz', 'kelvin-voigt', "
            "'hunt-crossley' or 'lankarani-nikravesh'"
        )
    return json.dumps(spec)


def impact(
    velocity: ArrayLike,
    *,
    law: str = "exponential",
    a_over_b: Optional[float] = None,
    alpha: Optional[float] = None,
    a: float = 1.0,
    stiffness: Optional[float] = None,
    exponent: Optional[float] = None,
    damping: Optional[float] = None,
    chi: Optional[float] = None,
    law_restitution: Optional[float] = None,
    min_impact_velocity: float = 1e-3,
    form: str = "published",
    mass1: float = 0.227,
    mass2: Union[float, str] = 0.227,
    method: Optional[str] = None,
    rtol: float = 1e-12,
    duration_level: Optional[float] = None,
    progress: Progress = None,
) -> Result:
    """Two-body impact relations at every impact velocity (``vibroimpact
    impact``), vectorised over ``velocity`` (m/s, any array-like).

    The law: ``law="exponential"`` (Fujita, seed eq. 1; ``a_over_b`` m/s,
    default 1.2, ``alpha`` 1/m, default 1.3e5, ``a`` N), ``"hertz"``
    (``stiffness``, ``exponent`` 1.5), ``"kelvin-voigt"`` (``stiffness``,
    ``damping``), ``"hunt-crossley"`` (``stiffness``, ``exponent``,
    ``chi``), ``"lankarani-nikravesh"`` (``stiffness``, ``exponent``,
    ``law_restitution``, ``min_impact_velocity``); ``form`` "published" or
    "non-negative". ``mass2`` may be ``"wall"``. ``method``:
    "closed-form" (the exponential law's closed form, seed eqs. 8-18; its
    default) or "integrate" (any law; the default for the others).

    Returns a :class:`Result` with ``method``, ``contact_law``, ``mass1``,
    ``mass2``, ``reduced_mass`` and one array per column: ``impact_velocity``,
    ``v``, ``restitution``, ``rebound_velocity``,
    ``peak_force_dimensionless``, ``peak_force``, ``peak_acceleration1``,
    ``peak_acceleration2``, ``max_penetration`` and, for "integrate",
    ``contact_duration`` (NaN where the CLI writes null).
    """
    spec = _law_spec(**{k: v for k, v in locals().items() if k in _LAW_KEYS})
    if method is None:
        method = "closed-form" if law == "exponential" else "integrate"
    _method(method, ("closed-form", "integrate"))
    return Result(
        _core.impact(
            _floats(velocity, "velocity"),
            spec,
            _real(mass1, "mass1", positive=True),
            _mass(mass2, "mass2"),
            method,
            _real(rtol, "rtol", positive=True),
            _real(duration_level, "duration_level", optional=True),
            _progress(progress),
        )
    )


def contact_force(
    s: ArrayLike,
    sdot: ArrayLike = 0.0,
    impact_velocity: ArrayLike = 1.0,
    *,
    law: str = "exponential",
    a_over_b: Optional[float] = None,
    alpha: Optional[float] = None,
    a: float = 1.0,
    stiffness: Optional[float] = None,
    exponent: Optional[float] = None,
    damping: Optional[float] = None,
    chi: Optional[float] = None,
    law_restitution: Optional[float] = None,
    min_impact_velocity: float = 1e-3,
    form: str = "published",
) -> Result:
    """A contact law's force F (N) and partial derivatives ``d_ds`` (N/m),
    ``d_dsdot`` (N s/m) at penetration ``s`` (m), rate ``sdot`` (m/s) and
    onset velocity ``impact_velocity`` (m/s, read by Lankarani-Nikravesh
    only); arrays broadcast against each other. Law keywords as in
    :func:`impact`."""
    spec = _law_spec(**{k: v for k, v in locals().items() if k in _LAW_KEYS})
    arrays = [np.asarray(x) for x in (s, sdot, impact_velocity)]
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError as e:
        raise ValueError(f"s, sdot, impact_velocity: shapes do not broadcast ({e})") from None
    shape = arrays[0].shape
    flat = [
        _floats(x.ravel(), name)
        for x, name in zip(arrays, ("s", "sdot", "impact_velocity"))
    ]
    d = _core.contact_force(spec, *flat)
    return Result({k: v.reshape(shape) for k, v in d.items()})


def _pairs(data: Any, name: str, second: str) -> tuple:
    if data is None:
        return np.empty(0), np.empty(0)
    if isinstance(data, (str, os.PathLike)):
        # A CSV file with the columns `impact_velocity` and `second`, as
        # `vibroimpact identify` reads it.
        path = os.fspath(data)
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError as e:
            raise OSError(f"{name}: {path}: cannot read: {e.strerror}") from None
        u, y = _core.parse_measured(text, path, ["impact_velocity", second])
        return u, y
    if isinstance(data, dict):
        missing = [k for k in ("impact_velocity", second) if k not in data]
        if missing or len(data) != 2:
            raise ValueError(
                f"{name}: a dict needs exactly the keys 'impact_velocity' and '{second}', got {sorted(data)}"
            )
        u = _floats(data["impact_velocity"], f"{name}['impact_velocity']")
        y = _floats(data[second], f"{name}['{second}']")
    elif isinstance(data, tuple) and len(data) == 2:
        u, y = data
        u, y = _floats(u, f"{name}[0] (impact_velocity)"), _floats(y, f"{name}[1] ({second})")
    else:
        arr = np.asarray(data, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2:
            raise ValueError(
                f"{name}: give (impact_velocity, {second}) arrays or an (n, 2) array, got shape {arr.shape}"
            )
        if arr.shape[0] == 2:
            # Rows of pairs or the two columns? The same numbers fit a/b
            # 1.020 one way and 0.552 the other (issue 38).
            raise ValueError(
                f"{name}: a 2 x 2 array is ambiguous (two (impact_velocity, {second}) rows, or the two "
                f"columns?): give a tuple (impact_velocities, {second}s) or a dict with the keys "
                f"'impact_velocity' and '{second}'"
            )
        u, y = _floats(arr[:, 0], f"{name}[:, 0]"), _floats(arr[:, 1], f"{name}[:, 1]")
    if u.shape != y.shape:
        raise ValueError(f"{name}: the two arrays differ in length ({u.size} and {y.size})")
    return u, y


def identify(
    *,
    restitution: Any = None,
    acceleration: Any = None,
    mass1: float = 0.227,
    mass2: Union[float, str] = 0.227,
    a_over_b: Optional[float] = None,
    joint: bool = False,
) -> Result:
    """Identify a/b and alpha of the exponential law from measured impacts
    (seed section 3; ``vibroimpact identify``).

    ``restitution``: (impact velocity, restitution) measurements and
    ``acceleration``: (impact velocity, peak acceleration of body 1 =
    F_max/m1) measurements, each as a tuple of two arrays (the columns), a
    dict with the keys ``impact_velocity`` and ``restitution`` (or
    ``peak_acceleration``), an (n, 2) array of rows (n > 2: a 2 x 2 array
    is refused as ambiguous) or a CSV file with the columns ``impact_velocity`` and ``restitution`` (or
    ``peak_acceleration``), as the CLI reads it; either may be omitted. ``a_over_b`` fixes a/b; ``joint`` fits both at
    once. Returns ``method``, ``a_over_b`` and ``alpha`` (each with
    ``value`` and ``std_error``), ``restitution_fit`` and
    ``acceleration_fit`` (with residuals).
    """
    if restitution is None and acceleration is None:
        raise ValueError("nothing to identify: give restitution and/or acceleration")
    ru, re = _pairs(restitution, "restitution", "restitution")
    au, aa = _pairs(acceleration, "acceleration", "peak_acceleration")
    return Result(
        _core.identify(
            ru,
            re,
            au,
            aa,
            _real(mass1, "mass1", positive=True),
            _mass(mass2, "mass2"),
            _real(a_over_b, "a_over_b", positive=True, optional=True),
            _flag(joint, "joint"),
        )
    )
