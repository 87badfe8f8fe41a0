#!/usr/bin/env python3
"""Brute-force frequency sweep of reference problem R2 (N = 2 by default) with
SciPy solve_ivp DOP853: the "sweep of the same resolution" that the
continuation peer (AUTO-07p, run_auto.py) is compared against.

For K frequencies Omega/omega0 from WMIN to WMAX (default 101 from 0.5 to 1.5):
integrate from rest (default) or from the previous frequency's final state
(--continue) over a transient of P1 periods (default 100), then record P2
periods (default 10): per period the maximum of |u_i| (from the dense output,
SAMPLES points per period, plus the accepted step points) and one stroboscopic
(Poincare) sample of the state at the end of the period.

Model: docs/theory.md §4 and §6, as in bench/peers/r2_scipy.py
(published contact law, no clamping; vectorised NumPy right-hand side, state
(u_1..u_N, v_1..v_N) in SI units). Base acceleration A sin(Omega t), t = 0 at
the start of every frequency (with --continue the previous run ended after a
whole number of periods, so the forcing phase is continuous).

Steadiness: the Poincare samples of the recorded periods are compared in the
max-norm, u in units of the clearance g and v in units of g*omega0.
  d1 = |P_P2 - P_(P2-1)|  (last two recorded periods)
  "period": smallest k <= P2/2 with |P_P2 - P_(P2-k)| < --tol (default 1e-6);
            null if none (not steady, quasi-periodic or chaotic)
  "steady": d1 < tol (period-1 steady state reached)

Output: one JSON line per frequency to --out (default: stdout), then ONE
summary JSON line on stdout: {"summary": true, "seconds_total":...,
"seconds_per_frequency_mean":..., ...}. "seconds" per frequency is the wall
time (time.perf_counter) of the solve_ivp calls for that frequency
(transient + recorded periods, including dense-output evaluation for the
maxima); building the right-hand side and writing output are excluded.

Usage:
  python sweep_scipy.py [--k 101] [--wmin 0.5] [--wmax 1.5] [--p1 100]
      [--p2 10] [--continue] [--down] [--rtol 1e-9] [--atol 1e-12]
      [--samples 2000] [--tol 1e-6] [--n 2] [--out FILE] [--quiet]
"""
import argparse
import json
import math
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

# R2 parameters (SI)
M = 0.227  # kg
OMEGA0 = 7.41  # rad/s
ZETA = 0.013
A_BASE = 0.05  # m/s^2
GAP = 1.0e-3  # m
CA = 1.0  # N
CB = CA / 1.2  # N s/m
ALPHA = 1.3e5  # 1/m

np.seterr(over="ignore", invalid="ignore")


def make_rhs(n, omega, counter):
    """y = (u_1..u_N, v_1..v_N); all N+1 contacts evaluated with one np.exp.
    Padding with wall 'bodies' at 0: contact j (0..N) has
    s_j = up[j] - up[j+1] - g with up = (0, u_1..u_N, 0)."""
    k = M * OMEGA0 ** 2
    c = 2.0 * ZETA * M * OMEGA0
    inv_m = 1.0 / M
    up = np.zeros(n + 2)
    vp = np.zeros(n + 2)

    def rhs(t, y):
        counter[0] += 1
        u = y[:n]
        v = y[n:]
        up[1:-1] = u
        vp[1:-1] = v
        s = up[:-1] - up[1:] - GAP
        sd = vp[:-1] - vp[1:]
        F = (CA + CB * sd) * np.exp(ALPHA * s)
        acc = (-c * v - k * u + (F[:-1] - F[1:])) * inv_m - A_BASE * math.sin(omega * t)
        return np.concatenate((v, acc))

    return rhs


def one_frequency(n, ratio, y0, args):
    omega = ratio * OMEGA0
    T = 2.0 * math.pi / omega
    counter = [0]
    rhs = make_rhs(n, omega, counter)
    steps = 0
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, args.p1 * T), y0, method="DOP853",
                    rtol=args.rtol, atol=args.atol)
    if sol.status != 0:
        raise RuntimeError(f"solve_ivp failed in the transient at {ratio}: {sol.message}")
    steps += len(sol.t) - 1
    t_transient = time.perf_counter() - t0
    y = sol.y[:, -1].copy()
    maxu = []      # per recorded period: [max|u_1|, ..., max|u_N|]
    poincare = []  # per recorded period: state at its end
    frac = np.linspace(0.0, 1.0, args.samples + 1)
    for j in range(args.p2):
        ta = (args.p1 + j) * T
        tb = ta + T
        sol = solve_ivp(rhs, (ta, tb), y, method="DOP853",
                        rtol=args.rtol, atol=args.atol, dense_output=True)
        if sol.status != 0:
            raise RuntimeError(f"solve_ivp failed in period {j} at {ratio}: {sol.message}")
        steps += len(sol.t) - 1
        dense = sol.sol(ta + frac * T)[:n]
        m = np.maximum(np.abs(dense).max(axis=1), np.abs(sol.y[:n]).max(axis=1))
        maxu.append(m)
        y = sol.y[:, -1].copy()
        poincare.append(y.copy())
    seconds = time.perf_counter() - t0

    scale = np.concatenate((np.full(n, GAP), np.full(n, GAP * OMEGA0)))
    P = np.array(poincare) / scale
    last = P[-1]
    d1 = float(np.abs(last - P[-2]).max()) if args.p2 >= 2 else float("nan")
    period = None
    for k in range(1, args.p2 // 2 + 1):
        if float(np.abs(last - P[-1 - k]).max()) < args.tol:
            period = k
            break
    maxu = np.array(maxu)
    rec = {
        "omega_over_omega0": ratio,
        "seconds": seconds,
        "seconds_transient": t_transient,
        "rhs_evaluations": counter[0],
        "steps": int(steps),
        "periods_transient": args.p1,
        "periods_recorded": args.p2,
        "max_u": [float(x) for x in maxu.max(axis=0)],
        "max_u_last_period": [float(x) for x in maxu[-1]],
        "max_u_per_period": [[float(x) for x in row] for row in maxu],
        "poincare": [[float(x) for x in row] for row in poincare],
        "poincare_diff_last2_scaled": d1,
        "max_u_diff_last2": float(np.abs(maxu[-1] - maxu[-2]).max()) if args.p2 >= 2 else None,
        "period": period,
        "steady": bool(d1 < args.tol),
    }
    return rec, y


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k", type=int, default=101, help="number of frequencies")
    ap.add_argument("--wmin", type=float, default=0.5)
    ap.add_argument("--wmax", type=float, default=1.5)
    ap.add_argument("--p1", type=int, default=100, help="transient periods")
    ap.add_argument("--p2", type=int, default=10, help="recorded periods")
    ap.add_argument("--continue", dest="cont", action="store_true",
                    help="start each frequency from the previous final state")
    ap.add_argument("--down", action="store_true", help="sweep from wmax down to wmin")
    ap.add_argument("--rtol", type=float, default=1e-9)
    ap.add_argument("--atol", type=float, default=1e-12)
    ap.add_argument("--samples", type=int, default=2000,
                    help="dense-output samples per recorded period for max|u|")
    ap.add_argument("--tol", type=float, default=1e-6,
                    help="steadiness tolerance on Poincare samples (u/g, v/(g omega0))")
    ap.add_argument("--n", type=int, default=2, help="number of bodies")
    ap.add_argument("--only", type=float, nargs="*", help="explicit list of Omega/omega0")
    ap.add_argument("--out", default="-", help="JSON-lines file ('-' = stdout)")
    ap.add_argument("--quiet", action="store_true", help="no progress table on stderr")
    args = ap.parse_args(argv[1:])
    if args.p2 < 2 or args.p1 < 0 or args.k < 1:
        ap.error("need --p2 >= 2, --p1 >= 0, --k >= 1")

    if args.only:
        ws = list(args.only)
    elif args.k == 1:
        ws = [args.wmin]
    else:
        ws = [args.wmin + (args.wmax - args.wmin) * i / (args.k - 1) for i in range(args.k)]
    if args.down:
        ws = ws[::-1]
    out = sys.stdout if args.out == "-" else open(args.out, "w")
    n = args.n
    y = np.zeros(2 * n)
    total = 0.0
    nsteady = 0
    rows = []
    for w in ws:
        if not args.cont:
            y = np.zeros(2 * n)
        rec, y = one_frequency(n, round(w, 12), y, args)
        rec.update({"n": n, "rtol": args.rtol, "atol": args.atol,
                    "start": "continue" if args.cont else "rest"})
        total += rec["seconds"]
        nsteady += rec["steady"]
        rows.append(rec)
        out.write(json.dumps(rec, separators=(",", ":")) + "\n")
        out.flush()
        if not args.quiet:
            sys.stderr.write("W=%.4f  max|u|/g = %s  d1=%.2e period=%s  %.2f s\n" % (
                rec["omega_over_omega0"],
                " ".join("%.5f" % (x / GAP) for x in rec["max_u"]),
                rec["poincare_diff_last2_scaled"], rec["period"], rec["seconds"]))
    if out is not sys.stdout:
        out.close()
    summary = {
        "summary": True,
        "solver": f"scipy {scipy.__version__} solve_ivp DOP853 (numpy {np.__version__})",
        "n": n, "frequencies": len(ws), "wmin": min(ws), "wmax": max(ws),
        "start": "continue" if args.cont else "rest", "direction": "down" if args.down else "up",
        "periods_transient": args.p1, "periods_recorded": args.p2,
        "rtol": args.rtol, "atol": args.atol, "tol": args.tol,
        "seconds_total": total,
        "seconds_per_frequency_mean": total / len(ws),
        "seconds_per_frequency_min": min(r["seconds"] for r in rows),
        "seconds_per_frequency_max": max(r["seconds"] for r in rows),
        "rhs_evaluations_total": sum(r["rhs_evaluations"] for r in rows),
        "steps_total": sum(r["steps"] for r in rows),
        "steady_count": nsteady,
        "period_counts": {str(k): sum(1 for r in rows if r["period"] == k)
                          for k in sorted({r["period"] for r in rows}, key=lambda p: (p is None, p or 0))},
    }
    print(json.dumps(summary, separators=(",", ":")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
