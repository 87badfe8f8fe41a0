#!/usr/bin/env python3
"""Work-precision and scaling study for the R2 peers.

  build/venv/bin/python bench/peers/study.py [BUILD_DIR] [--quick]

Writes bench/peers/results-<YYYY-MM-DD>.json with every raw peer output
(final states included) and prints a text summary. Uses only the two peers
(r2_sundials, r2_scipy.py); run build.sh first.

Study (all: atol = rtol * 1e-3 unless stated):
 A. reference, N = 3, Omega = 0.95 omega0, 5 periods: CVODE Adams at rtol 1e-13
    (atol 1e-16); checked against ARKStep Verner 6(5) and SciPy DOP853 at the
    same tolerances and against itself with atol perturbed by one ulp.
 B. work-precision, same problem, rtol 1e-4 .. 1e-12 for every method; error =
    max_i |y_i - y_ref_i| / max_i |y_ref_i| over the final state.
 C. atol ratio sensitivity (rtol * 1e-2, 1e-3, 1e-4) for the best methods.
 D. N = 1000, 1 period, rtol 1e-8: every ARKODE explicit method, CVODE Adams
    (and CVODE BDF, SciPy DOP853 for information), with errors vs an ARKStep
    Verner rtol 1e-13 run (itself checked against CVODE Adams rtol 1e-13).
 E. N = 10, 100, 1000, 10000, 1 period, rtol 1e-8: every ARKODE explicit
    method and CVODE Adams; seconds per period.
"""
import datetime
import json
import math
import os
import platform
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
args = [a for a in sys.argv[1:] if not a.startswith("--")]
QUICK = "--quick" in sys.argv
BUILD = os.path.abspath(args[0]) if args else os.path.join(HERE, "build")
CBIN = os.path.join(BUILD, "r2_sundials")
PY = sys.executable
PYPEER = os.path.join(HERE, "r2_scipy.py")

C_METHODS = ["cvode-adams", "cvode-bdf", "arkode-dp5", "arkode-verner8",
             "arkode-fehlberg8", "arkode-erk-default"]
ARK_EXPLICIT = ["arkode-dp5", "arkode-verner8", "arkode-fehlberg8", "arkode-erk-default"]
PY_METHODS = ["dop853", "lsoda", "radau"]
RTOLS = [10.0 ** -e for e in range(4, 13)]


def peer_cmd(method):
    if method in PY_METHODS or method.startswith("scipy-"):
        return [PY, PYPEER, method]
    return [CBIN, method]


def run(method, n, ratio, periods, rtol, atol, repeats, env=None):
    cmd = peer_cmd(method) + [str(n), repr(ratio), repr(periods), repr(rtol), repr(atol),
                              str(repeats)]
    e = dict(os.environ)
    e.update(env or {})
    p = subprocess.run(cmd, capture_output=True, text=True, env=e)
    line = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else "{}"
    d = json.loads(line)
    d["command"] = " ".join(cmd)
    if p.returncode != 0 and "error" not in d:
        d["error"] = p.stderr.strip()[-500:]
    if method in PY_METHODS:
        d["method"] = "scipy-" + method
    return d


def relerr(y, ref):
    mx = max(abs(x) for x in ref)
    return max(abs(a - b) for a, b in zip(y, ref)) / mx


def repeats_for(method, n):
    # best-of-REPEATS; the machine is shared (2 cores), so use many repeats
    # where runs are short
    if method == "radau":
        return 1
    if method in PY_METHODS:
        return 2 if n >= 1000 else 5
    if n <= 100:
        return 20
    return 5 if n <= 1000 else 3


def show(d, tag):
    e = d.get("error_vs_ref")
    es = f"{e:.2e}" if isinstance(e, float) else f"FAILED({d.get('error')},{d.get('flag')})"
    print(f"{tag} {d.get('method', '?'):20s} N {d.get('n', '?')} rtol {d.get('rtol', float('nan')):.0e} "
          f"err {es} s {d.get('seconds', float('nan')):.5f} nfe {d.get('rhs_evaluations')} "
          f"steps {d.get('steps')}", flush=True)


def summary_row(v):
    return {"rtol": v["rtol"], "atol": v["atol"], "error_vs_ref": v["error_vs_ref"],
            "seconds": v["seconds"], "rhs_evaluations": v["rhs_evaluations"], "steps": v["steps"]}


def best_table(rows, tol=1e-6):
    """fastest: the fastest run with error <= tol; robust: the loosest rtol with
    error <= tol at that rtol AND at every tighter rtol of the sweep (errors are
    not monotone in rtol on this problem)."""
    fastest, robust = {}, {}
    by_method = {}
    for d in rows:
        if "error_vs_ref" in d:
            by_method.setdefault(d["method"], []).append(d)
    for m, rs in by_method.items():
        ok = [d for d in rs if d["error_vs_ref"] <= tol]
        if ok:
            fastest[m] = summary_row(min(ok, key=lambda d: d["seconds"]))
        std = sorted([d for d in rs if d["atol"] == d["rtol"] * 1e-3 or d.get("extra_row")],
                     key=lambda d: d["rtol"])  # tight -> loose
        cand = None
        for d in std:
            if d["error_vs_ref"] <= tol:
                cand = d
            else:
                break
        if cand is not None:
            robust[m] = summary_row(cand)
    return {"fastest": fastest, "robust": robust}


def main():
    date = datetime.date.today().isoformat()
    res = {
        "date": date,
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                    "python": platform.python_version(),
                    "loadavg_at_start": open("/proc/loadavg").read().split()[:3],
                    "note": "shared machine: other sessions' load is invisible to ps; "
                            "seconds are best-of-repeats"},
        "problem": "R2 (docs/theory.md §6): m 0.227, omega0 7.41, zeta 0.013, A 0.05, g 1e-3, "
                   "a 1, b 1/1.2, alpha 1.3e5, published (unclamped) law, start at rest",
        "error_measure": "max_i |y_i - y_ref_i| / max_i |y_ref_i| over the final (u, v)",
        "atol_rule": "atol = rtol * 1e-3 unless stated",
    }
    N, RATIO, P = 3, 0.95, 5

    # ---- A. reference ----
    ref = run("cvode-adams", N, RATIO, P, 1e-13, 1e-16, 1)
    ref_checks = {
        "arkode-verner8": run("arkode-verner8", N, RATIO, P, 1e-13, 1e-16, 1),
        "scipy-dop853": run("dop853", N, RATIO, P, 1e-13, 1e-16, 1),
        "cvode-adams atol+1ulp": run("cvode-adams", N, RATIO, P, 1e-13, 1.0000000000000001e-16, 1),
        "arkode-dp5": run("arkode-dp5", N, RATIO, P, 1e-13, 1e-16, 1),
    }
    yref = ref["final_state"]
    res["reference"] = {"run": ref, "checks": {
        k: {"error_vs_reference": relerr(v["final_state"], yref), "run": v}
        for k, v in ref_checks.items()}}
    print("A. reference cvode-adams rtol 1e-13 atol 1e-16; agreement:")
    for k, v in res["reference"]["checks"].items():
        print(f"   {k:24s} {v['error_vs_reference']:.2e}")

    # ---- B. work-precision ----
    wp = []
    methods = C_METHODS + PY_METHODS
    for m in methods:
        for rtol in (RTOLS[::2] if QUICK else RTOLS):
            if m == "radau" and rtol < 1e-10:
                continue  # very slow, information only
            d = run(m, N, RATIO, P, rtol, rtol * 1e-3, repeats_for(m, N))
            if "final_state" in d:
                d["error_vs_ref"] = relerr(d["final_state"], yref)
            wp.append(d)
            show(d, "B.")
    # information only: rtol 1e-13 for methods that never reach 1e-6 above
    for m in methods:
        rows = [d for d in wp if d.get("method") in (m, "scipy-" + m)]
        if m != "radau" and not any(d.get("error_vs_ref", 1) <= 1e-6 for d in rows):
            d = run(m, N, RATIO, P, 1e-13, 1e-16, repeats_for(m, N))
            if "final_state" in d:
                d["error_vs_ref"] = relerr(d["final_state"], yref)
            d["extra_row"] = True
            wp.append(d)
            show(d, "B+")
    res["work_precision"] = wp
    res["best_at_error_1e-6"] = best_table(wp)

    # ---- C. atol ratio ----
    atol_study = []
    for m in ["arkode-verner8", "arkode-dp5", "cvode-adams", "dop853"]:
        for rtol in [1e-8, 1e-9, 1e-10]:
            for ratio_a in [1e-2, 1e-3, 1e-4]:
                d = run(m, N, RATIO, P, rtol, rtol * ratio_a, repeats_for(m, N))
                if "final_state" in d:
                    d["error_vs_ref"] = relerr(d["final_state"], yref)
                d["atol_over_rtol"] = ratio_a
                show(d, f"C. atol/rtol {ratio_a:.0e}")
                atol_study.append(d)
    res["atol_ratio_study"] = atol_study
    # fastest over the whole (rtol, atol) grid
    res["fastest_at_error_1e-6_any_atol"] = best_table(wp + atol_study)["fastest"]

    # ---- D. N = 1000, 1 period, rtol 1e-8 ----
    big = []
    ref1000 = run("arkode-verner8", 1000, RATIO, 1, 1e-13, 1e-16, 1)
    ref1000b = run("cvode-adams", 1000, RATIO, 1, 1e-13, 1e-16, 1)
    for m in ARK_EXPLICIT + ["cvode-adams", "cvode-bdf", "dop853"]:
        d = run(m, 1000, RATIO, 1, 1e-8, 1e-11, repeats_for(m, 1000))
        if "final_state" in d:
            d["error_vs_ref"] = relerr(d["final_state"], ref1000["final_state"])
        big.append(d)
        show(d, "D.")
    res["n1000"] = {"reference": {k: v for k, v in ref1000.items() if k != "final_state"},
                    "reference_agreement_cvode_adams_1e-13":
                        relerr(ref1000b["final_state"], ref1000["final_state"]),
                    "runs": big}

    # ---- E. N scaling ----
    scal = []
    for m in ARK_EXPLICIT + ["cvode-adams"]:
        for n in [10, 100, 1000, 10000]:
            d = run(m, n, RATIO, 1, 1e-8, 1e-11, repeats_for(m, n))
            d["seconds_per_period"] = d.get("seconds", float("nan")) / 1.0
            d["final_state"] = None  # keep the file small at N = 10000
            scal.append(d)
            print(f"E. {d['method']:20s} N {n:6d} s/period {d['seconds_per_period']:.5f} "
                  f"nfe {d.get('rhs_evaluations')} steps {d.get('steps')}", flush=True)
    res["n_scaling"] = scal

    res["machine"]["loadavg_at_end"] = open("/proc/loadavg").read().split()[:3]
    out = os.path.join(HERE, f"results-{date}.json")
    with open(out, "w") as f:
        json.dump(res, f, indent=1)
    print("wrote", out)


if __name__ == "__main__":
    main()
