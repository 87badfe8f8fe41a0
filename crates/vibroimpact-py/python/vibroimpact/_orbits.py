"""Periodic orbits: :func:`periodic` (``vibroimpact periodic``, one orbit by
shooting with its Floquet multipliers) and :func:`continue_` (``vibroimpact
continue``, a branch by pseudo-arclength continuation with its special
points, and their curves in a second parameter), raising
:class:`VibroimpactError` with the partial result on ``.result`` when Newton
or the branch stops.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any, Optional, Sequence

from . import _core
from ._checks import ModelLike, Progress, _count, _flag, _floats, _method, _model, _progress, _real, _with_impacts
from ._core import VibroimpactError
from ._results import Result, _keeping_on_ctrl_c


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
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
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
    products replay); the simulated guess is the same for every
    integrator (simulated by the one "auto" picks).

    ``impacts``: "soft" or "rigid" for every contact (rigid: velocity
    jumps with the law's e(U), docs/theory.md §12), default the model
    file's; ``restitution``: a constant coefficient in (0, 1] for rigid
    impacts, as ``Model.with_impacts``.

    Returns ``converged``, ``method``, ``period``, ``subharmonic``,
    ``initial_state``, ``residual_history``, ``floquet_multipliers`` ([re,
    im] rows), ``spectral_radius``, ``stable``, ``symmetric_orbit``,
    ``max_displacement``, ``max_velocity``, ``impacts_per_period``,
    ``impacts``, and the orbit over one period (``orbit_t``,
    ``orbit_displacement``, ``orbit_velocity``). Raises VibroimpactError if
    Newton does not converge (the result is on the exception as
    ``.result``).
    """
    m = _with_impacts(_model(model), impacts, restitution)
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
        try:
            with open(special_points, encoding="utf-8") as f:
                earlier = f.read()
        except OSError as e:
            raise OSError(f"special_points: {os.fspath(special_points)}: cannot read: {e.strerror}") from None
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
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
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
    forcing: "frequency", "amplitude"); the start guess is simulated by the
    integrator "auto" picks either way. ``start``: "auto" (a guess by
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

    ``impacts``: "soft" or "rigid" for every contact (rigid: velocity
    jumps with the law's e(U), docs/theory.md §12), default the model
    file's; ``restitution``: a constant coefficient in (0, 1] for rigid
    impacts, as ``Model.with_impacts``.

    Returns ``parameter_name``, ``subharmonic``, ``symmetric``, ``stop`` (ReachedEnd,
    MaxPoints, Interrupted, CannotContinue, Grazing: a branch through rigid
    impacts reached a grazing, its last point the special point GR,
    ClosedLoop or TurnedBack: a fold brought it out of the range on its
    start's side) with ``stop_detail``,
    ``contacts``, ``points`` (each with ``parameter``, ``max_displacement``,
    ``max_velocity``, ``impacts_per_period``, ``stable``,
    ``spectral_radius``, ``floquet_multipliers``, ``initial_state``,
    ``label``) and ``special_points``; ``result.column("parameter")`` gives
    one field over the points. Raises VibroimpactError if the branch cannot
    continue, and KeyboardInterrupt on Ctrl-C: the points so far are on
    the exception as ``.result`` (on Ctrl-C with ``stop`` "Interrupted").
    """
    m = _with_impacts(_model(model), impacts, restitution)
    if not isinstance(parameter, str):
        raise TypeError(f"parameter: expected a name, got {type(parameter).__name__}")
    if switch_at is not None and not isinstance(switch_at, str):
        raise TypeError("switch_at: expected a label such as 'BP1'")
    with _keeping_on_ctrl_c():
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
