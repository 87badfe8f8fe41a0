#!/usr/bin/env python3
"""The Python package's benchmark, in one run (ratios):

1. overhead: ``vi.simulate`` of R2 N = 3 (examples/fujita-row.toml), 5
   periods, rtol 1e-8, against the same simulation timed inside Rust
   (``bench/src/bin/time_simulate.rs``); target within 10 %;
2. ``vi.impact`` closed form on 10^6 velocities; target <= 200 ns each;
3. against what a Python user writes today: SciPy ``solve_ivp`` DOP853 with
   a vectorised NumPy right-hand side (``bench/peers/r2_scipy.py``) on the
   same R2 N = 3 history, both at their fastest setting that reaches a final
   state error <= 1e-6 (relative to max |u|) against a tight reference
   (ours at rtol 1e-13); settings scanned, the scan recorded; target >= 50x;
4. Dask: a 64-frequency R2 N = 10 sweep (5.9 to 8.9 rad/s, 100 transient and
   20 recorded periods) on a LocalCluster of 1 and of 2 worker processes (one
   thread each) against the local rayon run on 2 threads; targets: 2 workers
   >= 1.7x one worker, and within 20 % of the local run; results bit for bit
   equal.

Run it in the checkout's virtual environment (``bash scripts/test.sh`` makes
it): ``.venv/bin/python bench/python/bench.py [--quick] [--out FILE]``.
SciPy is installed into that environment if missing (the peers' pinned
version). The machine should be otherwise idle.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench" / "peers"))

import vibroimpact as vi  # noqa: E402

ROW = ROOT / "examples" / "fujita-row.toml"


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)


def overhead(repeats, lines):
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "vibroimpact-bench", "--bin", "time_simulate"],
        cwd=ROOT, check=True,
    )
    exe = ROOT / "target" / "release" / "time_simulate"
    rust = json.loads(subprocess.run(
        [str(exe), str(ROW), "5", "1e-8", str(repeats)], capture_output=True, text=True, check=True
    ).stdout)
    m = vi.Model.load(ROW)
    vi.simulate(m, periods=5, rtol=1e-8, output_step=0)  # warm up
    py_med, py_best = median_time(lambda: vi.simulate(m, periods=5, rtol=1e-8, output_step=0), repeats)
    hist_med, _ = median_time(lambda: vi.simulate(m, periods=5, rtol=1e-8), repeats)
    same = vi.simulate(m, periods=5, rtol=1e-8, output_step=0).final_displacement.tolist() == rust["final_displacement"]
    ratio = py_med / rust["median_s"]
    lines.append("== Python overhead: R2 N = 3, 5 periods, rtol 1e-8 (medians of %d) ==" % repeats)
    lines.append(f"Rust simulate            {1e3 * rust['median_s']:8.3f} ms (best {1e3 * rust['best_s']:.3f})")
    lines.append(f"vi.simulate (no history) {1e3 * py_med:8.3f} ms (best {1e3 * py_best:.3f})  python/rust = {ratio:.3f}  (target <= 1.10)")
    lines.append(f"vi.simulate (history, 100 samples/period) {1e3 * hist_med:8.3f} ms")
    lines.append(f"same final state bit for bit: {same}")
    return {"rust_ms": 1e3 * rust["median_s"], "python_ms": 1e3 * py_med, "ratio": ratio, "same": same}


def impact_speed(n, repeats, lines):
    v = np.logspace(-4, 1, n)
    vi.impact(v[:1000])
    med, best = median_time(lambda: vi.impact(v), repeats)
    ns = 1e9 * med / n
    lines.append(f"== vi.impact closed form, {n} velocities (medians of {repeats}) ==")
    lines.append(f"{1e3 * med:.1f} ms, {ns:.1f} ns per velocity (best {1e9 * best / n:.1f})  (target <= 200)")
    return {"ns_per_velocity": ns}


def ensure_scipy():
    try:
        import scipy  # noqa: F401
    except ImportError:
        req = (ROOT / "bench" / "peers" / "requirements.txt").read_text().split()
        pins = [r for r in req if r.startswith("scipy")]
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", *pins], check=True)


def scipy_comparison(repeats, lines):
    ensure_scipy()
    import scipy
    from scipy.integrate import solve_ivp
    from r2_scipy import make_rhs, OMEGA0

    n, ratio_w, periods = 3, 0.95, 5.0
    omega = ratio_w * OMEGA0
    t_end = periods * 2 * math.pi / omega
    m = vi.Model.load(ROW)
    assert abs(m.forcing_frequency - omega) < 1e-12
    ref = vi.simulate(m, periods=periods, rtol=1e-13, atol=1e-17, output_step=0)
    ref_u = np.asarray(ref.final_displacement)
    scale = np.max(np.abs(vi.simulate(m, periods=periods, rtol=1e-10).displacement))

    def error(u):
        return float(np.max(np.abs(np.asarray(u) - ref_u)) / scale)

    scan = []
    for rtol in (1e-7, 1e-8, 1e-9, 1e-10, 1e-11):
        for aratio in (1e-2, 1e-3, 1e-4):
            atol = rtol * aratio

            def run():
                rhs = make_rhs(n, omega, 1e-3, [0])
                return solve_ivp(rhs, (0.0, t_end), np.zeros(2 * n), method="DOP853", rtol=rtol, atol=atol)

            sol = run()
            t, _ = median_time(run, max(1, repeats // 10))
            scan.append(("scipy-dop853", rtol, atol, error(sol.y[:n, -1]) if sol.status == 0 else math.inf, t))

            def ours():
                return vi.simulate(m, periods=periods, rtol=rtol, atol=atol, output_step=0)

            r = ours()
            t, _ = median_time(ours, repeats)
            scan.append(("vi.simulate", rtol, atol, error(r.final_displacement), t))
    lines.append(f"== R2 N = 3, 5 periods: vi.simulate against SciPy {scipy.__version__} solve_ivp DOP853 ==")
    lines.append("tool            rtol     atol      error       ms")
    for name, rtol, atol, err, t in scan:
        lines.append(f"{name:14s} {rtol:7.0e} {atol:8.0e} {err:10.2e} {1e3 * t:9.3f}")
    best = {}
    for name, rtol, atol, err, t in scan:
        if err <= 1e-6 and (name not in best or t < best[name][4]):
            best[name] = (name, rtol, atol, err, t)
    ratio = best["scipy-dop853"][4] / best["vi.simulate"][4]
    for b in best.values():
        lines.append(f"fastest with error <= 1e-6: {b[0]} rtol {b[1]:.0e} atol {b[2]:.0e} error {b[3]:.2e} {1e3 * b[4]:.3f} ms")
    lines.append(f"scipy / vi.simulate = {ratio:.0f}  (target >= 50)")
    return {"ratio": ratio, "best": {k: list(v) for k, v in best.items()}}


def dask_comparison(points, lines):
    from dask.distributed import Client, LocalCluster

    m = vi.Model.load(ROW).with_({"row.count": 10})
    kw = dict(from_=5.9, to=8.9, points=points, transient=100, record=20)
    t0 = time.perf_counter()
    local = vi.sweep(m, "frequency", threads=2, **kw)
    t_local = time.perf_counter() - t0
    out = {"local_s": t_local}
    lines.append(f"== Dask: R2 N = 10 sweep, {points} frequencies, 100 + 20 periods each ==")
    lines.append(f"local (rayon, 2 threads)       {t_local:7.2f} s")
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.wait_for_workers(workers)
            t0 = time.perf_counter()
            r = vi.sweep(m, "frequency", client=client, **kw)
            t = time.perf_counter() - t0
        same = json.dumps(r.to_dict(), sort_keys=True) == json.dumps(local.to_dict(), sort_keys=True)
        out[f"workers{workers}_s"] = t
        lines.append(f"LocalCluster, {workers} worker process(es) {t:7.2f} s  bit for bit the local result: {same}")
        out[f"same{workers}"] = same
    s = out["workers1_s"] / out["workers2_s"]
    o = out["workers2_s"] / t_local
    lines.append(f"2 workers / 1 worker speed-up {s:.2f} (target >= 1.7); 2 workers / local {o:.2f} (target <= 1.20)")
    out.update(speedup=s, overhead=o)
    return out


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--quick", action="store_true", help="fewer repeats, 16 sweep frequencies")
    p.add_argument("--out", help="also write the report (text) and FILE.json")
    p.add_argument("--only", choices=("overhead", "impact", "scipy", "dask"), action="append",
                   help="run only these parts (repeatable; default: all)")
    a = p.parse_args()
    repeats = 5 if a.quick else 31
    lines = [
        f"# vibroimpact Python benchmark, {time.strftime('%Y-%m-%d %H:%M')}",
        f"# python {platform.python_version()}, numpy {np.__version__}, vibroimpact {vi.__version__}, "
        f"{os.cpu_count()} cores; command: .venv/bin/python bench/python/bench.py{' --quick' if a.quick else ''}",
    ]
    parts = {
        "overhead": lambda: overhead(repeats, lines),
        "impact": lambda: impact_speed(10**6, max(3, repeats // 5), lines),
        "scipy": lambda: scipy_comparison(repeats, lines),
        "dask": lambda: dask_comparison(16 if a.quick else 64, lines),
    }
    results = {name: run() for name, run in parts.items() if not a.only or name in a.only}
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if a.out:
        Path(a.out).write_text(text)
        Path(a.out).with_suffix(".json").write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
