"""Brute-force maps over parameters and initial states:
:func:`parameter_values` (the values of ``sweep --from --to --points``),
:func:`sweep` (the bifurcation diagram), :func:`chart` (the stability
chart) and :func:`basins` (basins of attraction). Their runs on this
machine are in :mod:`._map_runs`, which :mod:`vibroimpact.distributed`
also runs as Dask tasks.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import _core
from ._checks import (
    ArrayLike,
    ModelLike,
    Progress,
    _count,
    _flag,
    _floats,
    _method,
    _model,
    _progress,
    _with_impacts,
    _real,
)
from ._map_runs import _chart_local, _sweep_local
from ._results import Result


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


def _run_options(transient, settle, record, rtol, atol, method, cluster_tolerance, integrator) -> dict:
    """The checked settings every map's runs share (sweep, chart, basins)."""
    return dict(
        transient=_count(transient, "transient"),
        settle=None if settle is None else _count(settle, "settle", maximum=10**9),
        record=_count(record, "record", minimum=1, maximum=10**7),
        rtol=_real(rtol, "rtol", positive=True, optional=True),
        atol=_real(atol, "atol", positive=True, optional=True),
        method=_method(method, ("dop853", "dopri5", "rodas", "auto")),
        cluster_tolerance=_real(cluster_tolerance, "cluster_tolerance", positive=True, optional=True),
        integrator=_method(integrator, ("auto", "global", "local"), "integrator"),
    )


def sweep(
    model: ModelLike,
    parameter: str,
    values: Optional[ArrayLike] = None,
    *,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    points: Optional[int] = None,
    transient: int = 100,
    settle: Optional[int] = None,
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
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
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

    A value whose Poincaré samples still converge onto an orbit runs on
    for the periods the convergence needs, at most ``settle`` more (default
    9 × ``transient``): it is called periodic only once its samples repeat
    to ``cluster_tolerance`` (docs/theory.md §8).

    ``impacts``: "soft" or "rigid" for every contact (rigid: velocity
    jumps with the law's e(U), docs/theory.md §12), default the model
    file's; ``restitution``: a constant coefficient in (0, 1] for rigid
    impacts, as ``Model.with_impacts``.

    Returns ``parameter_name``, ``bodies``, ``from``, ``to``,
    ``transient_periods``, ``record_periods``, ``up_down``, ``rtol``,
    ``atol``, ``cluster_tolerance`` and ``points`` (each with
    ``parameter``, ``direction``, ``max_displacement``,
    ``distinct_section_points``, ``section_spread``, ``motion``
    ("periodic", "settling" or "irregular"), ``period``,
    ``settle_periods`` (a settling value: the periods it still needs),
    ``transient_periods`` (its own, settling included),
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
    m = _with_impacts(_model(model), impacts, restitution)
    if not isinstance(parameter, str):
        raise TypeError(f"parameter: expected a name, got {type(parameter).__name__}")
    v = _sweep_values(values, from_, to, points)
    options = dict(
        _run_options(transient, settle, record, rtol, atol, method, cluster_tolerance, integrator),
        up_down=_flag(up_down, "up_down"),
        lyapunov=None if lyapunov is None else _count(lyapunov, "lyapunov", minimum=1, maximum=10**6),
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


def chart(
    model: ModelLike,
    x: str,
    x_values: ArrayLike,
    y: str,
    y_values: ArrayLike,
    *,
    transient: int = 100,
    settle: Optional[int] = None,
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
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
) -> Result:
    """The brute-force stability chart (``vibroimpact chart``): every cell of
    the grid ``x_values`` × ``y_values`` of the parameters ``x`` and ``y``
    simulated from ``starts`` initial states for ``transient`` forcing
    periods, then ``record`` periods; each run classified by the period of
    its attractor on the Poincaré section (None: not periodic), its impacts
    per period, its largest |u| and, with ``lyapunov``, its largest Lyapunov
    exponent. Defaults as the CLI: ``rtol`` 1e-7 unless the model's
    ``[simulation]`` gives one, ``cluster_tolerance`` max(1e-5, 1000
    rtol), ``settle`` as :func:`sweep` (a run is periodic only once its
    samples repeat).
    ``integrator="local"``: the transients and recorded periods move
    bodies out of contact exactly.

    Without ``client`` the cells run on this machine's cores (``threads``:
    pool size). With a ``dask.distributed.Client`` the rows of the grid run
    on its workers in ``tasks`` chunks; the result is bit for bit the local
    one.

    ``impacts``: "soft" or "rigid" for every contact (rigid: velocity
    jumps with the law's e(U), docs/theory.md §12), default the model
    file's; ``restitution``: a constant coefficient in (0, 1] for rigid
    impacts, as ``Model.with_impacts``.

    Returns ``x_name``, ``y_name``, ``x_values``, ``y_values``,
    ``transient_periods``, ``record_periods``, ``rtol``,
    ``cluster_tolerance`` and ``cells`` (row by row: all x at the first y,
    …), each with ``x``, ``y``, ``attractors`` (distinct attractors of its
    runs) and ``runs`` (``start``, ``period``, ``impacts_per_period``,
    ``max_displacement``, ``lyapunov``, ``error``).
    """
    m = _with_impacts(_model(model), impacts, restitution)
    for name, value in (("x", x), ("y", y)):
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a parameter name, got {type(value).__name__}")
    xs = _floats(x_values, "x_values", allow_scalar=False)
    ys = _floats(y_values, "y_values", allow_scalar=False)
    for name, v in (("x_values", xs), ("y_values", ys)):
        if v.size < 1:
            raise ValueError(f"{name}: at least one value")
    options = dict(
        _run_options(transient, settle, record, rtol, atol, method, cluster_tolerance, integrator),
        starts=_count(starts, "starts", minimum=1, maximum=10**6),
        lyapunov=_flag(lyapunov, "lyapunov"),
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


def basins(
    model: ModelLike,
    x: str,
    x_values: ArrayLike,
    y: str,
    y_values: ArrayLike,
    *,
    base: Optional[ArrayLike] = None,
    transient: int = 100,
    settle: Optional[int] = None,
    record: int = 20,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    method: str = "dop853",
    cluster_tolerance: Optional[float] = None,
    integrator: str = "auto",
    client: Any = None,
    tasks: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Progress = None,
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
) -> Result:
    """Basins of attraction (``vibroimpact basins``): every initial state of
    the grid ``x_values`` × ``y_values`` of the state components ``x`` and
    ``y`` (``"u1"``, ``"v2"``, …; the other components from ``base``, u then
    v, default the model's initial state) run to its attractor in parallel
    (``transient`` periods, then ``record`` recorded ones). Defaults and
    ``integrator`` as :func:`chart`. Without ``client`` the states run on
    this machine's cores (``threads``: pool size). With a
    ``dask.distributed.Client`` the rows of the grid run on its workers in
    ``tasks`` chunks and the attractors are identified here over all of
    them; the result is bit for bit the local one.

    ``impacts``: "soft" or "rigid" for every contact (rigid: velocity
    jumps with the law's e(U), docs/theory.md §12), default the model
    file's; ``restitution``: a constant coefficient in (0, 1] for rigid
    impacts, as ``Model.with_impacts``.

    Returns ``x_component``, ``y_component``, ``x_values``, ``y_values``,
    ``base_state``, ``transient_periods``, ``record_periods``,
    ``attractors`` (each with ``period``, ``impacts_per_period``,
    ``max_displacement``, ``section`` — one cycle of Poincaré samples —
    ``cells`` and ``fraction``), ``cells`` (the attractor index of every
    start, row by row; None where the start overlaps a contact or failed),
    ``inadmissible``, ``failed`` and ``errors``.
    """
    m = _with_impacts(_model(model), impacts, restitution)
    for name, value in (("x", x), ("y", y)):
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a state component such as 'u1', got {type(value).__name__}")
    xs = np.require(_floats(x_values, "x_values", allow_scalar=False), np.float64, ["C", "A"])
    ys = np.require(_floats(y_values, "y_values", allow_scalar=False), np.float64, ["C", "A"])
    b = None if base is None else np.require(_floats(base, "base", allow_scalar=False), np.float64, ["C", "A"])
    options = _run_options(transient, settle, record, rtol, atol, method, cluster_tolerance, integrator)
    if threads is not None:
        threads = _count(threads, "threads", minimum=1, maximum=4096)
        if client is not None:
            raise ValueError("threads: applies to local basins; with a client every task runs on one thread")
    if tasks is not None:
        if client is None:
            raise ValueError("tasks: applies with a Dask client only")
        tasks = _count(tasks, "tasks", minimum=1, maximum=10**6)
    if client is not None:
        from .distributed import basins_on

        return basins_on(client, m, (x, xs), (y, ys), b, options, tasks=tasks, progress=progress)
    d = _core.basins(
        m,
        x,
        xs,
        y,
        ys,
        b,
        options["transient"],
        options["record"],
        options["rtol"],
        options["atol"],
        options["method"],
        options["cluster_tolerance"],
        threads,
        _progress(progress),
        options["integrator"],
        options["settle"],
    )
    return Result(d)
