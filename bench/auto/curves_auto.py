#!/usr/bin/env python3
"""Two-parameter peer for R2 (default N = 1): AUTO-07p continues the fold (LP)
and symmetry-breaking branch-point (BP) curves of the periodic orbits in the
plane (W, AS) = (Omega/omega0, A/(g omega0^2)).

    python3 bench/auto/curves_auto.py [--n 1] [--ntst 400] [--ntst-fine 800] [--ncol 4]
        [--ds2 0.002] [--dsmax2 0.005] [--dsmax-bp 0.001] [--eps 1e-8] [--epss 1e-6]
        [--wmin 0.5] [--wmax 1.5] [--amin 0] [--amax 0.1] [--no-bp]
        [--out bench/auto/results/auto-curves-n1.json] [--workdir DIR] [--timeout S]

Needs build/rn.exe (build.sh --no-python). Standard library only; reuses
run_auto.py (constants, run_exe, parse_b, analyse, locate, command_text).
Every AUTO run is rn.exe with a keyword constants file on stdin in a work
directory (default: a temporary directory, removed at the end); the JSON
records each run's constants (file names only), wall time and steps.

Runs, for NTST = --ntst and again for --ntst-fine (the refinement check):
  hom      homotopy in AS from rest at W = 0.5 to AS(A = 0.05 m/s^2) (run_auto's run 1)
  branch   W from 0.5 to 1.5 (UZSTOP), ICP [1, 11], ILP=1, BP detection off
           (SP=['BP0'], see run_auto.py), DS 0.002, DSMAX 0.005: the LP points
  branchuz, bp0.. run_auto.locate: the BPs (symmetry-breaking pitchforks)
           from the changes of the unstable-multiplier count
  bpxK     only if that fails for BP K: the location run again with EPSS
           1e-4 (AUTO misses the BP near W = 0.923 at NTST 600-1000)
  lpKsw    from LP K: ISW=2, ICP=[1, 2, 11]: AUTO's start run of the fold
           continuation (Dercole/Doedel extended system, NDIM doubled; it
           grows the null vector at the fixed fold point, 5 steps)
  lpKf/b   from its EP label: ISW=2, ICP=[1, 2, 11, 21..24, 26] (21..24, 26
           printed only), both directions, stops UZSTOP W in [0.5, 1.5],
           AS in [0, 2 AS(0.05)] (i.e. A in [0, 0.1] m/s^2)
  bpcKsw   from BP K: ISW=2, ICP=[1, 2, 11]: start of the BP continuation
           for periodic orbits in a symmetric (non-generic) system (AUTO
           demo lcbp run 2; NDIM x4, DS 1e-4, NMX 20); its EP label is
           the BP corrected on the extended system
  bpcKf/b  from there: ISW=2, ICP as for folds, DSMAX --dsmax-bp (the BP
           loop of N = 1 has tight turns), both directions; a BP curve
           that closes on itself (AUTO does not stop on a closed loop) is
           recognised (it passes its start again with the same tangent),
           cut to one lap and the other direction is not run; NMX is
           raised (x2, up to --bp-nmx-max) until the loop closes or a stop
           is reached. A BP lying on a BP curve already computed is not
           continued again ("on_curve_of").

JSON (one document, --out): settings, runs, the one-parameter LP and BP
points, and the curves: one per start point (the backward run reversed and
joined to the forward one), {"kind": "fold"|"branch-point", "from": "LP1",
"closed": bool, "stops": [...], "labels": [AUTO's special points on the
curve], "points": [{"W", "AS", "frequency" (rad/s), "amplitude" (m/s^2),
"period", "max_u1" (m), "symmetry_defect"}]}, plus "refinement": the
distance of every NTST point to the NTST-fine curve in the plane
(W, A/0.05) (compare_curves.Curve: local parametric cubics).
"""
import argparse
import json
import math
import os
import re
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run_auto as ra  # noqa: E402
from compare_curves import Curve, distances, summary  # noqa: E402

OMEGA0, GAP, A_REF = ra.OMEGA0, ra.GAP, ra.A_BASE
AS_REF = ra.AS                       # AS of A = 0.05 m/s^2
AMP_PER_AS = GAP * OMEGA0 ** 2       # A = AS * g * omega0^2
OUT_PARS = "21, 22, 23, 24, 26"      # printed only (max/min x1, max/min xN, symmetry defect)

RE_NAME = re.compile(r"MAX U\(\d+\)|MIN U\(\d+\)|INTEGRAL U\(\d+\)|L2-NORM|PAR\(\d+\)|PERIOD|\S+")


def parse_b2(path):
    """Rows of a b-file with any ICP: dict(pt, ty (AUTO's code), type (LP, BP,
    UZ, EP, ... or None), lab, cols {name: value}), names from the header
    line (PAR(k), PERIOD, L2-NORM, MAX U(i), ...)."""
    names = None
    rows = []
    for line in open(path):
        f = line.split()
        if not f:
            continue
        if f[0] == "0":
            if len(f) > 3 and f[1] == "PT" and f[2] == "TY":
                names = RE_NAME.findall(line.split("LAB", 1)[1])
            continue
        if names is None or len(f) < 4 + len(names):
            continue
        try:
            pt, ty, lab = int(f[1]), int(f[2]), int(f[3])
            vals = [ra.fnum(x) for x in f[4:4 + len(names)]]
        except ValueError:
            continue
        base = (1 if ty > 0 else -1) * (abs(ty) % 10) if ty else 0
        rows.append({"pt": pt, "ty": ty, "type": ra.TYPES.get(base), "lab": lab,
                     "cols": dict(zip(names, vals))})
    return rows


def curve_point(r):
    c = r["cols"]
    w, as_ = c["PAR(1)"], c["PAR(2)"]
    p = {"W": w, "AS": as_, "frequency": w * OMEGA0, "amplitude": as_ * AMP_PER_AS,
         "period": c.get("PERIOD", c.get("PAR(11)"))}
    if "PAR(21)" in c and "PAR(22)" in c:
        p["max_u1"] = GAP * max(abs(c["PAR(21)"]), abs(c["PAR(22)"]))
    if "PAR(26)" in c:
        p["symmetry_defect"] = c["PAR(26)"]
    return p


def plane(p):
    """(W, A/A_ref): the plane of the comparison."""
    return (p["W"], p["amplitude"] / A_REF)


def closure(points, tol=1e-4, leave=0.05):
    """Index j if the polyline returns to its first point (within tol in the
    plane, with the same direction) on the segment [j, j+1] after having
    gone at least `leave` away from it; else None."""
    pl = [plane(p) for p in points]
    if len(pl) < 4:
        return None
    p0 = pl[0]
    t0 = (pl[1][0] - p0[0], pl[1][1] - p0[1])
    away = False
    for j in range(1, len(pl) - 1):
        a, b = pl[j], pl[j + 1]
        if math.dist(a, p0) > leave:
            away = True
        if not away:
            continue
        dx, dy = b[0] - a[0], b[1] - a[1]
        L2 = dx * dx + dy * dy
        if L2 == 0:
            continue
        u = max(0.0, min(1.0, ((p0[0] - a[0]) * dx + (p0[1] - a[1]) * dy) / L2))
        d = math.dist(p0, (a[0] + u * dx, a[1] + u * dy))
        cos = (dx * t0[0] + dy * t0[1]) / math.sqrt(L2 * (t0[0] ** 2 + t0[1] ** 2))
        if d < tol and cos > 0.9:
            return j
    return None


class Recorder:
    """Wraps run_auto.run_exe (also as used inside run_auto.locate) and records
    every run: name, constants (as written, no paths), seconds, steps."""

    def __init__(self, orig):
        self.orig = orig
        self.runs = []

    def __call__(self, exe, workdir, text, name, timeout=None):
        dt, out = self.orig(exe, workdir, text, name, timeout)
        consts = {}
        for ln in text.strip().split("\n"):
            k, v = ln.split("=", 1)
            consts[k.strip()] = v.strip().strip("'")
        try:
            steps = len(parse_b2(os.path.join(workdir, f"b.{name}")))
        except (OSError, KeyError):
            steps = None
        self.runs.append({"name": name, "seconds": round(dt, 3), "steps": steps,
                          "constants": consts})
        return dt, out


def turning(points, lb, closed):
    """Which of W, A has a local extremum along the curve at the label lb
    (AUTO's LP / BP labels on these curves turn out to be turning points of
    the curve in the plane): "W", "A", both or none, from the nearest curve
    point and its neighbours two steps away."""
    pl = [plane(p) for p in points]
    q = plane(lb)
    i = min(range(len(pl)), key=lambda j: math.dist(pl[j], q))
    n = len(pl)
    if not closed and not 2 <= i < n - 2:
        return None
    a, b = pl[(i - 2) % n], pl[(i + 2) % n]
    out = [name for d, name in ((0, "W"), (1, "A"))
           if (pl[i][d] - a[d]) * (b[d] - pl[i][d]) < 0]
    return "+".join(out) or None


def run_set(a, ntst, workdir, exe, exe_name, rec):
    """All runs at one NTST; returns a dict (lp_points, bp_points, curves, seconds)."""
    n = a.n
    ndim = 2 * n + 2
    out1 = ra.ICP_OUT_RN
    common = dict(NDIM=ndim, NTST=ntst, NCOL=a.ncol, EPSL=a.eps, EPSU=a.eps, EPSS=a.epss,
                  DSMIN=a.dsmin)
    bounds = "{1: [%.12g, %.12g], 2: [%.12g, %.12g]}" % (a.wmin, a.wmax, a.amin / AMP_PER_AS,
                                                          a.amax / AMP_PER_AS)
    icp2 = f"[1, 2, 11, {OUT_PARS}]"
    t_start = time.perf_counter()
    i_run0 = len(rec.runs)

    def go(name, **kw):
        text = ra.constants(e=exe_name, sv=name, **dict(common, **kw))
        return ra.run_exe(exe, workdir, text, name, a.timeout)[0]

    def c_branch(name, uzr=None, irs=None, sp="['BP0']"):
        kw = dict(e=exe_name, s="hom", sv=name, IRS=irs, ICP=f"[1, 11, {out1}]", NMX=20000,
                  DS=a.ds1, DSMAX=a.dsmax1, UZSTOP="{1: [0.45, %.12g]}" % a.wmax, **common)
        if sp:
            kw["SP"] = sp
        if uzr:
            kw["UZR"] = "{1: [%s]}" % ", ".join("%.12g" % w for w in uzr)
        return ra.constants(**kw)

    # ---- one-parameter runs ------------------------------------------------
    go("hom", IRS=0, ICP=f"[2, 11, {out1}]", NMX=500, DS=0.01, DSMAX=0.1,
       UZSTOP="{2: %.12g}" % AS_REF)
    irs = ra.label_of(ra.parse_b(os.path.join(workdir, "b.hom")), "UZ")
    if irs is None:
        raise RuntimeError("homotopy did not reach A = 0.05")
    ra.run_exe(exe, workdir, c_branch("branch", irs=irs), "branch", a.timeout)
    rows, mult, branch, special, cands = ra.analyse(workdir, ndim, n, 1e-3)
    last = rows[-1]
    one = {"points": len(rows), "end_W": last["par1"], "end_type": ra.TYPES.get(last["ty"])}
    lps = [s for s in special if s["auto_type"] == "LP"]
    located = []
    if cands and not a.no_bp:
        ns = argparse.Namespace(ds_locate=1e-4, dsmax=a.dsmax1, wmin=0.45, wmax=a.wmax,
                                sym_tol=1e-3)
        _, located = ra.locate(ns, exe, exe_name, workdir, irs, out1, common, c_branch,
                               cands, a.timeout)
    # one BP per branch-point candidate (a change of the unstable count by a
    # real multiplier through +1), named BP1, BP2, ... in branch order
    bp_cands = [c for c in cands if c["kind"] == "branch-point"] if not a.no_bp else []
    bps, unlocated = [], []
    for k, c in enumerate(bp_cands):
        b = next((x for x in located
                  if x.get("between_branch_pts") == [c["pt_before"], c["pt_after"]]), None)
        if (b is None or b["auto_type"] != "BP") and c.get("restart_label"):
            # AUTO's BP location is flaky here (at NTST 600-1000 it does not
            # locate the BP near W = 0.923 and runs on to the next one); with
            # EPSS 1e-4 it accepts a coarse location, which is enough: the
            # start run of the BP continuation corrects it on the extended
            # system ("W_corrected")
            sgn = 1.0 if c["w_after"] >= c["w_before"] else -1.0
            name = f"bpx{k + 1}"
            go(name, s="branchuz", IRS=c["restart_label"], ICP=f"[1, 11, {out1}]", NMX=200,
               DS=sgn * 1e-4, DSMAX=a.dsmax1, SP="['BP1']", EPSS=1e-4,
               UZSTOP="{1: [0.45, %.12g]}" % a.wmax)
            w_lim = c["w_after"] + 0.5 * (c["w_after"] - c["w_before"])
            found = [r for r in ra.parse_b(os.path.join(workdir, f"b.{name}"))
                     if ra.TYPES.get(r["ty"]) == "BP" and sgn * r["par1"] <= sgn * w_lim]
            if found:
                b = {"auto_type": "BP", "parameter_over_omega0": found[0]["par1"],
                     "label": found[0]["lab"], "run": name, "epss_fallback": True}
        if b is None or b["auto_type"] != "BP":
            unlocated.append({"label": f"BP{k + 1}", "w_interval": [c["w_before"], c["w_after"]],
                              "auto_type": b["auto_type"] if b else None})
            continue
        bps.append((f"BP{k + 1}", b))
    others = [b for b in located if b["auto_type"] != "BP"] + \
             [s for s in special if s["auto_type"] not in ("LP",)]

    def pt_of(w, as_=AS_REF):
        return {"W": w, "AS": as_, "frequency": w * OMEGA0, "amplitude": as_ * AMP_PER_AS}

    lp_points = [{"label": f"LP{i + 1}", "auto_label": s["label"], "run": "branch",
                  **pt_of(s["parameter_over_omega0"])} for i, s in enumerate(lps)]
    bp_points = [{"label": lab, "auto_label": b["label"], "run": b["run"],
                  **({"epss_fallback": True} if b.get("epss_fallback") else {}),
                  **pt_of(b["parameter_over_omega0"])} for lab, b in bps]

    def ep_label(name):
        labs = [r for r in parse_b2(os.path.join(workdir, f"b.{name}")) if r["lab"] > 0]
        return labs[-1]

    def finish(name):
        rs = parse_b2(os.path.join(workdir, f"b.{name}"))
        end = rs[-1]
        return rs, {"run": name, "steps": len(rs), "type": end["type"], "W": end["cols"]["PAR(1)"],
                    "AS": end["cols"]["PAR(2)"]}

    def labels_of(rs, name):
        out = []
        for r in rs[1:-1]:
            if r["lab"] > 0 and r["type"] not in (None, "RG", "EP"):
                p = curve_point(r)
                out.append({"auto_type": r["type"], "run": name, "pt": abs(r["pt"]),
                            "W": p["W"], "AS": p["AS"], "frequency": p["frequency"],
                            "amplitude": p["amplitude"]})
        return out

    curves = []
    # ---- fold curves -------------------------------------------------------
    for i, s in enumerate(lps):
        k = i + 1
        go(f"lp{k}sw", s="branch", IRS=s["label"], ISW=2, ICP="[1, 2, 11]", NMX=5, NPR=1,
           DS=0.01, DSMAX=0.01)
        lab = ep_label(f"lp{k}sw")["lab"]
        parts, stops, labels = [], [], []
        for sgn, d in ((1, "f"), (-1, "b")):
            name = f"lp{k}{d}"
            go(name, s=f"lp{k}sw", IRS=lab, ISW=2, ICP=icp2, NMX=a.nmx2, NPR=a.nmx2,
               DS=sgn * a.ds2, DSMAX=a.dsmax2, UZSTOP=bounds)
            rs, stop = finish(name)
            parts.append([curve_point(r) for r in rs])
            stops.append({"direction": sgn, **stop})
            labels += labels_of(rs, name)
        pts = parts[1][::-1] + parts[0][1:]
        for lb in labels:
            lb["extremum_of"] = turning(pts, lb, False)
        curves.append({"kind": "fold", "from": f"LP{k}", "start": lp_points[i],
                       "closed": False, "stops": stops, "labels": labels,
                       "start_index": len(parts[1]) - 1, "points": pts})

    # ---- branch-point curves ----------------------------------------------
    for i, (bplabel, b) in enumerate(bps):
        k = int(bplabel[2:])
        q = (b["parameter_over_omega0"], AS_REF * AMP_PER_AS / A_REF)
        on = None
        for c in curves:
            if c["kind"] == "branch-point":
                cv = Curve([plane(p) for p in c["points"]], closed=c["closed"])
                if cv.distance(q)[0] < 1e-4:
                    on = c["from"]
        if on:
            bp_points[i]["on_curve_of"] = on
            continue
        go(f"bpc{k}sw", s=b["run"], IRS=b["label"], ISW=2, ICP="[1, 2, 11]", NMX=20, NPR=10,
           DS=1e-4, DSMAX=0.01)
        ep = ep_label(f"bpc{k}sw")
        lab = ep["lab"]
        bp_points[i]["W_corrected"] = ep["cols"]["PAR(1)"]
        bp_points[i]["frequency_corrected"] = ep["cols"]["PAR(1)"] * OMEGA0
        parts, stops, labels, closed = [], [], [], False
        for sgn, d in ((1, "f"), (-1, "b")):
            if closed:
                break
            name = f"bpc{k}{d}"
            nmx = a.bp_nmx
            while True:
                go(name, s=f"bpc{k}sw", IRS=lab, ISW=2, ICP=icp2, NMX=nmx, NPR=nmx,
                   DS=sgn * min(a.ds2, a.dsmax_bp), DSMAX=a.dsmax_bp, UZSTOP=bounds)
                rs, stop = finish(name)
                pts = [curve_point(r) for r in rs]
                j = closure(pts)
                if j is not None or stop["type"] != "EP" or nmx >= a.bp_nmx_max:
                    break
                nmx = min(2 * nmx, a.bp_nmx_max)
            labels += labels_of(rs, name)   # the whole run (a closed loop: all laps)
            if j is not None:
                closed = True
                pts = pts[:j + 1]
                stop = {**stop, "type": "closed", "closes_after_steps": j + 1,
                        "W": pts[-1]["W"], "AS": pts[-1]["AS"], "run_end_type": stop["type"],
                        "run_steps": stop["steps"]}
            parts.append(pts)
            stops.append({"direction": sgn, **stop})
        # one entry per special point (a closed loop run for several laps meets
        # each several times; AUTO does not test the first steps after a restart)
        uniq = []
        for lb in labels:
            if not any(u["auto_type"] == lb["auto_type"] and abs(u["W"] - lb["W"]) < 1e-6
                       and abs(u["AS"] - lb["AS"]) < 1e-6 for u in uniq):
                uniq.append(lb)
        labels = uniq
        pts_all = parts[0] if closed else parts[1][::-1] + parts[0][1:]
        for lb in labels:
            lb["extremum_of"] = turning(pts_all, lb, closed)
        pts = parts[0] if closed else parts[1][::-1] + parts[0][1:]
        curves.append({"kind": "branch-point", "from": bplabel, "start": bp_points[i],
                       "closed": closed, "stops": stops, "labels": labels,
                       "start_index": 0 if closed else len(parts[1]) - 1, "points": pts})

    return {"ntst": ntst, "seconds": time.perf_counter() - t_start,
            "seconds_auto": sum(r["seconds"] for r in rec.runs[i_run0:]),
            "one_parameter_branch": one, "lp_points": lp_points, "bp_points": bp_points,
            "bp_not_located": unlocated,
            "other_special_points": [{"auto_type": s["auto_type"],
                                      "W": s["parameter_over_omega0"]} for s in others],
            "curves": curves}


def refinement(coarse, fine, end_skip=2e-3):
    """Distance of the coarse curves' points to the fine curves (same start)
    in the plane (W, A/A_ref), and the one-parameter points' differences."""
    out = {"curves": []}
    for c in coarse["curves"]:
        f = [x for x in fine["curves"] if x["from"] == c["from"] and x["kind"] == c["kind"]]
        if not f:
            out["curves"].append({"from": c["from"], "error": "no fine curve"})
            continue
        cv = Curve([plane(p) for p in f[0]["points"]], closed=f[0]["closed"])
        rows = distances([plane(p) for p in c["points"]], cv, end_skip=end_skip)
        s = summary(rows)
        out["curves"].append({"kind": c["kind"], "from": c["from"], **s})
    ds = [x["max"] for x in out["curves"] if x.get("max") is not None]
    out["max_distance"] = max(ds) if ds else None
    pts = []
    for key in ("lp_points", "bp_points"):
        fine_by = {q["label"]: q for q in fine[key]}
        for p in coarse[key]:
            q = fine_by.get(p["label"])
            if q is None:
                pts.append({"label": p["label"], "error": "not found at the fine NTST"})
                continue
            pts.append({"label": p["label"], "dW": q["W"] - p["W"]})
            if "W_corrected" in p and "W_corrected" in q:
                pts[-1]["dW_corrected"] = q["W_corrected"] - p["W_corrected"]
    out["one_parameter_points"] = pts
    return out


def main(argv):
    ap = argparse.ArgumentParser(description="AUTO-07p fold/BP curves of R2 in (W, AS)")
    ap.add_argument("--build", default=os.path.join(HERE, "build"))
    ap.add_argument("--n", type=int, default=1, help="number of bodies (NDIM = 2N + 2)")
    ap.add_argument("--ntst", type=int, default=400)
    ap.add_argument("--ntst-fine", type=int, default=800, help="refinement check (0: none)")
    ap.add_argument("--ncol", type=int, default=4)
    ap.add_argument("--ds1", type=float, default=0.002, help="DS of the one-parameter branch")
    ap.add_argument("--dsmax1", type=float, default=0.005)
    ap.add_argument("--ds2", type=float, default=0.002, help="DS of the curve runs")
    ap.add_argument("--dsmax2", type=float, default=0.005)
    ap.add_argument("--dsmin", type=float, default=1e-8)
    ap.add_argument("--eps", type=float, default=1e-8, help="EPSL = EPSU")
    ap.add_argument("--epss", type=float, default=1e-6)
    ap.add_argument("--nmx2", type=int, default=5000, help="NMX of the fold-curve runs")
    ap.add_argument("--dsmax-bp", type=float, default=0.001,
                    help="DSMAX of the BP-curve runs (the BP loop has tight turns)")
    ap.add_argument("--bp-nmx", type=int, default=2400, help="first NMX of a BP-curve run")
    ap.add_argument("--bp-nmx-max", type=int, default=12000)
    ap.add_argument("--wmin", type=float, default=0.5)
    ap.add_argument("--wmax", type=float, default=1.5)
    ap.add_argument("--amin", type=float, default=0.0, help="m/s^2")
    ap.add_argument("--amax", type=float, default=0.1, help="m/s^2")
    ap.add_argument("--no-bp", action="store_true", help="no BP location and BP curves")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per AUTO run")
    ap.add_argument("--threads", default="1", help="OMP_NUM_THREADS (default 1)")
    ap.add_argument("--workdir", default=None, help="keep the runs here (default: temporary)")
    ap.add_argument("--out", default=None, help="default results/auto-curves-n<N>.json")
    a = ap.parse_args(argv[1:])

    exe_src = os.path.join(os.path.abspath(a.build), "rn.exe")
    if not os.path.exists(exe_src):
        sys.stderr.write(f"curves_auto.py: {exe_src} missing; run build.sh --no-python first\n")
        return 2
    out = a.out or os.path.join(HERE, "results", f"auto-curves-n{a.n}.json")
    os.environ["OMP_NUM_THREADS"] = str(a.threads)
    base = os.path.abspath(a.workdir) if a.workdir else tempfile.mkdtemp(prefix="curves-auto-")
    rec = Recorder(ra.run_exe)
    ra.run_exe = rec        # also records the runs made inside run_auto.locate
    sets = []
    try:
        for ntst in [a.ntst] + ([a.ntst_fine] if a.ntst_fine else []):
            wd = os.path.join(base, f"ntst{ntst}")
            os.makedirs(wd, exist_ok=True)
            exe = os.path.join(wd, "rn.exe")
            shutil.copy2(exe_src, exe)
            i0 = len(rec.runs)
            s = run_set(a, ntst, wd, exe, "rn", rec)
            s["runs"] = rec.runs[i0:]
            sets.append(s)
            sys.stderr.write("NTST %d: %.1f s, %d curves (%s)\n" % (
                ntst, s["seconds"], len(s["curves"]),
                ", ".join("%s %s %d pts%s" % (c["kind"], c["from"], len(c["points"]),
                                               " closed" if c["closed"] else "")
                          for c in s["curves"])))
    finally:
        ra.run_exe = rec.orig
        if not a.workdir:
            shutil.rmtree(base, ignore_errors=True)

    main_set = sets[0]
    doc = {
        "solver": "AUTO-07p 0.9.2 (Debian auto-07p), IPS=2 orthogonal collocation; ISW=2 "
                  "continuation of folds and (symmetric system) branch points of periodic orbits",
        "problem": "R2, N = %d (rn.f90, NDIM = %d): W = PAR(1) = Omega/omega0, AS = PAR(2) = "
                   "A/(g omega0^2)" % (a.n, 2 * a.n + 2),
        "n": a.n, "omega0": OMEGA0, "gap": GAP, "a_ref": A_REF, "as_ref": AS_REF,
        "amplitude_per_as": AMP_PER_AS,
        "date": time.strftime("%Y-%m-%d"),
        "command": ra.command_text([sys.executable, os.path.abspath(__file__)] + argv[1:]),
        "workdir": ra.command_text([base]) if a.workdir else "$TMP (removed)",
        "loadavg": open("/proc/loadavg").read().split()[:3],
        "settings": {
            "NTST": a.ntst, "NTST_fine": a.ntst_fine, "NCOL": a.ncol, "IAD": 3, "JAC": 1,
            "EPSL": a.eps, "EPSU": a.eps, "EPSS": a.epss, "DSMIN": a.dsmin,
            "one_parameter": {"DS": a.ds1, "DSMAX": a.dsmax1, "ICP": "[1, 11]", "ILP": 1,
                              "ISP": 2, "SP": "['BP0'] + run_auto.locate"},
            "curves": {"DS": a.ds2, "DSMAX": a.dsmax2, "DSMAX_bp": a.dsmax_bp, "ISW": 2, "ICP": f"[1, 2, 11, {OUT_PARS}]",
                       "ILP": 1, "ISP": 2, "NMX_fold": a.nmx2, "NMX_bp": [a.bp_nmx, a.bp_nmx_max],
                       "UZSTOP": {"W": [a.wmin, a.wmax],
                                  "AS": [a.amin / AMP_PER_AS, a.amax / AMP_PER_AS],
                                  "amplitude_m_s2": [a.amin, a.amax]}},
            "OMP_NUM_THREADS": a.threads,
        },
        "seconds": main_set["seconds"],
        "seconds_auto_runs": main_set["seconds_auto"],
        "one_parameter_branch": main_set["one_parameter_branch"],
        "lp_points": main_set["lp_points"],
        "bp_points": main_set["bp_points"],
        "bp_not_located": main_set["bp_not_located"],
        "other_special_points": main_set["other_special_points"],
        "curves": main_set["curves"],
        "runs": main_set["runs"],
    }
    if len(sets) > 1:
        ref = refinement(sets[0], sets[1])
        ref.update({"ntst": a.ntst, "ntst_fine": a.ntst_fine, "seconds_fine": sets[1]["seconds"],
                    "plane": "(W, A/0.05 m/s^2)",
                    "fine_curves": [{"kind": c["kind"], "from": c["from"],
                                     "points": len(c["points"]), "closed": c["closed"],
                                     "stops": c["stops"], "labels": c["labels"]}
                                    for c in sets[1]["curves"]],
                    "fine_lp_points": sets[1]["lp_points"], "fine_bp_points": sets[1]["bp_points"],
                    "fine_runs": [{k: r[k] for k in ("name", "seconds", "steps")}
                                  for r in sets[1]["runs"]]})
        doc["refinement"] = ref
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")

    # short report
    print("one-parameter branch: %d steps to W = %.10g (%s)" % (
        doc["one_parameter_branch"]["points"], doc["one_parameter_branch"]["end_W"],
        doc["one_parameter_branch"]["end_type"]))
    for p in doc["lp_points"] + doc["bp_points"]:
        print("  %-4s W = %.10f%s%s" % (p["label"], p["W"],
                                        "  (corrected %.10f)" % p["W_corrected"] if "W_corrected" in p else "",
                                        "  on the curve of " + p["on_curve_of"] if "on_curve_of" in p else ""))
    for c in doc["curves"]:
        ws = [p["W"] for p in c["points"]]
        amps = [p["amplitude"] for p in c["points"]]
        print("%-13s from %-4s %5d points, W in [%.6f, %.6f], A in [%.6f, %.6f] m/s^2, %s; stops %s; "
              "labels %s" % (c["kind"], c["from"], len(c["points"]), min(ws), max(ws), min(amps),
                             max(amps), "closed" if c["closed"] else "open",
                             [(s["type"], round(s["W"], 6), round(s["AS"] * AMP_PER_AS, 6))
                              for s in c["stops"]],
                             [(lb["auto_type"], round(lb["W"], 6), round(lb["amplitude"], 6),
                               "extremum of %s" % lb["extremum_of"]) for lb in c["labels"]]))
    print("time: %.1f s (AUTO runs %.1f s) at NTST %d" % (doc["seconds"], doc["seconds_auto_runs"],
                                                         a.ntst))
    if "refinement" in doc:
        r = doc["refinement"]
        print("NTST %d -> %d: max distance %.2e (per curve %s), one-parameter points %s; fine run %.1f s" % (
            a.ntst, a.ntst_fine, r["max_distance"] or float("nan"),
            [(c["from"], "%.1e" % c["max"]) for c in r["curves"] if c.get("max") is not None],
            [(p["label"], "%.1e" % p["dW"], "%.1e" % p.get("dW_corrected", float("nan")))
             for p in r["one_parameter_points"] if "dW" in p], r["seconds_fine"]))
    print("wrote", ra.command_text([os.path.abspath(out)]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
