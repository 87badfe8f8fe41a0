"""vibroimpact: vibrating systems whose bodies collide, after T. Fujita (1977).

The library's computations from Python, named after the command line
(subcommand -> function, ``--option-name`` -> ``option_name=``, same
defaults). Results are :class:`Result` objects whose fields carry the names
of the CLI's JSON output, with numpy arrays for numeric lists.

>>> import vibroimpact as vi
>>> r = vi.impact([0.01, 0.1, 1.0])              # the seed's law and balls
>>> r.restitution                                 # doctest: +SKIP
>>> m = vi.Model.load("examples/fujita-row.toml")
>>> h = vi.simulate(m, periods=5)                 # h.t, h.displacement, h.impacts
>>> s = vi.sweep(m, parameter="frequency", from_=5.9, to=8.9, points=41)

Long calls release the GIL, stop on Ctrl-C (KeyboardInterrupt) and report
progress to ``progress(done, total)`` if given. Bad input raises
``ValueError`` naming the argument or model key; a numerical failure raises
:class:`VibroimpactError`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from . import _core
from ._core import Model, VibroimpactError
from ._results import Result

__all__ = [
    "Model",
    "Result",
    "VibroimpactError",
    "basins",
    "chart",
    "contact_force",
    "continue_",
    "identify",
    "impact",
    "parameter_values",
    "periodic",
    "pounding",
    "pounding_history",
    "read_record",
    "response_spectrum",
    "simulate",
    "sweep",
]

try:  # pragma: no cover - metadata exists once installed
    from importlib.metadata import version as _version

    __version__ = _version("vibroimpact")
except Exception:  # pragma: no cover
    __version__ = "0+unknown"

Progress = Optional[Callable[[int, int], Any]]
ArrayLike = Union[Sequence[float], np.ndarray, float]
ModelLike = Union[Model, str, "os.PathLike[str]"]


def _floats(x: Any, name: str, *, allow_scalar: bool = True) -> np.ndarray:
    """A contiguous, aligned float64 1-D array from any array-like; NaN and
    infinities are rejected with the argument's name."""
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
    a = np.require(a, np.float64, ["C", "A"])
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise ValueError(f"{name}[{bad[0]}] = {a[bad[0]]}: must be finite")
    return a


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


def _method(name: str, choices: Sequence[str], arg: str = "method") -> str:
    if name not in choices:
        raise ValueError(f"{arg} = {name!r}: give one of {', '.join(map(repr, choices))}")
    return name


def _progress(progress: Progress) -> Progress:
    if progress is not None and not callable(progress):
        raise TypeError("progress: expected a callable progress(done, total)")
    return progress


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
    if isinstance(data, tuple) and len(data) == 2:
        u, y = data
        u, y = _floats(u, f"{name}[0] (impact_velocity)"), _floats(y, f"{name}[1] ({second})")
    else:
        arr = np.asarray(data, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2:
            raise ValueError(
                f"{name}: give (impact_velocity, {second}) arrays or an (n, 2) array, got shape {arr.shape}"
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
    F_max/m1) measurements, each as a pair of arrays, an (n, 2) array or a
    CSV file with the columns ``impact_velocity`` and ``restitution`` (or
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


def simulate(
    model: ModelLike,
    *,
    periods: Optional[float] = None,
    duration: Optional[float] = None,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    method: str = "dop853",
    output_step: Optional[float] = None,
    energy: bool = False,
    impact_force_threshold: Optional[float] = None,
    integrator: str = "auto",
    progress: Progress = None,
) -> Result:
    """A time history with its impact log (``vibroimpact simulate``).

    Give ``duration`` (s) or ``periods`` (forcing periods). ``rtol``,
    ``atol``, ``impact_force_threshold``: default the model's
    ``[simulation]`` settings, else 1e-8, rtol*1e-4, 1e-3 N. ``method``:
    "dop853", "dopri5", "rodas" or "auto". ``output_step`` (s): sampling of the
    history, default 1/100 forcing period (or duration/2000); 0: none.
    ``integrator``: "auto" (local from 16 groups of bodies up, global
    below), "global" (every body integrated at every step) or "local"
    (exact motion between contacts, only bodies in touch integrated; the
    summary then has ``local`` with its work counters).

    Returns the CLI's summary fields (``completed``, ``error``,
    ``final_time``, ``final_displacement``, ``final_velocity``,
    ``impact_count``, ``impacts_per_contact``, ``rhs_evaluations``,
    ``steps``, ``rejected_steps``, ``contact_evaluations``,
    ``contact_laws``, ``energy``) and the arrays ``t``, ``displacement``
    and ``velocity`` (one row per time, one column per body) and
    ``impacts`` (``contact``, ``start_time``, ``end_time``,
    ``impact_velocity``, ``rebound_velocity``, ``restitution``,
    ``peak_force``, ``duration``). An integration failure keeps what was
    computed: ``completed`` is False and ``error`` says where. The
    counters (``rhs_evaluations``, ``steps``) include the dense-output
    evaluations of the history, as the CLI's with ``--out``; with
    ``output_step=0`` they equal the CLI's without ``--out``.
    ``progress(done, 1000)`` reports the time reached in thousandths.
    """
    m = _model(model)
    if (periods is None) == (duration is None):
        raise ValueError("give exactly one of periods= and duration=")
    if periods is not None:
        w = m.forcing_frequency
        if w is None:
            raise ValueError("periods= needs a periodic excitation with one frequency; use duration=")
        t_end = _real(periods, "periods", positive=True) * 2.0 * math.pi / w
    else:
        t_end = _real(duration, "duration", positive=True)
    if output_step is not None:
        output_step = _real(output_step, "output_step")
        if output_step < 0:
            raise ValueError(f"output_step = {output_step}: must be >= 0")
    return Result(
        _core.simulate(
            m,
            t_end,
            _real(rtol, "rtol", positive=True, optional=True),
            _real(atol, "atol", positive=True, optional=True),
            _method(method, ("dop853", "dopri5", "rodas", "auto")),
            output_step,
            _flag(energy, "energy"),
            _real(impact_force_threshold, "impact_force_threshold", positive=True, optional=True),
            _method(integrator, ("auto", "global", "local"), "integrator"),
            _progress(progress),
        )
    )


def periodic(
    model: ModelLike,
    *,
    subharmonic: int = 1,
    guess: Any = "simulate",
    guess_periods: float = 200.0,
    rtol: float = 1e-10,
    tol: float = 1e-9,
    krylov: bool = False,
    dense: bool = False,
    arnoldi: int = 20,
    symmetric: bool = False,
    progress: Progress = None,
    integrator: str = "auto",
) -> Result:
    """A periodic solution by shooting, with its Floquet multipliers
    (``vibroimpact periodic``).

    ``guess``: "simulate" (the state after ``guess_periods`` forcing periods
    from the model's initial state), "homotopy" (continued in the forcing
    amplitude from the rest state: the primary orbit), a state array
    ``[u..., v...]``, an earlier result with ``initial_state`` or a JSON file
    holding one (``summary.json`` of ``periodic --out``).
    ``krylov=True``: matrix-free Newton-Krylov with Arnoldi multipliers
    (the default from 200 bodies on); ``dense=True``: the dense monodromy
    at any size.
    ``symmetric``: shoot on the half map of a mirror-symmetric row.
    ``integrator="local"``: the period map by the exact motion between
    contacts (its monodromy matrix, or with ``krylov`` the record that its
    products replay).

    Returns ``converged``, ``method``, ``period``, ``subharmonic``,
    ``initial_state``, ``residual_history``, ``floquet_multipliers`` ([re,
    im] rows), ``spectral_radius``, ``stable``, ``symmetric_orbit``,
    ``max_displacement``, ``max_velocity``, ``impacts_per_period``,
    ``impacts``, and the orbit over one period (``orbit_t``,
    ``orbit_displacement``, ``orbit_velocity``). Raises VibroimpactError if
    Newton does not converge (the result is on the exception as
    ``.result``).
    """
    m = _model(model)
    if isinstance(guess, os.PathLike) or (
        isinstance(guess, str) and guess not in ("simulate", "homotopy")
    ):
        # A JSON file with `initial_state` (an earlier output), as the CLI.
        path = os.fspath(guess)
        try:
            with open(path, encoding="utf-8") as f:
                earlier = json.load(f)
        except OSError as e:
            raise OSError(
                f"guess = {path!r}: 'simulate', 'homotopy', a state array, an earlier "
                f"result or a JSON file with initial_state; cannot read it: {e.strerror}"
            ) from None
        except ValueError as e:
            raise ValueError(f"guess: {path}: not JSON: {e}") from None
        if not isinstance(earlier, dict) or "initial_state" not in earlier:
            raise ValueError(f"guess: {path}: no `initial_state` array")
        g = _floats(earlier["initial_state"], "guess['initial_state']")
    elif isinstance(guess, str):
        g = None
    elif isinstance(guess, (Result, dict)):
        g = _floats(guess["initial_state"], "guess['initial_state']")
    else:
        g = _floats(guess, "guess")
    r = Result(
        _core.periodic(
            m,
            _count(subharmonic, "subharmonic", minimum=1, maximum=10**6),
            g,
            _real(guess_periods, "guess_periods", positive=True),
            _real(rtol, "rtol", positive=True),
            _real(tol, "tol", positive=True),
            _flag(krylov, "krylov"),
            _count(arnoldi, "arnoldi", minimum=1, maximum=10**5),
            _flag(symmetric, "symmetric"),
            _progress(progress),
            _method(integrator, ("auto", "global", "local"), "integrator"),
            _flag(dense, "dense"),
            isinstance(guess, str) and guess == "homotopy",
        )
    )
    if not r.converged:
        e = VibroimpactError(
            f"Newton did not converge ({r.newton_stop}; residual history "
            + str([f"{x:.2e}" for x in r.residual_history])
            + ")"
        )
        e.result = r
        raise e
    return r


def _second_parameter(
    parameter2: Any, from2: Any, to2: Any, curves: Any, curve_step: Any, special_points: Any
) -> tuple:
    """The curves' settings of :func:`continue_`, checked (an earlier
    branch as the JSON text of its document)."""
    if special_points is None:
        earlier = None
    elif isinstance(special_points, (str, os.PathLike)):
        with open(special_points, encoding="utf-8") as f:
            earlier = f.read()
    elif isinstance(special_points, Mapping):
        earlier = json.dumps(
            special_points.to_dict() if isinstance(special_points, Result) else special_points
        )
    else:
        raise TypeError("special_points: expected a continue_ result or a branch.json file")
    if parameter2 is not None and not isinstance(parameter2, str):
        raise TypeError(f"parameter2: expected a name, got {type(parameter2).__name__}")
    if isinstance(curves, str) or not all(isinstance(c, str) for c in curves):
        raise TypeError("curves: expected a list of names such as ['fold', 'pd']")
    return (
        parameter2,
        _real(from2, "from2", optional=True),
        _real(to2, "to2", optional=True),
        list(curves),
        _real(curve_step, "curve_step", positive=True),
        earlier,
    )


def continue_(
    model: ModelLike,
    parameter: str,
    from_: float,
    to: float,
    *,
    subharmonic: int = 1,
    switch_at: Optional[str] = None,
    max_points: int = 1500,
    ds_max: float = 0.05,
    guess_periods: float = 200.0,
    progress: Progress = None,
    integrator: str = "auto",
    start: str = "auto",
    krylov: bool = False,
    dense: bool = False,
    arnoldi: int = 20,
    parameter2: Optional[str] = None,
    from2: Optional[float] = None,
    to2: Optional[float] = None,
    curves: Sequence[str] = ("fold", "bp", "pd", "ns", "grazing"),
    curve_step: float = 0.05,
    special_points: Any = None,
) -> Result:
    """A branch of periodic solutions by pseudo-arclength continuation in
    ``parameter`` from ``from_`` to ``to`` (``vibroimpact continue``), with
    folds, branch points, period doublings, torus and grazing points
    located. ``parameter``: "frequency", "amplitude" or a dotted key
    ("row.clearance", "body.2.mass"). ``switch_at``: a special point's
    label (e.g. "BP1", "PD1") whose crossing or period-doubled branch is
    continued too (``switched_branch``). ``progress(points, max_points)``.
    ``integrator="local"``: the period maps by the exact motion between
    contacts, integrating only the bodies in touch (a parameter of the
    forcing: "frequency", "amplitude"). ``start``: "auto" (a guess by
    simulation over ``guess_periods``, then the homotopy in the forcing
    amplitude if Newton does not converge from it), "simulate" or
    "homotopy" (the primary branch from rest). ``krylov=True``:
    matrix-free (Newton–Krylov, ``arnoldi`` dominant multipliers), the
    default from 200 bodies; ``dense=True``: the dense monodromy at any
    size. ``parameter2``: a second parameter; every fold, branch point,
    period doubling, Neimark–Sacker point and grazing of the branch (or
    those named in ``curves``: "fold", "bp", "pd", "ns", "grazing") is
    continued as a curve in both parameters within ``from2``–``to2``
    (default 0 to twice its value), steps up to ``curve_step``, with the
    codimension-two points on it: ``curves`` and ``curves_skipped`` in the
    result, as ``continue --parameter2``. ``special_points``: an earlier
    result of ``continue_`` (or its ``branch.json``) whose special points
    start the curves instead of a new branch; the result is then the
    curves' document (``parameter``, ``parameter2``, ``curves``,
    ``skipped``).

    Returns ``parameter_name``, ``subharmonic``, ``symmetric``, ``stop`` (ReachedEnd,
    MaxPoints, Interrupted, CannotContinue or ClosedLoop) with ``stop_detail``,
    ``contacts``, ``points`` (each with ``parameter``, ``max_displacement``,
    ``max_velocity``, ``impacts_per_period``, ``stable``,
    ``spectral_radius``, ``floquet_multipliers``, ``initial_state``,
    ``label``) and ``special_points``; ``result.column("parameter")`` gives
    one field over the points. Raises VibroimpactError if the branch cannot
    continue (the points so far are on the exception as ``.result``).
    """
    m = _model(model)
    if not isinstance(parameter, str):
        raise TypeError(f"parameter: expected a name, got {type(parameter).__name__}")
    if switch_at is not None and not isinstance(switch_at, str):
        raise TypeError("switch_at: expected a label such as 'BP1'")
    d = _core.continue_branch(
        m,
        parameter,
        _real(from_, "from_"),
        _real(to, "to"),
        _count(subharmonic, "subharmonic", minimum=1, maximum=10**6),
        switch_at,
        _count(max_points, "max_points", minimum=2, maximum=10**8),
        _real(ds_max, "ds_max", positive=True),
        _real(guess_periods, "guess_periods", positive=True),
        _progress(progress),
        _method(integrator, ("auto", "global", "local"), "integrator"),
        _method(start, ("auto", "simulate", "homotopy"), "start"),
        _flag(krylov, "krylov"),
        _flag(dense, "dense"),
        _count(arnoldi, "arnoldi", minimum=2, maximum=10**6),
        _second_parameter(parameter2, from2, to2, curves, curve_step, special_points),
    )
    r = Result(d)
    if special_points is not None:
        return r
    problem = None
    if r.stop == "CannotContinue":
        problem = (
            f"the branch cannot continue: {r.stop_detail} (the points computed so far are kept)"
        )
    elif "switch_error" in r:
        problem = r.switch_error
    if problem:
        e = VibroimpactError(problem)
        e.result = r
        raise e
    return r


def parameter_values(from_: float, to: float, points: int) -> np.ndarray:
    """``points`` values evenly spaced from ``from_`` to ``to``, both ends
    exact: the values of ``vibroimpact sweep --from --to --points``, bit for
    bit."""
    from_, to = _real(from_, "from_"), _real(to, "to")
    k = _count(points, "points", minimum=2, maximum=10**7)
    if from_ == to:
        raise ValueError(f"from_ and to are both {from_}: give a range")
    return _core.parameter_values(from_, to, k)


def _sweep_values(values, from_, to, points) -> np.ndarray:
    if values is not None:
        if from_ is not None or to is not None or points is not None:
            raise ValueError("give values= or from_=, to=, points=, not both")
        v = _floats(values, "values")
        if v.size < 2:
            raise ValueError(f"values: a sweep needs at least 2 values, got {v.size}")
        steps = np.diff(v)
        if not (np.all(steps > 0) or np.all(steps < 0)):
            raise ValueError(
                "values: give them in increasing or decreasing order (the points come back "
                "sorted by the parameter, and an up-down sweep follows the order)"
            )
        return v
    if from_ is None or to is None or points is None:
        raise ValueError("give values= or all of from_=, to=, points=")
    return parameter_values(from_, to, points)


def sweep(
    model: ModelLike,
    parameter: str,
    values: Optional[ArrayLike] = None,
    *,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    points: Optional[int] = None,
    transient: int = 100,
    record: int = 20,
    up_down: bool = False,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    method: str = "dop853",
    cluster_tolerance: Optional[float] = None,
    lyapunov: Optional[int] = None,
    integrator: str = "auto",
    client: Any = None,
    tasks: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Progress = None,
) -> Result:
    """The brute-force bifurcation diagram (``vibroimpact sweep``): every
    value of ``parameter`` simulated for ``transient`` forcing periods, then
    ``record`` periods whose Poincaré samples are kept.

    Values: ``values`` (any array-like) or ``from_``, ``to``, ``points``.
    ``up_down``: sweep up and down, each value continuing from the previous
    one's state. Without ``client`` the values run on this machine's cores
    (``threads``: pool size, default all). With a
    ``dask.distributed.Client`` they run on its workers in ``tasks``
    chunks (see :mod:`vibroimpact.distributed`); the result is bit for bit
    the local one.

    Returns ``parameter_name``, ``bodies``, ``from``, ``to``,
    ``transient_periods``, ``record_periods``, ``up_down``, ``rtol``,
    ``atol``, ``cluster_tolerance`` and ``points`` (each with
    ``parameter``, ``direction``, ``max_displacement``,
    ``distinct_section_points``, ``section_spread``,
    ``impacts_per_period``, ``recorded_periods``, ``completed``, ``error``
    and ``sections``, the Poincaré samples as a record x 2N array). A value
    that fails numerically is kept with its ``error``.

    ``integrator="local"``: the transients, recorded periods and Lyapunov
    exponents move bodies out of contact exactly (docs/theory.md §10).

    ``lyapunov = k``: every point also gains ``lyapunov``, its k largest
    Lyapunov exponents (1/s, largest first, averaged over the recorded
    periods; a positive first one marks chaos) and
    ``lyapunov_uncertainty``, their standard errors (batch means).
    """
    m = _model(model)
    if not isinstance(parameter, str):
        raise TypeError(f"parameter: expected a name, got {type(parameter).__name__}")
    v = _sweep_values(values, from_, to, points)
    options = dict(
        transient=_count(transient, "transient"),
        record=_count(record, "record", minimum=1, maximum=10**7),
        up_down=_flag(up_down, "up_down"),
        rtol=_real(rtol, "rtol", positive=True, optional=True),
        atol=_real(atol, "atol", positive=True, optional=True),
        method=_method(method, ("dop853", "dopri5", "rodas", "auto")),
        cluster_tolerance=_real(cluster_tolerance, "cluster_tolerance", positive=True, optional=True),
        lyapunov=None if lyapunov is None else _count(lyapunov, "lyapunov", minimum=1, maximum=10**6),
        integrator=_method(integrator, ("auto", "global", "local"), "integrator"),
    )
    if threads is not None:
        threads = _count(threads, "threads", minimum=1, maximum=4096)
        if client is not None:
            raise ValueError("threads: applies to a local sweep; with a client every task runs on one thread")
    if tasks is not None:
        if client is None:
            raise ValueError("tasks: applies with a Dask client only")
        tasks = _count(tasks, "tasks", minimum=1, maximum=10**6)
    if client is not None:
        from .distributed import sweep_on

        return sweep_on(client, m, parameter, v, options, tasks=tasks, progress=progress)
    return _sweep_local(m, parameter, v, options, threads=threads, progress=progress)


def _sweep_local(
    model: Model,
    parameter: str,
    values: np.ndarray,
    options: dict,
    *,
    threads: Optional[int] = None,
    progress: Progress = None,
    raw: bool = False,
    only: Optional[str] = None,
):
    """One sweep on this machine (also one Dask task's work); ``raw``: the
    plain document, for gathering."""
    # Arrays unpickled on a Dask worker are often misaligned: copy those.
    values = np.require(values, np.float64, ["C", "A"])
    d = _core.sweep(
        model,
        parameter,
        values,
        options["transient"],
        options["record"],
        options["up_down"],
        options["rtol"],
        options["atol"],
        options["method"],
        options["cluster_tolerance"],
        threads,
        only,
        _progress(progress),
        options["lyapunov"],
        options.get("integrator", "auto"),
    )
    return d if raw else Result(d)


def chart(
    model: ModelLike,
    x: str,
    x_values: ArrayLike,
    y: str,
    y_values: ArrayLike,
    *,
    transient: int = 100,
    record: int = 20,
    starts: int = 1,
    lyapunov: bool = False,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    method: str = "dop853",
    cluster_tolerance: Optional[float] = None,
    integrator: str = "auto",
    client: Any = None,
    tasks: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Progress = None,
) -> Result:
    """The brute-force stability chart (``vibroimpact chart``): every cell of
    the grid ``x_values`` × ``y_values`` of the parameters ``x`` and ``y``
    simulated from ``starts`` initial states for ``transient`` forcing
    periods, then ``record`` periods; each run classified by the period of
    its attractor on the Poincaré section (None: not periodic), its impacts
    per period, its largest |u| and, with ``lyapunov``, its largest Lyapunov
    exponent. Defaults as the CLI: ``rtol`` 1e-7 unless the model's
    ``[simulation]`` gives one, ``cluster_tolerance`` 1e-3.
    ``integrator="local"``: the transients and recorded periods move
    bodies out of contact exactly.

    Without ``client`` the cells run on this machine's cores (``threads``:
    pool size). With a ``dask.distributed.Client`` the rows of the grid run
    on its workers in ``tasks`` chunks; the result is bit for bit the local
    one.

    Returns ``x_name``, ``y_name``, ``x_values``, ``y_values``,
    ``transient_periods``, ``record_periods``, ``rtol``,
    ``cluster_tolerance`` and ``cells`` (row by row: all x at the first y,
    …), each with ``x``, ``y``, ``attractors`` (distinct attractors of its
    runs) and ``runs`` (``start``, ``period``, ``impacts_per_period``,
    ``max_displacement``, ``lyapunov``, ``error``).
    """
    m = _model(model)
    for name, value in (("x", x), ("y", y)):
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a parameter name, got {type(value).__name__}")
    xs = _floats(x_values, "x_values", allow_scalar=False)
    ys = _floats(y_values, "y_values", allow_scalar=False)
    for name, v in (("x_values", xs), ("y_values", ys)):
        if v.size < 1:
            raise ValueError(f"{name}: at least one value")
    options = dict(
        transient=_count(transient, "transient"),
        record=_count(record, "record", minimum=1, maximum=10**7),
        starts=_count(starts, "starts", minimum=1, maximum=10**6),
        lyapunov=_flag(lyapunov, "lyapunov"),
        rtol=_real(rtol, "rtol", positive=True, optional=True),
        atol=_real(atol, "atol", positive=True, optional=True),
        method=_method(method, ("dop853", "dopri5", "rodas", "auto")),
        cluster_tolerance=_real(cluster_tolerance, "cluster_tolerance", positive=True, optional=True),
        integrator=_method(integrator, ("auto", "global", "local"), "integrator"),
    )
    if threads is not None:
        threads = _count(threads, "threads", minimum=1, maximum=4096)
        if client is not None:
            raise ValueError("threads: applies to a local chart; with a client every task runs on one thread")
    if tasks is not None:
        if client is None:
            raise ValueError("tasks: applies with a Dask client only")
        tasks = _count(tasks, "tasks", minimum=1, maximum=10**6)
    if client is not None:
        from .distributed import chart_on

        return chart_on(client, m, (x, xs), (y, ys), options, tasks=tasks, progress=progress)
    return _chart_local(m, (x, xs), (y, ys), options, threads=threads, progress=progress)


def _chart_local(model: Model, x, y, options: dict, *, threads=None, progress: Progress = None, raw: bool = False):
    """One chart on this machine (also one Dask task's rows); ``raw``: the
    plain document, for gathering."""
    xs = np.require(x[1], np.float64, ["C", "A"])
    ys = np.require(y[1], np.float64, ["C", "A"])
    d = _core.chart(
        model,
        x[0],
        xs,
        y[0],
        ys,
        options["transient"],
        options["record"],
        options["starts"],
        options["lyapunov"],
        options["rtol"],
        options["atol"],
        options["method"],
        options["cluster_tolerance"],
        threads,
        _progress(progress),
        options.get("integrator", "auto"),
    )
    return d if raw else Result(d)


def basins(
    model: ModelLike,
    x: str,
    x_values: ArrayLike,
    y: str,
    y_values: ArrayLike,
    *,
    base: Optional[ArrayLike] = None,
    transient: int = 100,
    record: int = 20,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    method: str = "dop853",
    cluster_tolerance: Optional[float] = None,
    integrator: str = "auto",
    threads: Optional[int] = None,
    progress: Progress = None,
) -> Result:
    """Basins of attraction (``vibroimpact basins``): every initial state of
    the grid ``x_values`` × ``y_values`` of the state components ``x`` and
    ``y`` (``"u1"``, ``"v2"``, …; the other components from ``base``, u then
    v, default the model's initial state) run to its attractor in parallel
    (``transient`` periods, then ``record`` recorded ones). Defaults and
    ``integrator`` as :func:`chart`.

    Returns ``x_component``, ``y_component``, ``x_values``, ``y_values``,
    ``base_state``, ``transient_periods``, ``record_periods``,
    ``attractors`` (each with ``period``, ``impacts_per_period``,
    ``max_displacement``, ``section`` — one cycle of Poincaré samples —
    ``cells`` and ``fraction``), ``cells`` (the attractor index of every
    start, row by row; None where the start overlaps a contact or failed),
    ``inadmissible``, ``failed`` and ``errors``.
    """
    m = _model(model)
    for name, value in (("x", x), ("y", y)):
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a state component such as 'u1', got {type(value).__name__}")
    xs = np.require(_floats(x_values, "x_values", allow_scalar=False), np.float64, ["C", "A"])
    ys = np.require(_floats(y_values, "y_values", allow_scalar=False), np.float64, ["C", "A"])
    b = None if base is None else np.require(_floats(base, "base", allow_scalar=False), np.float64, ["C", "A"])
    if threads is not None:
        threads = _count(threads, "threads", minimum=1, maximum=4096)
    d = _core.basins(
        m,
        x,
        xs,
        y,
        ys,
        b,
        _count(transient, "transient"),
        _count(record, "record", minimum=1, maximum=10**7),
        _real(rtol, "rtol", positive=True, optional=True),
        _real(atol, "atol", positive=True, optional=True),
        _method(method, ("dop853", "dopri5", "rodas", "auto")),
        _real(cluster_tolerance, "cluster_tolerance", positive=True, optional=True),
        threads,
        _progress(progress),
        _method(integrator, ("auto", "global", "local"), "integrator"),
    )
    return Result(d)


def read_record(path: Union[str, "os.PathLike[str]"], *, units: Optional[str] = None) -> Result:
    """A ground-motion record: a PEER NGA ``.AT2`` file, two columns (time s,
    acceleration; header lines skipped) or CSV. ``units`` (``"g"``,
    ``"m/s2"``, ``"gal"``) is needed when the header does not state them.

    Returns ``source``, ``header`` (the header lines), ``units`` (of the
    file), ``dt`` (None if not uniform), ``times`` (s), ``acceleration``
    (m/s², converted), ``pga`` (m/s²)."""
    path = os.fspath(path)
    if not isinstance(path, str):
        raise TypeError("path: expected a file name")
    if units is not None and not isinstance(units, str):
        raise TypeError("units: expected 'g', 'm/s2' or 'gal'")
    try:
        size = os.stat(path).st_size
    except OSError as e:
        raise OSError(f"{path}: cannot read: {e.strerror}") from None
    if size > 1 << 30:
        raise ValueError(f"path: {path} has {size} bytes, more than the input limit of 1 GiB")
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    return Result(_core.parse_record(text, path, units))


def response_spectrum(
    record: Any,
    periods: Optional[ArrayLike] = None,
    *,
    damping: float = 0.05,
    scale: float = 1.0,
    acceleration: Optional[ArrayLike] = None,
    units: Optional[str] = None,
) -> Result:
    """Elastic response spectra of a record, exact for its piecewise-linear
    ground acceleration (Nigam–Jennings; ``vibroimpact spectrum``).
    ``record``: a result of :func:`read_record`, a file name (read with
    ``units`` when its header does not state them), or the sample times (s)
    with ``acceleration`` (m/s²). ``periods`` (s): default 100
    log-spaced from 0.05 to 5. Peaks over the record's time steps.

    Returns ``period``, ``pseudo_acceleration`` (m/s²), ``pseudo_velocity``
    (m/s), ``displacement`` (m)."""
    if isinstance(record, (str, os.PathLike)):
        record = read_record(record, units=units)
    if acceleration is None:
        try:
            times, acc = record["times"], record["acceleration"]
        except (KeyError, TypeError, IndexError):
            raise TypeError(
                "record: expected a read_record result, a file name, or times with acceleration="
            ) from None
    else:
        times, acc = record, acceleration
    if periods is None:
        periods = np.geomspace(0.05, 5.0, 100)
    for name, v in (("damping", damping), ("scale", scale)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    return Result(
        _core.response_spectrum(
            _floats(times, "times", allow_scalar=False),
            _floats(acc, "acceleration", allow_scalar=False),
            _floats(periods, "periods"),
            float(damping),
            float(scale),
        )
    )


def _pair_text(pair: Any):
    """(source, TOML text) of a pounding pair given as a file name or text
    (text holds a line break or an `=`; anything else is a file name)."""
    if isinstance(pair, str) and ("\n" in pair or "=" in pair):
        return "<pair>", pair
    if isinstance(pair, (str, os.PathLike)):
        source = os.fspath(pair)
        try:
            with open(source, encoding="utf-8") as f:
                return source, f.read()
        except OSError as e:
            raise OSError(f"pair: {source}: cannot read: {e.strerror}") from None
    raise TypeError("pair: expected a pair file name or its TOML text")


def _record_arrays(record: Any):
    if isinstance(record, (str, os.PathLike)):
        record = read_record(record)
    try:
        return record["times"], record["acceleration"]
    except (KeyError, TypeError, IndexError):
        raise TypeError("record: expected a read_record result or a file name") from None


def _record_inputs(records: Any, units: Optional[str]) -> list:
    """The binding's records: (source, header, units, times, acceleration)
    of one record or a list of them (file names or :func:`read_record`
    results)."""
    one = isinstance(records, (str, os.PathLike, Mapping))
    out = []
    for k, r in enumerate([records] if one else list(records)):
        if isinstance(r, (str, os.PathLike)):
            r = read_record(r, units=units)
        try:
            times, acc = r["times"], r["acceleration"]
        except (KeyError, TypeError, IndexError):
            raise TypeError(
                f"records[{k}]: expected a read_record result or a file name"
            ) from None
        out.append(
            (
                str(r.get("source", f"record {k}")),
                [str(h) for h in r.get("header", [])],
                str(r.get("units", "m/s2")),
                _floats(times, "times", allow_scalar=False),
                _floats(acc, "acceleration", allow_scalar=False),
            )
        )
    if not out:
        raise ValueError("records: give at least one record")
    return out


def _value_range(values: Any, name: str) -> Optional[np.ndarray]:
    """`FROM:TO:N` (the CLI's form) or a list of values."""
    if values is None:
        return None
    if isinstance(values, str):
        return _core.value_range(name, values)
    return _floats(values, name, allow_scalar=False)


def _pounding_settings(scale: Any, sample: Any, rtol: Any, method: Any, integrator: Any) -> None:
    """Checks the settings of a pounding run (the binding checks their
    ranges)."""
    for name, v in (("scale", scale), ("sample", sample), ("rtol", rtol)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    _method(method, ("dop853", "dopri5", "rodas", "auto"))
    _method(integrator, ("auto", "global", "local"), "integrator")


def _pounding_args(
    pair: Any, record: Any, scale: Any, sample: Any, rtol: Any, method: Any, integrator: Any
) -> tuple:
    """The binding's leading arguments of a pounding run, checked."""
    source, text = _pair_text(pair)
    _pounding_settings(scale, sample, rtol, method, integrator)
    times, acc = _record_arrays(record)
    return (
        text,
        source,
        _floats(times, "times", allow_scalar=False),
        _floats(acc, "acceleration", allow_scalar=False),
        float(scale),
        float(sample),
        float(rtol),
        method,
        integrator,
    )


def pounding(
    pair: Union[str, "os.PathLike[str]"],
    records: Any,
    *,
    units: Optional[str] = None,
    scale: float = 1.0,
    sample: float = 0.0025,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
    free: bool = True,
    gaps: Any = None,
    ratios: Any = None,
) -> Result:
    """Pounding of two shear frames under recorded ground motions
    (``vibroimpact pounding``): ``pair`` is a pair file (TOML,
    docs/earthquakes.md) or its text; ``records`` one record or a list, each
    a :func:`read_record` result or a file name (read with ``units`` when
    its header does not state them), scaled by ``scale``. ``sample`` (s):
    the sampling of drifts and floor accelerations. ``method``: "dop853",
    or "dopri5", the faster at ``rtol`` 1e-3 to 1e-5 (the record's samples
    limit the step; peaks within 1 % there, docs/earthquakes.md).
    ``integrator="local"``: each frame moves exactly between poundings, per
    record sample. ``free=False`` runs the pair with its contacts only
    (half the work; no ``free``, ``amplification``, ``required_gap`` or
    ``code_gaps``). ``gaps`` and ``ratios`` (``"FROM:TO:N"`` or lists of
    values): the pounding spectrum over gaps (m) × period ratios
    T_left/T_right instead of the runs.

    Returns the CLI's document: ``pair`` (``left_period``,
    ``right_period``, ``gap``, ``floors``) and ``runs``, one per record,
    each with ``record``, ``pounding`` and ``free`` (``peak_drift``,
    ``peak_floor_acceleration``, ``peak_displacement`` per floor of the
    ``left`` and ``right`` frames, ``peak_impact_force``, ``impacts``,
    ``closing``), ``amplification``, ``required_gap`` and ``code_gaps``
    (``absolute_sum``, ``srss``, ``double_difference``, ``correlation``);
    with ``gaps`` and ``ratios``, ``pair``, ``records`` and ``cells`` (per
    gap and ratio the median, 16 and 84 % quantiles over the records)."""
    source, text = _pair_text(pair)
    _pounding_settings(scale, sample, rtol, method, integrator)
    if not isinstance(free, bool):
        raise TypeError(f"free: expected True or False, got {free!r}")
    if (gaps is None) != (ratios is None):
        raise ValueError("gaps, ratios: give both (the pounding spectrum) or neither")
    return Result(
        _core.pounding(
            text,
            source,
            _record_inputs(records, units),
            float(scale),
            float(sample),
            float(rtol),
            method,
            integrator,
            free,
            _value_range(gaps, "gaps"),
            _value_range(ratios, "ratios"),
        )
    )


def pounding_history(
    pair: Union[str, "os.PathLike[str]"],
    record: Any,
    *,
    scale: float = 1.0,
    sample: float = 0.01,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
) -> Result:
    """The time history of a pounding pair with its contacts under one
    record (as :func:`pounding` takes them), sampled every ``sample``
    seconds: ``t`` (s), ``left`` and ``right`` (floor displacements relative
    to the ground, floors × samples, m) and the impact log
    ``impact_time`` (s), ``impact_floor`` (1-based), ``impact_peak_force``
    (N)."""
    d = _core.pounding_history(*_pounding_args(pair, record, scale, sample, rtol, method, integrator))
    d["left"] = np.asarray(d["left"])
    d["right"] = np.asarray(d["right"])
    d["impact_floor"] = np.asarray(d["impact_floor"], dtype=np.int64)
    return Result(d)
