"""Time histories: :func:`simulate` (``vibroimpact simulate``), a model's
motion over a duration or a number of forcing periods with its impact log.
"""

from __future__ import annotations

import math
from typing import Optional

from . import _core
from ._checks import ModelLike, Progress, _flag, _method, _model, _progress, _real
from ._results import Result, _keeping_on_ctrl_c


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
    impacts: Optional[str] = None,
    restitution: Optional[float] = None,
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
    summary then has ``local`` with its work counters). ``impacts``:
    every contact's, "soft" (the law integrated) or "rigid" (velocity
    jumps with the law's e(U), docs/theory.md §12; the global
    integrator); default the model file's. ``restitution``: a constant
    coefficient in (0, 1] for rigid impacts in place of the law's.

    Returns the CLI's summary fields (``completed``, ``error``,
    ``final_time``, ``final_displacement``, ``final_velocity``,
    ``impact_count``, ``impacts_per_contact``, ``rhs_evaluations``,
    ``steps``, ``rejected_steps``, ``contact_evaluations``,
    ``contact_laws``, ``energy``) and the arrays ``t``, ``displacement``
    and ``velocity`` (one row per time, one column per body) and
    ``impacts`` (``contact``, ``start_time``, ``end_time``,
    ``impact_velocity``, ``rebound_velocity``, ``restitution``,
    ``peak_force``, ``duration``, ``impacts`` ("soft" or "rigid"),
    ``impulse`` and ``energy_lost``; a rigid impact's peak force and
    duration are its soft law's estimates). An integration failure keeps what was
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
    with _keeping_on_ctrl_c():
        d = _core.simulate(
            m,
            t_end,
            _real(rtol, "rtol", positive=True, optional=True),
            _real(atol, "atol", positive=True, optional=True),
            _method(method, ("dop853", "dopri5", "rodas", "auto")),
            output_step,
            _flag(energy, "energy"),
            _real(impact_force_threshold, "impact_force_threshold", positive=True, optional=True),
            _method(integrator, ("auto", "global", "local"), "integrator"),
            None if impacts is None else _method(impacts, ("soft", "rigid"), "impacts"),
            _real(restitution, "restitution", optional=True),
            _progress(progress),
        )
    return Result(d)
