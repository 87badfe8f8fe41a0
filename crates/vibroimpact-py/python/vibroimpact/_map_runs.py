"""The runs of a sweep's values and a chart's rows on this machine (the
binding's thread pool): what :func:`vibroimpact.sweep` and
:func:`vibroimpact.chart` call, and what :mod:`vibroimpact.distributed`
runs as Dask tasks on its workers.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from . import _core
from ._checks import Progress, _progress
from ._core import Model
from ._results import Result, _keeping_on_ctrl_c


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
    with _keeping_on_ctrl_c(raw):
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
            options.get("settle"),
        )
    return d if raw else Result(d)


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
        options.get("settle"),
    )
    return d if raw else Result(d)
