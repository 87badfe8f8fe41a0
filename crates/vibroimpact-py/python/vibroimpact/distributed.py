"""Sweeps, charts, basins and ensembles on a Dask cluster.

``vibroimpact.sweep(..., client=client)`` splits the parameter values into
contiguous chunks, one Dask task each (a few per worker thread, so a task
lasts long enough to pay for its scheduling), ships the model (it pickles as
its TOML text, records inline), runs every chunk single-threaded on a worker
and gathers the points into the same result as the local run: every value is
computed by the same code from the same inputs, so the result is bit for bit
the local one whatever the number of workers. An up-down sweep is two chains
in which every value starts from the previous one's state: one task each.

:func:`ensemble` runs one computation (``simulate``, ``periodic``,
``sweep``, ...) over a list of models (e.g. one per accelerogram) and
returns one result per model, in order; a model that fails numerically gives
a result with its ``error`` instead of stopping the others. Worker failures
are retried by Dask (``retries``).
"""

from __future__ import annotations

from typing import Any, Callable, List, Optional, Sequence

import numpy as np

from ._results import Result


def _sweep_task(model, parameter, values, options, only=None):
    from ._map_runs import _sweep_local

    return _sweep_local(model, parameter, values, options, threads=1, raw=True, only=only)


def _worker_threads(client) -> int:
    info = client.scheduler_info()
    workers = info.get("workers", {})
    return max(1, sum(int(w.get("nthreads", 1)) for w in workers.values()))


def _chunks(values: np.ndarray, tasks: int) -> List[np.ndarray]:
    k = max(1, min(int(tasks), values.size))
    bounds = np.linspace(0, values.size, k + 1).round().astype(int)
    return [values[a:b] for a, b in zip(bounds[:-1], bounds[1:]) if b > a]


def _gather(futures, progress: Optional[Callable[[int, int], Any]], total: int):
    from dask.distributed import as_completed

    done = 0
    for f in as_completed(futures):
        if f.status == "error":
            f.result()  # raises the task's exception here
        done += 1
        if progress is not None:
            progress(done, total)
    return [f.result() for f in futures]


def sweep_on(
    client,
    model,
    parameter: str,
    values: np.ndarray,
    options: dict,
    *,
    tasks: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
    retries: int = 2,
) -> Result:
    """The sweep of :func:`vibroimpact.sweep` on the workers of ``client``
    (``tasks`` chunks; default four per worker thread)."""
    if not hasattr(client, "submit") or not hasattr(client, "scheduler_info"):
        raise TypeError(
            f"client: expected a dask.distributed.Client, got {type(client).__name__}"
        )
    if tasks is not None and (isinstance(tasks, bool) or int(tasks) < 1):
        raise ValueError(f"tasks = {tasks}: must be >= 1")
    if options["up_down"]:
        # Two chains of continued states: one task each.
        work = [(values, "up"), (values, "down")]
    else:
        work = [(c, None) for c in _chunks(values, tasks or 4 * _worker_threads(client))]
    [model_future] = client.scatter([model], broadcast=False, hash=False)
    futures = [
        client.submit(
            _sweep_task, model_future, parameter, c, options, only, retries=retries, pure=False
        )
        for c, only in work
    ]
    docs = _gather(futures, progress, len(futures))
    head = dict(docs[0])
    points = [p for d in docs for p in d["points"]]
    direction_order = {"none": 0, "up": 1, "down": 2}
    points.sort(key=lambda p: (p["parameter"], direction_order[p["direction"]]))
    head["points"] = points
    head["from"] = float(values[0])
    head["to"] = float(values[-1])
    return Result(head)


def _chart_task(model, x, y, options):
    from ._map_runs import _chart_local

    return _chart_local(model, x, y, options, threads=1, raw=True)


def chart_on(client, model, x, y, options: dict, *, tasks: Optional[int] = None, progress=None, retries: int = 2) -> Result:
    """The chart of :func:`vibroimpact.chart` on the workers of ``client``:
    the rows of the grid (values of ``y``) in ``tasks`` chunks (default four
    per worker thread), gathered in order."""
    if not hasattr(client, "submit") or not hasattr(client, "scheduler_info"):
        raise TypeError(
            f"client: expected a dask.distributed.Client, got {type(client).__name__}"
        )
    name, ys = y
    chunks = _chunks(ys, tasks or 4 * _worker_threads(client))
    [model_future] = client.scatter([model], broadcast=False, hash=False)
    futures = [
        client.submit(_chart_task, model_future, x, (name, c), options, retries=retries, pure=False)
        for c in chunks
    ]
    docs = _gather(futures, progress, len(futures))
    head = dict(docs[0])
    head["y_values"] = [v for d in docs for v in d["y_values"]]
    head["cells"] = [c for d in docs for c in d["cells"]]
    return Result(head)


def _basin_task(model, x, y, base, options):
    from . import _core

    # Arrays unpickled on a Dask worker are often misaligned: copy those.
    def aligned(a):
        return None if a is None else np.require(a, np.float64, ["C", "A"])

    return _core.basin_runs(model, x[0], aligned(x[1]), y[0], aligned(y[1]), aligned(base), options)


def basins_on(client, model, x, y, base, options: dict, *, tasks: Optional[int] = None, progress=None, retries: int = 2) -> Result:
    """The basins of :func:`vibroimpact.basins` on the workers of
    ``client``: the rows of the grid (values of ``y``) in ``tasks`` chunks
    (default four per worker thread), each task's runs sent back whole and
    the attractors identified here over all of them, so the result is bit
    for bit the local one."""
    from . import _core

    if not hasattr(client, "submit") or not hasattr(client, "scheduler_info"):
        raise TypeError(
            f"client: expected a dask.distributed.Client, got {type(client).__name__}"
        )
    name, ys = y
    chunks = _chunks(ys, tasks or 4 * _worker_threads(client))
    [model_future] = client.scatter([model], broadcast=False, hash=False)
    futures = [
        client.submit(_basin_task, model_future, x, (name, c), base, options, retries=retries, pure=False)
        for c in chunks
    ]
    parts = _gather(futures, progress, len(futures))
    d = _core.basins_merge(model, x[0], x[1], name, ys, base, options, parts)
    return Result(d)


def _ensemble_task(name: str, model, kwargs: dict):
    import vibroimpact

    try:
        return getattr(vibroimpact, name)(model, **kwargs).to_dict()
    except vibroimpact.VibroimpactError as e:
        partial = getattr(e, "result", None)
        out = partial.to_dict() if partial is not None else {}
        out["error"] = str(e)
        return out


def ensemble(
    models: Sequence[Any],
    function: str = "simulate",
    *,
    client=None,
    retries: int = 2,
    progress: Optional[Callable[[int, int], Any]] = None,
    **kwargs,
) -> List[Result]:
    """Runs ``vibroimpact.<function>(model, **kwargs)`` for every model (one
    Dask task each with ``client``, else one after the other here) and
    returns the results in order. A numerical failure gives that model's
    result with ``error`` set (and what was computed); bad arguments raise
    at once."""
    from ._checks import _model

    names = ("simulate", "periodic", "continue_", "sweep")
    if function not in names:
        raise ValueError(f"function = {function!r}: give one of {', '.join(names)}")
    if isinstance(models, (str, bytes)) or not hasattr(models, "__iter__"):
        raise TypeError("models: expected a list of models (or paths or dicts)")
    models = [_model(m) for m in models]
    if not models:
        return []
    if client is None:
        out = []
        for k, m in enumerate(models):
            out.append(Result(_ensemble_task(function, m, kwargs)))
            if progress is not None:
                progress(k + 1, len(models))
        return out
    futures = [
        client.submit(_ensemble_task, function, m, kwargs, retries=retries, pure=False)
        for m in models
    ]
    return [Result(d) for d in _gather(futures, progress, len(futures))]


def _pounding_task(text: str, source: str, record, scales, run: tuple):
    """One record at every scale (one Dask task per record: its scheduling
    cost paid once, not once per scale): per scale the row and the
    record's run (``vibroimpact pounding``'s ``row`` and ``runs[0]``)."""
    from . import _core
    from ._checks import _floats

    name, header, units, times, acc = record
    # Arrays unpickled on a worker need not be aligned: copied as the
    # binding reads them.
    t = _floats(times, "times", allow_scalar=False)
    a = _floats(acc, "acceleration", allow_scalar=False)
    sample, rtol, method, integrator = run
    out = []
    for scale in scales:
        doc = _core.pounding(
            text, source, [(name, header, units, t, a)], float(scale), sample, rtol, method,
            integrator, True,
        )
        out.append({"row": dict(doc["row"]), **dict(doc["runs"][0])})
    return out


def ida(
    pair,
    records: Sequence[Any],
    scales: Sequence[float],
    *,
    client=None,
    damping: float = 0.05,
    sample: float = 0.0025,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
    retries: int = 2,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> Result:
    """Incremental dynamic analysis of a pounding pair (docs/earthquakes.md):
    every record × every scale factor, one Dask task per record (its
    scales inside) with ``client`` (else here, one after the other; the
    same numbers either way); ``progress(done, total)`` counts records. The
    intensity is the scaled record's pseudo-spectral acceleration Sa(T1) at
    the first (left) building's fundamental period and ``damping``. ``sample``,
    ``rtol``, ``method`` and ``integrator`` as :func:`vibroimpact.pounding`
    takes them.

    Returns arrays over the runs, record-major: ``record`` (index),
    ``scale``, ``sa`` (m/s²), ``peak_impact_force`` (N), ``impacts``,
    ``max_drift`` (the largest storey drift of every building with
    pounding, m), ``drift_amplification`` (largest ratio to the free
    buildings'), ``required_gap`` (the largest over the joints, m); and
    ``period`` (T1, s) and ``sources``."""
    import os

    from ._earthquakes import (
        _pair_text,
        _pounding_settings,
        _record_inputs,
        read_record,
        response_spectrum,
    )

    source, text = _pair_text(pair)
    _pounding_settings(1.0, sample, rtol, method, integrator)
    run = (float(sample), float(rtol), method, integrator)
    recs = [read_record(r) if isinstance(r, (str, os.PathLike)) else r for r in records]
    scales = np.asarray(scales, dtype=np.float64)
    if scales.ndim != 1 or scales.size == 0 or not np.all(np.isfinite(scales)):
        raise ValueError("scales: expected a non-empty list of finite factors")
    jobs = [(i, float(s)) for i in range(len(recs)) for s in scales]
    arrays = _record_inputs(recs, None)
    if client is None:
        per_record = []
        for k, a in enumerate(arrays):
            per_record.append(_pounding_task(text, source, a, scales, run))
            if progress is not None:
                progress(k + 1, len(arrays))
    else:
        # One task per record (its scales inside): the record goes to the
        # cluster once, and a task's scheduling is paid once per record.
        shipped = client.scatter(arrays, hash=False)
        futures = [
            client.submit(_pounding_task, text, source, r, scales, run, retries=retries, pure=False)
            for r in shipped
        ]
        per_record = _gather(futures, progress, len(futures))
    results = [res for runs in per_record for res in runs]
    period = float(results[0]["row"]["buildings"][0]["period"])
    sa_unit = [
        float(response_spectrum(r, [period], damping=damping)["pseudo_acceleration"][0])
        for r in recs
    ]

    def drifts(res, key):
        return [d for name in sorted(res[key]["peak_drift"]) for d in res[key]["peak_drift"][name]]

    max_drift = [max(drifts(r, "pounding")) for r in results]
    amplification = [
        max(p / f if f > 0 else 1.0 for p, f in zip(drifts(r, "pounding"), drifts(r, "free")))
        for r in results
    ]
    return Result(
        {
            "period": period,
            "sources": [r.get("source", f"record {k}") for k, r in enumerate(recs)],
            "record": np.array([i for i, _ in jobs]),
            "scale": np.array([s for _, s in jobs]),
            "sa": np.array([sa_unit[i] * s for i, s in jobs]),
            "peak_impact_force": np.array([r["pounding"]["peak_impact_force"] for r in results]),
            "impacts": np.array([r["pounding"]["impacts"] for r in results]),
            "max_drift": np.array(max_drift),
            "drift_amplification": np.array(amplification),
            "required_gap": np.array(
                [max((j["required_gap"] for j in r["joints"]), default=0.0) for r in results]
            ),
        }
    )


def _normal_cdf(x):
    import math

    return 0.5 * (1.0 + np.vectorize(math.erf)(np.asarray(x) / math.sqrt(2.0)))


def fragility(intensity: Any, exceeded: Any) -> Result:
    """A lognormal fragility curve P(exceed | IM = x) = Φ(ln(x/θ)/β) fitted by
    maximum likelihood (Baker 2015) to runs at intensities ``intensity``
    with outcomes ``exceeded`` (booleans, or fractions of records at one
    level). Returns ``theta`` (the median capacity, in the intensity's
    units), ``beta`` (the dispersion) and ``log_likelihood``. A grid over
    (ln θ, β) refined five times around its best point: deterministic."""
    x = np.asarray(intensity, dtype=np.float64)
    y = np.asarray(exceeded, dtype=np.float64)
    if x.shape != y.shape or x.ndim != 1 or x.size < 2:
        raise ValueError("intensity, exceeded: give two 1-D arrays of one length (at least 2)")
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise ValueError("intensity: positive finite values")
    if np.any((y < 0) | (y > 1)):
        raise ValueError("exceeded: booleans or fractions in [0, 1]")
    if not 0.0 < float(y.sum()) < y.size:
        what = "no run exceeded" if y.sum() == 0 else "every run exceeded"
        raise ValueError(
            f"exceeded: {what}; the fragility's median and dispersion are not determined "
            "(extend the intensities)"
        )
    partial = (y > 0) & (y < 1)
    if not partial.any() and x[y == 0].max() < x[y == 1].min():
        raise ValueError(
            "exceeded: every exceedance lies above every non-exceedance; the likelihood "
            "grows without bound as beta -> 0, so the dispersion is not determined"
        )
    lx = np.log(x)

    def loglik(lt, b):
        p = np.clip(_normal_cdf((lx - lt) / b), 1e-300, 1 - 1e-16)
        return float(np.sum(y * np.log(p) + (1 - y) * np.log1p(-p)))

    lo, hi = float(lx.min()) - 1.0, float(lx.max()) + 1.0
    blo, bhi = 0.01, 3.0
    best = (loglik(lo, 1.0), lo, 1.0)
    for _ in range(6):
        for lt in np.linspace(lo, hi, 41):
            for b in np.linspace(blo, bhi, 41):
                v = loglik(lt, b)
                if v > best[0]:
                    best = (v, float(lt), float(b))
        dl, db = (hi - lo) / 10, (bhi - blo) / 10
        lo, hi = best[1] - dl, best[1] + dl
        blo, bhi = max(1e-4, best[2] - db), best[2] + db
    return Result({"theta": float(np.exp(best[1])), "beta": best[2], "log_likelihood": best[0]})
