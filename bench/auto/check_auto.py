#!/usr/bin/env python3
"""Independent checks of the AUTO-07p branch (run_auto.py) with SciPy DOP853.

1. Runs the branch continuation again (same settings as run_auto.py defaults,
   or --ntst/--dsmax) with user points (UZR) at Omega/omega0 = --grid values,
   so that AUTO writes those orbits to s.check.
2. For each such orbit: takes AUTO's state at t = 0 (scaled: x = u/g,
   v = x', oscillator (X, Y) = (sin phi, cos phi)), converts to SI at time
   t0 = phi/Omega of the SI model (forcing -A sin(Omega t)) and integrates one
   period with DOP853 (rtol 1e-12, atol 1e-15 in SI):
     - periodicity residual |x(t0+T) - x(t0)| (max-norm, u/g and v/(g omega0));
     - max|u_i| over the period (dense output) vs AUTO's collocation maxima;
     - the monodromy matrix by central differences (h = 1e-6 in scaled units)
       and its eigenvalues vs AUTO's four non-trivial multipliers (d-file);
   and, for --long P periods (default 200), whether the orbit, started at
   AUTO's point plus 1e-6 (scaled) in every component, stays on it.
Prints one JSON line per orbit and a summary line.

Usage: build/venv/bin/python check_auto.py [--grid 0.5 0.6 ...] [--long 200]
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run_auto as ra  # noqa: E402

M, OMEGA0, ZETA, A_BASE, GAP = 0.227, 7.41, 0.013, 0.05, 1.0e-3
CA, CB, ALPHA = 1.0, 1.0 / 1.2, 1.3e5
np.seterr(over="ignore", invalid="ignore")


def rhs_factory(omega):
    k = M * OMEGA0 ** 2
    c = 2.0 * ZETA * M * OMEGA0

    def rhs(t, y):
        u1, u2, v1, v2 = y
        F0 = (CA - CB * v1) * np.exp(ALPHA * (-u1 - GAP))
        F1 = (CA + CB * (v1 - v2)) * np.exp(ALPHA * (u1 - u2 - GAP))
        F2 = (CA + CB * v2) * np.exp(ALPHA * (u2 - GAP))
        f = -A_BASE * math.sin(omega * t)
        return [v1, v2, (-c * v1 - k * u1 + F0 - F1) / M + f, (-c * v2 - k * u2 + F1 - F2) / M + f]

    return rhs


def parse_s(path):
    """Solutions of an AUTO s-file: list of dict(lab, pt, t[], u[][], par[])."""
    sols = []
    with open(path) as fh:
        lines = fh.read().splitlines()
    i = 0
    while i < len(lines):
        h = lines[i].split()
        if not h:
            i += 1
            continue
        ibr, ntot, itp, lab, nfpr, isw, ntpl, nar, nrowpr, ntst, ncol, npar = (int(x) for x in h[:12])
        block = " ".join(lines[i + 1:i + 1 + nrowpr]).replace("D", "E").split()
        vals = block
        pos = 0
        orb = np.array([float(x) for x in vals[pos:pos + ntpl * nar]]).reshape(ntpl, nar)
        pos += ntpl * nar
        pos += nfpr  # ICP
        pos += nfpr  # RLDOT
        pos += ntpl * (nar - 1)  # UDOT
        par = [float(x) for x in vals[pos:pos + npar]]
        sols.append({"lab": lab, "pt": abs(ntot), "itp": itp, "t": orb[:, 0], "u": orb[:, 1:], "par": par})
        i += 1 + nrowpr
    return sols


def main(argv):
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid", type=float, nargs="*",
                    default=[0.5, 0.505, 0.52, 0.6, 0.7, 0.8, 0.9, 0.95, 0.98, 0.99, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5])
    ap.add_argument("--ntst", type=int, default=300)
    ap.add_argument("--dsmax", type=float, default=0.005)
    ap.add_argument("--long", type=int, default=200)
    ap.add_argument("--build", default=os.path.join(HERE, "build"))
    args = ap.parse_args(argv[1:])

    workdir = os.path.join(args.build, "check")
    os.makedirs(workdir, exist_ok=True)
    exe = os.path.join(workdir, "r2n2.exe")
    import shutil
    shutil.copy2(os.path.join(args.build, "r2n2.exe"), exe)
    os.environ["OMP_NUM_THREADS"] = "1"
    common = dict(NTST=args.ntst, NCOL=4, EPSL=1e-7, EPSU=1e-7, EPSS=1e-5, DSMIN=1e-7)
    ra.run_exe(exe, workdir, ra.constants(e="r2n2", sv="hom", IRS=0, ICP=f"[2, 11, {ra.ICP_OUT}]",
                                          NMX=500, DS=0.01, DSMAX=0.1,
                                          UZSTOP="{2: %.12g}" % ra.AS, **common), "hom")
    irs = ra.label_of(ra.parse_b(os.path.join(workdir, "b.hom")), "UZ")
    grid = [w for w in args.grid if w < 1.5 - 1e-9]
    ra.run_exe(exe, workdir, ra.constants(
        e="r2n2", s="hom", sv="check", IRS=irs, ICP=f"[1, 11, {ra.ICP_OUT}]", NMX=20000,
        DS=0.002, DSMAX=args.dsmax, SP="['BP0']", UZSTOP="{1: [0.45, 1.5]}",
        UZR="{1: [%s]}" % ", ".join("%.12g" % w for w in grid), **common), "check")
    # the start orbit (W = 0.5, end of the amplitude homotopy) and the UZR orbits
    mult_hom = ra.parse_d(os.path.join(workdir, "d.hom"))
    mult_chk = ra.parse_d(os.path.join(workdir, "d.check"))
    sols = [dict(s, mult=mult_hom) for s in parse_s(os.path.join(workdir, "s.hom")) if s["lab"] == irs]
    sols += [dict(s, mult=mult_chk) for s in parse_s(os.path.join(workdir, "s.check")) if s["itp"] == -4]
    scale = np.array([GAP, GAP, GAP * OMEGA0, GAP * OMEGA0])
    worst = {"periodicity": 0.0, "maxu_rel": 0.0, "multiplier_rel": 0.0}
    for s in sols:
        W = s["par"][0]
        if W < 0.499:
            continue
        omega = W * OMEGA0
        T = 2 * math.pi / omega
        x0 = s["u"][0]
        phi = math.atan2(x0[4], x0[5])
        t0 = (phi % (2 * math.pi)) / omega
        y0 = x0[:4] * scale
        rhs = rhs_factory(omega)
        t_a = time.perf_counter()
        sol = solve_ivp(rhs, (t0, t0 + T), y0, method="DOP853", rtol=1e-12, atol=1e-15,
                        dense_output=True)
        res = float(np.abs((sol.y[:, -1] - y0) / scale).max())
        tt = np.linspace(t0, t0 + T, 20001)
        uu = np.abs(sol.sol(tt)[:2]).max(axis=1)
        maxu_auto = np.array([max(abs(s["u"][:, 0].max()), abs(s["u"][:, 0].min())),
                              max(abs(s["u"][:, 1].max()), abs(s["u"][:, 1].min()))]) * GAP
        # monodromy (scaled coordinates) by central differences
        h = 1e-6
        Mx = np.zeros((4, 4))
        for j in range(4):
            e = np.zeros(4)
            e[j] = h
            yp = solve_ivp(rhs, (t0, t0 + T), (x0[:4] + e) * scale, method="DOP853",
                           rtol=1e-12, atol=1e-15).y[:, -1] / scale
            ym = solve_ivp(rhs, (t0, t0 + T), (x0[:4] - e) * scale, method="DOP853",
                           rtol=1e-12, atol=1e-15).y[:, -1] / scale
            Mx[:, j] = (yp - ym) / (2 * h)
        ev = np.linalg.eigvals(Mx)
        ev_auto = ra.nontrivial(s["mult"].get(s["pt"], (0, []))[1])
        # drop the oscillator's multiplier exp(-2T) (smallest modulus)
        ev_auto = sorted(ev_auto, key=abs, reverse=True)[:4]
        ev_s = sorted(ev, key=abs, reverse=True)
        mrel = max(abs(abs(a) - abs(b)) / max(abs(b), 1e-300) for a, b in zip(ev_auto, ev_s)) if ev_auto else None
        # long run from the orbit plus 1e-6
        yl = (x0[:4] + 1e-6) * scale
        soll = solve_ivp(rhs, (t0, t0 + args.long * T), yl, method="DOP853", rtol=1e-10, atol=1e-13)
        dev = float(np.abs((soll.y[:, -1] - y0) / scale).max())
        dt = time.perf_counter() - t_a
        stable_auto = max((abs(z) for z in ev_auto), default=0) < 1
        rec = {"omega_over_omega0": W, "label": s["lab"], "periodicity_residual": res,
               "max_u_scipy": [float(x) for x in uu], "max_u_auto": [float(x) for x in maxu_auto],
               "max_u_rel_diff": float(np.abs(uu - maxu_auto).max() / uu.max()),
               "multipliers_fd": sorted([abs(complex(z)) for z in ev_s], reverse=True),
               "multipliers_auto": [abs(z) for z in ev_auto], "multiplier_rel_diff": mrel,
               "auto_stable": stable_auto, "long_periods": args.long,
               "deviation_after_long": dev, "stays": dev < 1e-3, "seconds": dt}
        worst["periodicity"] = max(worst["periodicity"], res)
        worst["maxu_rel"] = max(worst["maxu_rel"], rec["max_u_rel_diff"])
        if mrel is not None:
            worst["multiplier_rel"] = max(worst["multiplier_rel"], mrel)
        print(json.dumps(rec, separators=(",", ":")), flush=True)
    print(json.dumps({"summary": True, "orbits": len(sols), "worst": worst}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
