#!/usr/bin/env python3
"""SciPy peer for reference problem R2 (docs/theory.md §6).

N identical pendulums in a row between two walls, exponential contact law
F = (a + b*sdot) * exp(alpha*s) (published form, no clamping), harmonic base
acceleration A sin(Omega t), start at rest, integrate to t_end = PERIODS * T.

Usage:
    python r2_scipy.py METHOD N OMEGA_OVER_OMEGA0 PERIODS RTOL ATOL REPEATS

METHOD: dop853 (the benchmark peer), and for information rk45, lsoda, radau,
bdf (a "scipy-" prefix is accepted too). The right-hand side is vectorised
NumPy (no Python loop over bodies). State layout is (u1..uN, v1..vN).

Environment override (checks only): R2_GAP = every clearance g in metres
(default 1e-3; 1e3 gives the linear limit, nothing touches).

Prints ONE JSON line; "seconds" is the best wall time (time.perf_counter,
monotonic) over REPEATS calls of solve_ivp only (building the right-hand side
and output are excluded); counters come from the last run.
"""
import json
import math
import os
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

# R2 parameters
M = 0.227  # kg
OMEGA0 = 7.41  # rad/s
ZETA = 0.013
A_BASE = 0.05  # m/s^2
GAP = 1.0e-3  # m
CA = 1.0  # N
CB = CA / 1.2  # N s/m
ALPHA = 1.3e5  # 1/m

# Trial steps that overshoot deep into a contact overflow exp() to inf (or
# inf*0 = nan); the integrators reject such steps. Silence NumPy's warnings
# instead of printing them on every occurrence.
np.seterr(over="ignore", invalid="ignore")

METHODS = {"dop853": "DOP853", "rk45": "RK45", "lsoda": "LSODA",
           "radau": "Radau", "bdf": "BDF"}


def make_rhs(n, omega, gap, counter):
    """Vectorised right-hand side for y = (u, v); all N+1 contacts evaluated
    on every call. Padding with wall 'bodies' at u = v = 0 makes contact j
    (0..N) s_j = up[j] - up[j+1] - g, with up = (0, u1..uN, 0)."""
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
        s = up[:-1] - up[1:] - gap
        sd = vp[:-1] - vp[1:]
        F = (CA + CB * sd) * np.exp(ALPHA * s)
        # body i: +F of the contact on its left, -F of the contact on its right
        acc = (-c * v - k * u + (F[:-1] - F[1:])) * inv_m - A_BASE * math.sin(omega * t)
        return np.concatenate((v, acc))

    return rhs


def jac_sparsity(n):
    from scipy.sparse import lil_matrix, identity
    S = lil_matrix((2 * n, 2 * n))
    S[:n, n:] = identity(n)
    for blk in (0, n):
        for i in range(n):
            for j in (i - 1, i, i + 1):
                if 0 <= j < n:
                    S[n + i, blk + j] = 1
    return S.tocsr()


def main(argv):
    if len(argv) != 8:
        sys.stderr.write("usage: r2_scipy.py METHOD N OMEGA_OVER_OMEGA0 PERIODS RTOL ATOL REPEATS\n"
                         "methods: " + " ".join(METHODS) + "\n")
        return 2
    mname = argv[1].lower()
    if mname.startswith("scipy-"):
        mname = mname[len("scipy-"):]
    if mname not in METHODS:
        sys.stderr.write(f"unknown method {argv[1]!r}\n")
        return 2
    n = int(argv[2])
    ratio = float(argv[3])
    periods = float(argv[4])
    rtol = float(argv[5])
    atol = float(argv[6])
    repeats = int(argv[7])
    if n < 1 or ratio <= 0 or periods <= 0 or rtol <= 0 or atol <= 0 or repeats < 1:
        sys.stderr.write("invalid arguments\n")
        return 2
    gap = float(os.environ.get("R2_GAP") or GAP)
    omega = ratio * OMEGA0
    T = 2.0 * math.pi / omega
    t_end = periods * T

    kwargs = {}
    if METHODS[mname] in ("Radau", "BDF"):
        kwargs["jac_sparsity"] = jac_sparsity(n)

    best = math.inf
    sol = None
    counter = [0]
    for _ in range(repeats):
        counter = [0]
        rhs = make_rhs(n, omega, gap, counter)
        y0 = np.zeros(2 * n)
        t0 = time.perf_counter()
        sol = solve_ivp(rhs, (0.0, t_end), y0, method=METHODS[mname],
                        rtol=rtol, atol=atol, **kwargs)
        t1 = time.perf_counter()
        if sol.status != 0:
            print(json.dumps({"method": argv[1], "error": sol.message, "flag": int(sol.status)}))
            return 1
        best = min(best, t1 - t0)
    out = {
        "method": argv[1],
        "solver": f"scipy {scipy.__version__} solve_ivp {METHODS[mname]} (numpy {np.__version__})",
        "n": n,
        "omega_over_omega0": ratio,
        "periods": periods,
        "t_end": t_end,
        "gap": gap,
        "rtol": rtol,
        "atol": atol,
        "repeats": repeats,
        "seconds": best,
        "rhs_evaluations": counter[0],
        "rhs_evaluations_solver": int(sol.nfev),
        "steps": int(len(sol.t) - 1),
        "jacobian_evaluations": int(sol.njev),
        "lu_decompositions": int(sol.nlu),
        "final_state": [float(x) for x in sol.y[:, -1]],
    }
    print(json.dumps(out, separators=(",", ":")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
