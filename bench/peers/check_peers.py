#!/usr/bin/env python3
"""Correctness checks for the R2 peers (run with the venv python).

  python check_peers.py [BUILD_DIR]        (default: bench/peers/build)

1. Linear limit (R2_GAP=1e3, nothing touches): final state of every peer at
   tight tolerance vs the exact solution of u'' + 2 zeta w0 u' + w0^2 u =
   -A sin(W t), u(0) = u'(0) = 0 (steady-state amplitude
   A / sqrt((w0^2 - W^2)^2 + (2 zeta w0 W)^2) plus the damped transient).
2. Cross-check with impacts: C (CVODE Adams, ARKStep Verner) vs SciPy DOP853,
   N = 3, 0.95 omega0, 5 periods, rtol 1e-13.
3. Fixed-step order of the explicit tables in the linear limit (smooth), which
   exposes SUNDIALS issue #311 (ERKStep treats tables with c_s = 1 as FSAL).
Prints a JSON summary on stdout; exits non-zero if a check fails.
"""
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else os.path.join(HERE, "build")
CBIN = os.path.join(BUILD, "r2_sundials")
PYPEER = [sys.executable, os.path.join(HERE, "r2_scipy.py")]

M, W0, ZETA, A = 0.227, 7.41, 0.013, 0.05


def exact_linear(t, W):
    """u, v of u'' + 2 z w0 u' + w0^2 u = -A sin(W t), zero initial state."""
    # particular solution X sin + Y cos
    d = W0 ** 2 - W ** 2
    e = 2 * ZETA * W0 * W
    den = d * d + e * e
    X = -A * d / den
    Y = A * e / den
    wd = W0 * math.sqrt(1 - ZETA ** 2)
    sig = ZETA * W0
    C1 = -Y
    C2 = (sig * C1 - X * W) / wd
    ex = math.exp(-sig * t)
    u = X * math.sin(W * t) + Y * math.cos(W * t) + ex * (C1 * math.cos(wd * t) + C2 * math.sin(wd * t))
    v = (X * W * math.cos(W * t) - Y * W * math.sin(W * t)
         + ex * ((-sig * C1 + wd * C2) * math.cos(wd * t) + (-sig * C2 - wd * C1) * math.sin(wd * t)))
    return u, v, math.sqrt(X * X + Y * Y)


def run(cmd, env_extra=None):
    env = dict(os.environ)
    env.update(env_extra or {})
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise RuntimeError(f"{cmd}: {out.stdout} {out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def relerr(y, ref):
    mx = max(abs(x) for x in ref)
    return max(abs(a - b) for a, b in zip(y, ref)) / mx


def main():
    ok = True
    summary = {}
    # ---- 1. linear limit ----
    n, ratio, periods = 3, 0.95, 5
    W = ratio * W0
    t_end = periods * 2 * math.pi / W
    u, v, amp = exact_linear(t_end, W)
    exact = [u] * n + [v] * n
    lin = {"t_end": t_end, "exact_u": u, "exact_v": v, "steady_amplitude": amp}
    peers = [
        ([CBIN, "cvode-adams"], 1e-12),
        ([CBIN, "cvode-bdf"], 1e-12),
        ([CBIN, "arkode-dp5"], 1e-12),
        ([CBIN, "arkode-verner8"], 1e-12),
        ([CBIN, "arkode-fehlberg8"], 1e-12),
        ([CBIN, "arkode-erk-default"], 1e-12),
        (PYPEER + ["dop853"], 1e-12),
    ]
    for cmd, rtol in peers:
        d = run(cmd + [str(n), str(ratio), str(periods), repr(rtol), repr(rtol * 1e-3), "1"],
                {"R2_GAP": "1e3"})
        e = relerr(d["final_state"], exact)
        lin[d["method"]] = {"rtol": rtol, "error": e}
        if e > 1e-8:
            ok = False
    summary["linear_limit_vs_exact"] = lin

    # ---- 2. cross-check with impacts ----
    args = ["3", "0.95", "5", "1e-13", "1e-16", "1"]
    ref = run([CBIN, "cvode-adams"] + args)
    ver = run([CBIN, "arkode-verner8"] + args)
    dp = run(PYPEER + ["dop853"] + args)
    cross = {
        "settings": "N=3, 0.95 omega0, 5 periods, rtol 1e-13, atol 1e-16",
        "cvode-adams_vs_scipy-dop853": relerr(dp["final_state"], ref["final_state"]),
        "arkode-verner8_vs_scipy-dop853": relerr(ver["final_state"], dp["final_state"]),
        "arkode-verner8_vs_cvode-adams": relerr(ver["final_state"], ref["final_state"]),
    }
    if max(v for k, v in cross.items() if k != "settings") > 1e-8:
        ok = False
    summary["impact_cross_check"] = cross

    # ---- 3. fixed-step order (linear limit, 1 period) ----
    orders = {}
    T = 2 * math.pi / W
    u1, v1, _ = exact_linear(T, W)
    ex1 = [u1, v1]
    # (method, nominal order); 10, 20, 40 fixed steps per period: coarse enough
    # that the error stays far above round-off
    steps = (10, 20, 40)
    for meth, nominal in [("arkode-dp5", 5), ("arkode-verner8", 6), ("arkode-fehlberg8", 8),
                          ("arkode-erk-default", 4), ("erkstep-verner8-raw", 6),
                          ("erkstep-fehlberg8-raw", 8)]:
        errs, nfe = [], []
        for nsteps in steps:
            d = run([CBIN, meth, "1", str(ratio), "1", "1e-6", "1e-9", "1"],
                    {"R2_GAP": "1e3", "R2_FIXED_STEP": repr(T / nsteps)})
            errs.append(relerr(d["final_state"], ex1))
            nfe.append(d["rhs_evaluations"])
        obs = [math.log2(errs[i] / errs[i + 1]) for i in range(len(steps) - 1)]
        orders[meth] = {"nominal_order": nominal, "steps_per_period": steps, "errors": errs,
                        "rhs_evaluations": nfe, "observed_orders": obs}
        # the ARKStep/ERKStep paths used by the benchmark must show their order
        if not meth.endswith("-raw") and obs[-1] < nominal - 0.7:
            ok = False
    summary["fixed_step_order_linear_limit"] = orders
    summary["ok"] = ok
    print(json.dumps(summary, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
