#!/usr/bin/env python3
"""Continuation peer for reference problem R2 (default N = 2 bodies; --n N
for a row of N): AUTO-07p follows the branch of T-periodic solutions in Omega
from 0.5 to 1.5 omega0.

Needs the executables built by build.sh (BUILD/r2n2.exe from r2n2.f90, N = 2
only, and BUILD/rn.exe from rn.f90, any N; both with the AUTO-07p library of
the Debian package auto-07p). --exe r2n2|rn|PATH picks one (default: r2n2 for
N = 2, rn otherwise). Standard library only.

Runs (each a call of the executable with a keyword constants file on stdin, in
WORKDIR; AUTO writes b.NAME / s.NAME / d.NAME there):
  1. hom     homotopy in the forcing amplitude at Omega = 0.5 omega0: from the
             exact solution with zero forcing (bodies at rest, oscillator on
             its unit circle; STPNT in r2n2.f90) to A = 0.05 m/s^2 (UZSTOP).
  2. branch  from that orbit, continuation in Omega/omega0 up to 1.5 (UZSTOP),
             Floquet multipliers and detection of folds (LP), period doublings
             (PD) and torus bifurcations (TR); detection of branch points is
             switched off (SP=['BP0']) because after locating a (symmetry-
             breaking) pitchfork AUTO continues on the bifurcating asymmetric
             branch instead of the primary one.
  Runs 1+2 are "the continuation"; "seconds" is their best wall time over
  --repeats complete repetitions (with --repeat-location the BP location of
  step 3 is repeated too, and "seconds_total" is the best of runs 1+2+3).
  3. BP location (unless --no-locate-bp): every change of the number of
     unstable multipliers on the branch that no located LP/PD/TR explains is a
     branch-point candidate. Run 2 is repeated with a user point (UZR) at the
     Omega of the last point before each candidate, and from each such label a
     short run with BP detection on stops at the first BP (SP=['BP1']): the
     located branch point. Timed separately ("seconds_bp_location").
  4. --secondary: branch switching (ISW=-1) at each located BP, both
     directions, for information (the asymmetric branches), NMX limited.

Prints ONE JSON line:
  {"seconds":..., "points":..., "special_points":[{"kind":..., "parameter_over_omega0":...,
   "label":..., ...}], "branch":[{"omega_over_omega0":..., "max_u1":..., "max_u2":...,
   "stable":..., "max_abs_multiplier":...}], ...settings and extra timings...}
max_u_i in metres (max over the orbit of |u_i|, from the collocation points).
For N != 2 the branch rows have max_u1 and max_uN (first and last body); with
rn.exe every row also has "symmetry_defect" (PAR(26) of rn.f90, in units of
g: max_i |max x_i + min x_(N+1-i)|, ~0 on the symmetric branch
u_(N+1-i)(t) = -u_i(t + T/2)); with r2n2.exe (N = 2) the same quantity is
computed from PAR(21..24). "symmetric_to_wmax": reached 1.5 with every point
symmetric (defect < --sym-tol).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))

# R2 in the scaled units of r2n2.f90
M, OMEGA0, A_BASE, GAP = 0.227, 7.41, 0.05, 1.0e-3
AS = A_BASE / (GAP * OMEGA0 ** 2)

TYPES = {1: "BP", 2: "LP", 3: "HB", 4: "RG", -4: "UZ", 5: "LP", 6: "BP", 7: "PD",
         8: "TR", 9: "EP", -9: "MX"}
KINDS = {"LP": "fold", "BP": "branch-point", "PD": "period-doubling", "TR": "neimark-sacker"}
ICP_OUT = "21, 22, 23, 24, 25"
ICP_OUT_RN = "21, 22, 23, 24, 25, 26"   # rn.f90: PAR(26) = symmetry defect


def constants(**kw):
    c = dict(NDIM=6, IPS=2, ILP=1, NCOL=4, IAD=3, ISP=2, ISW=1, IPLT=0, NBC=0, NINT=0,
             NPR=100000, MXBF=10, IID=2, ITMX=8, ITNW=7, NWTN=3, JAC=1, IADS=1)
    c.update(kw)
    lines = []
    for k, v in c.items():
        if isinstance(v, str) and k in ("s", "sv", "e"):
            lines.append(f"{k} = '{v}'")
        else:
            lines.append(f"{k} = {v}")
    return "\n".join(lines) + "\n"


class AutoTimeout(RuntimeError):
    pass


def command_text(cmd):
    """A command line as text for the results: the Python interpreter as
    `python3`, paths in the repository relative to its root, temporary
    paths under `$TMP` (results must not name this machine's folders)."""
    root = os.path.dirname(os.path.dirname(HERE))
    tmp = tempfile.gettempdir()
    out = []
    for i, tok in enumerate(cmd):
        if i == 0 and tok == sys.executable:
            tok = "python3"
        elif os.path.isabs(tok) and tok.startswith(root + os.sep):
            tok = os.path.relpath(tok, root)
        elif os.path.isabs(tok) and tok.startswith(tmp + os.sep):
            tok = "$TMP/" + os.path.relpath(tok, tmp)
        out.append(tok)
    return " ".join(out)


def run_exe(exe, workdir, text, name, timeout=None):
    """Run the AUTO executable with constants TEXT on stdin; returns (wall
    seconds, stdout). Raises AutoTimeout after TIMEOUT seconds (child killed)."""
    for ext in "bsd":
        p = os.path.join(workdir, f"{ext}.{name}")
        if os.path.exists(p):
            os.remove(p)
    t0 = time.perf_counter()
    try:
        p = subprocess.run([exe], input=text, cwd=workdir, capture_output=True, text=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        raise AutoTimeout(f"AUTO run {name} exceeded {timeout} s")
    dt = time.perf_counter() - t0
    if p.returncode != 0 or not os.path.exists(os.path.join(workdir, f"b.{name}")):
        sys.stderr.write(p.stdout[-3000:] + p.stderr[-3000:])
        raise RuntimeError(f"AUTO run {name} failed (exit {p.returncode})")
    return dt, p.stdout


_RE_FEXP = re.compile(r"(?<=[0-9.])([+-]\d{3})$")


def fnum(x):
    """A Fortran number: 1.5D-03, 1.5E-03 and, for three-digit exponents,
    1.5-152 / 1.5+308 (no exponent letter)."""
    x = x.replace("D", "E")
    if "E" not in x and "e" not in x:
        x = _RE_FEXP.sub(r"E\1", x)
    return float(x)


def parse_b(path):
    """Rows of a b-file: dict(br, pt, ty, lab, par1, l2, period, p21..p25 and,
    if printed (rn.exe), p26 as "defect")."""
    rows = []
    for line in open(path):
        f = line.split()
        if len(f) < 12 or f[0] == "0":
            continue
        try:
            br, pt, ty, lab = (int(x) for x in f[:4])
            vals = [fnum(x) for x in f[4:13]]
        except ValueError:
            continue
        rows.append(dict(br=br, pt=pt, ty=ty, lab=lab, par1=vals[0], l2=vals[1], period=vals[2],
                         maxx1=vals[3], minx1=vals[4], maxx2=vals[5], minx2=vals[6], mu=vals[7]))
        if len(vals) > 8:
            rows[-1]["defect"] = vals[8]
    return rows


RE_STAB = re.compile(r"^\s*(-?\d+)\s+(-?\d+)\s+Multipliers:\s+Stable:\s+(\d+)")
RE_MULT = re.compile(r"^\s*(-?\d+)\s+(-?\d+)\s+Multiplier\s+(\d+)\s+(\S+)\s+(\S+)\s+Abs")


def parse_d(path):
    """Floquet multipliers per |PT| (the last block printed for that point, i.e.
    the converged one): dict pt -> (stable count, [complex])."""
    out = {}
    cur = None
    for line in open(path):
        m = RE_STAB.match(line)
        if m:
            cur = abs(int(m.group(2)))
            out[cur] = (int(m.group(3)), [])
            continue
        m = RE_MULT.match(line)
        if m and cur is not None and abs(int(m.group(2))) == cur:
            out[cur][1].append(complex(fnum(m.group(4)), fnum(m.group(5))))
    return out


def cabs(z):
    """|z|, inf instead of an OverflowError (diverged runs print +-1.8e308)."""
    try:
        return abs(z)
    except OverflowError:
        return float("inf")


def nontrivial(mults):
    """Drop the multiplier nearest +1 (the trivial one of an autonomous orbit)."""
    if not mults:
        return []
    i = min(range(len(mults)), key=lambda j: cabs(mults[j] - 1.0))
    return mults[:i] + mults[i + 1:]


def crossing_kind(before, after, u_before, u_after):
    """Kind of the multiplier(s) that crossed the unit circle between two
    consecutive points. On the side where they are outside (after if the
    unstable count rose from k to l, before if it fell from l to k) they are
    the smallest l-k of the l multipliers of modulus > 1. Complex ->
    neimark-sacker, real > 0 -> branch-point (a fold would have been located
    by ILP=1), real < 0 -> period-doubling."""
    lo, hi = min(u_before, u_after), max(u_before, u_after)
    mults = after if u_after > u_before else before
    nt = sorted(nontrivial(mults), key=cabs, reverse=True)
    kinds = set()
    for z in nt[lo:hi]:
        if abs(z.imag) > 1e-6 * max(1.0, cabs(z)):
            kinds.add("neimark-sacker")
        else:
            kinds.add("branch-point" if z.real > 0 else "period-doubling")
    for k in ("neimark-sacker", "period-doubling", "branch-point"):
        if k in kinds:
            return k
    return "unknown"


def label_of(rows, tyname):
    for r in rows:
        if TYPES.get(r["ty"]) == tyname:
            return r["lab"]
    return None


def main(argv):
    ap = argparse.ArgumentParser(description="AUTO-07p continuation peer for R2 (N bodies, default 2)")
    ap.add_argument("--build", default=os.path.join(HERE, "build"), help="build dir with r2n2.exe, rn.exe")
    ap.add_argument("--n", type=int, default=2, help="number of bodies N (NDIM = 2N + 2)")
    ap.add_argument("--exe", default=None,
                    help="r2n2 | rn | path of an executable (default: r2n2 for N = 2, rn otherwise)")
    ap.add_argument("--workdir", default=None, help="run directory (default BUILD/run)")
    ap.add_argument("--ntst", type=int, default=300)
    ap.add_argument("--ncol", type=int, default=4)
    ap.add_argument("--ds", type=float, default=0.002)
    ap.add_argument("--dsmax", type=float, default=0.005)
    ap.add_argument("--dsmin", type=float, default=1e-7)
    ap.add_argument("--eps", type=float, default=1e-7, help="EPSL = EPSU")
    ap.add_argument("--epss", type=float, default=1e-5)
    ap.add_argument("--nmx", type=int, default=20000)
    ap.add_argument("--wmax", type=float, default=1.5)
    ap.add_argument("--wmin", type=float, default=0.45, help="lower stop of the branch run (UZSTOP)")
    ap.add_argument("--start", type=float, default=0.5,
                    help="Omega/omega0 of the homotopy (default 0.5); another value adds a run 'pre' "
                         "that moves the rest solution (zero forcing) from 0.5 there first; a start "
                         "above 1 continues the branch downwards (end: --wmin)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", default="1", help="OMP_NUM_THREADS for AUTO (default 1)")
    ap.add_argument("--bp-detection", action="store_true",
                    help="leave BP detection on in the branch run (AUTO then switches branches)")
    ap.add_argument("--no-locate-bp", action="store_true")
    ap.add_argument("--ds-locate", type=float, default=1e-4,
                    help="DS of the BP-location runs (small: AUTO does not test the first step)")
    ap.add_argument("--secondary", action="store_true",
                    help="also switch onto the branches bifurcating at the located BPs")
    ap.add_argument("--secondary-nmx", type=int, default=3000)
    ap.add_argument("--repeat-location", action="store_true",
                    help="repeat the BP location (step 3) in every repetition; seconds_total = best "
                         "of runs 1+2+3")
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds per AUTO run; on expiry one JSON line with \"error\": \"timeout\"")
    ap.add_argument("--sym-tol", type=float, default=1e-3,
                    help="symmetry defect (units of g) below which a point counts as symmetric")
    ap.add_argument("--no-branch", action="store_true", help="leave the branch table out of the JSON")
    args = ap.parse_args(argv[1:])

    n_bodies = args.n
    ndim = 2 * n_bodies + 2
    exe_name = args.exe or ("r2n2" if n_bodies == 2 else "rn")
    if exe_name in ("r2n2", "rn"):
        exe_src = os.path.join(os.path.abspath(args.build), exe_name + ".exe")
    else:
        exe_src = os.path.abspath(exe_name)
        exe_name = os.path.splitext(os.path.basename(exe_src))[0]
    if exe_name == "r2n2" and n_bodies != 2:
        sys.stderr.write("run_auto.py: r2n2.exe is N = 2 only; use --exe rn\n")
        return 2
    if not os.path.exists(exe_src):
        sys.stderr.write(f"run_auto.py: {exe_src} missing; run build.sh first\n")
        return 2
    # rn.f90 prints the symmetry defect PAR(26) as well
    icp_out = ICP_OUT if exe_name == "r2n2" else ICP_OUT_RN
    workdir = os.path.abspath(args.workdir or os.path.join(args.build, "run"))
    os.makedirs(workdir, exist_ok=True)
    exe = os.path.join(workdir, exe_name + ".exe")
    shutil.copy2(exe_src, exe)
    os.environ["OMP_NUM_THREADS"] = str(args.threads)
    try:
        return run_all(args, n_bodies, ndim, exe_name, exe, icp_out, workdir)
    except AutoTimeout as e:
        print(json.dumps({"error": "timeout", "message": str(e), "n": n_bodies, "exe": exe_name,
                          "timeout": args.timeout}))
        return 3


def defect_of(r):
    """Symmetry defect of a b-file row: PAR(26) if printed (rn.exe), else (N = 2,
    r2n2.exe) from max/min of x1 and x2: |max x1 + min x2|, |min x1 + max x2|."""
    if "defect" in r:
        return r["defect"]
    return max(abs(r["maxx1"] + r["minx2"]), abs(r["minx1"] + r["maxx2"]))


def analyse(workdir, ndim, n_bodies, sym_tol):
    """Branch table of run 2, AUTO's located special points and the stability
    changes no located point explains (BP candidates)."""
    rows = parse_b(os.path.join(workdir, "b.branch"))
    mult = parse_d(os.path.join(workdir, "d.branch"))
    key_last = "max_u2" if n_bodies == 2 else "max_uN"
    branch = []
    special = []
    for r in rows:
        pt = abs(r["pt"])
        mu = mult.get(pt)
        nt = nontrivial(mu[1]) if mu else []
        b = {
            "omega_over_omega0": r["par1"],
            "max_u1": GAP * max(abs(r["maxx1"]), abs(r["minx1"])),
            key_last: GAP * max(abs(r["maxx2"]), abs(r["minx2"])),
            "stable": r["pt"] < 0,
            "max_abs_multiplier": max((cabs(z) for z in nt), default=None),
            "unstable_multipliers": (ndim - mu[0]) if mu else None,
            "pt": pt,
        }
        if "defect" in r:
            b["symmetry_defect"] = r["defect"]
        branch.append(b)
        t = TYPES.get(r["ty"])
        if t in KINDS:
            special.append({"kind": KINDS[t], "parameter_over_omega0": r["par1"],
                            "label": r["lab"], "auto_type": t, "pt": pt, "run": "branch",
                            "located": True, "symmetric": defect_of(r) < sym_tol})

    # ---- stability changes not explained by a located special point ---------
    candidates = []
    prev = None
    for b in branch:
        if prev is not None and b["unstable_multipliers"] is not None \
                and prev["unstable_multipliers"] is not None \
                and b["unstable_multipliers"] != prev["unstable_multipliers"]:
            explained = any(prev["pt"] < s["pt"] <= b["pt"] or s["pt"] == prev["pt"]
                            for s in special)
            if not explained:
                kind = crossing_kind(mult[prev["pt"]][1], mult[b["pt"]][1],
                                     prev["unstable_multipliers"], b["unstable_multipliers"])
                candidates.append({"pt_before": prev["pt"], "pt_after": b["pt"],
                                   "w_before": prev["omega_over_omega0"],
                                   "w_after": b["omega_over_omega0"], "kind": kind,
                                   "unstable_before": prev["unstable_multipliers"],
                                   "unstable_after": b["unstable_multipliers"]})
        prev = b
    return rows, mult, branch, special, candidates


def locate(args, exe, exe_name, workdir, irs, icp_out, common, c_branch, candidates, tmo):
    """Step 3: rerun of the branch with user points before the candidates, then
    one short run with BP detection on from each. Returns (seconds, located)."""
    t_bp = 0.0
    located_bps = []
    ws = [c["w_before"] for c in candidates]
    dt, _ = run_exe(exe, workdir, c_branch("branchuz", uzr=ws, irs=irs), "branchuz", tmo)
    t_bp += dt
    # labelled points of the rerun (the UZ points; AUTO may type one as LP/TR/...)
    uzrows = [r for r in parse_b(os.path.join(workdir, "b.branchuz")) if r["lab"] > 0]
    for c in candidates:
        # the label nearest w_before
        lab = None
        # (on a folded branch the same Omega is crossed more than once: the
        # crossing nearest in step number)
        near = [r for r in uzrows if abs(r["par1"] - c["w_before"]) < 1e-4]
        if near:
            lab = min(near, key=lambda r: abs(abs(r["pt"]) - c["pt_before"]))["lab"]
        c["restart_label"] = lab
        if lab is None:
            continue
        name = "bp%d" % len(located_bps)
        sgn = 1.0 if c["w_after"] >= c["w_before"] else -1.0
        text = constants(e=exe_name, s="branchuz", sv=name, IRS=lab,
                         ICP=f"[1, 11, {icp_out}]", NMX=200, DS=sgn * args.ds_locate,
                         DSMAX=args.dsmax, SP="['BP1']",
                         UZSTOP="{1: [%.12g, %.12g]}" % (args.wmin, args.wmax), **common)
        dt, _ = run_exe(exe, workdir, text, name, tmo)
        t_bp += dt
        found = [r for r in parse_b(os.path.join(workdir, f"b.{name}"))
                 if TYPES.get(r["ty"]) in ("BP", "LP", "PD", "TR")]
        w_lim = c["w_after"] + 0.5 * (c["w_after"] - c["w_before"]) + sgn * 1e-6
        if found and sgn * found[0]["par1"] <= sgn * w_lim:
            f = found[0]
            t = TYPES[f["ty"]]
            located_bps.append({"kind": KINDS[t], "parameter_over_omega0": f["par1"],
                                "label": f["lab"], "auto_type": t, "run": name,
                                "located": True, "between_branch_pts": [c["pt_before"], c["pt_after"]],
                                "restart": f"s.branchuz label {lab}",
                                "symmetric": defect_of(f) < args.sym_tol})
            c["located"] = located_bps[-1]["parameter_over_omega0"]
    return t_bp, located_bps


def run_all(args, n_bodies, ndim, exe_name, exe, icp_out, workdir):
    ICP_OUT = icp_out  # noqa: N806 (shadows the module constant for this run)
    tmo = args.timeout
    key_last = "max_u2" if n_bodies == 2 else "max_uN"

    common = dict(NDIM=ndim, NTST=args.ntst, NCOL=args.ncol, EPSL=args.eps, EPSU=args.eps, EPSS=args.epss,
                  DSMIN=args.dsmin)
    pre = abs(args.start - 0.5) > 1e-12
    down = args.start > 1.0
    sgn = -1.0 if down else 1.0
    w_end = args.wmin if down else args.wmax
    c_pre = constants(e=exe_name, sv="pre", IRS=0, ICP=f"[1, 11, {ICP_OUT}]", NMX=2000, ISP=0,
                      DS=0.01, DSMAX=0.05, SP="['BP0']", UZSTOP="{1: %.12g}" % args.start, **common)
    if pre:
        c_hom = constants(e=exe_name, s="pre", sv="hom", IRS="PRE_LABEL", ICP=f"[2, 11, {ICP_OUT}]",
                          NMX=500, DS=0.01, DSMAX=0.1, UZSTOP="{2: %.12g}" % AS, **common)
    else:
        c_hom = constants(e=exe_name, sv="hom", IRS=0, ICP=f"[2, 11, {ICP_OUT}]", NMX=500,
                          DS=0.01, DSMAX=0.1, UZSTOP="{2: %.12g}" % AS, **common)

    def c_branch(name, uzr=None, irs=None, sp="['BP0']"):
        kw = dict(e=exe_name, s="hom", sv=name, IRS=irs, ICP=f"[1, 11, {ICP_OUT}]", NMX=args.nmx,
                  DS=sgn * args.ds, DSMAX=args.dsmax,
                  UZSTOP="{1: [%.12g, %.12g]}" % (args.wmin, args.wmax), **common)
        if sp:
            kw["SP"] = sp
        if uzr:
            kw["UZR"] = "{1: [%s]}" % ", ".join("%.12g" % w for w in uzr)
        return constants(**kw)

    # ---- runs 1 + 2, timed (and 3, with --repeat-location) ----------------------
    times = []
    totals = []
    timed_out = False
    nrep = max(1, args.repeats)
    for rep_i in range(nrep):
        t_pre = 0.0
        if pre:
            t_pre, _ = run_exe(exe, workdir, c_pre, "pre", tmo)
            lab = label_of(parse_b(os.path.join(workdir, "b.pre")), "UZ")
            if lab is None:
                raise RuntimeError("the rest solution did not reach --start")
            t_hom, _ = run_exe(exe, workdir, c_hom.replace("PRE_LABEL", str(lab)), "hom", tmo)
            t_hom += t_pre
        else:
            t_hom, _ = run_exe(exe, workdir, c_hom, "hom", tmo)
        irs = label_of(parse_b(os.path.join(workdir, "b.hom")), "UZ")
        if irs is None:
            raise RuntimeError("homotopy in the amplitude did not reach A")
        try:
            t_br, out_br = run_exe(exe, workdir, c_branch("branch", irs=irs,
                                                          sp="['BP']" if args.bp_detection else "['BP0']"),
                                   "branch", tmo)
        except AutoTimeout:
            # keep what AUTO wrote so far (b/d files are written as it goes)
            timed_out = True
            t_br = tmo
            times.append((t_hom + t_br, t_hom, t_br))
            rows, mult, branch, special, candidates = analyse(workdir, ndim, n_bodies, args.sym_tol)
            t_bp, located_bps = 0.0, []
            totals.append(t_hom + t_br)
            break
        times.append((t_hom + t_br, t_hom, t_br))
        if args.repeat_location or rep_i == nrep - 1:
            rows, mult, branch, special, candidates = analyse(workdir, ndim, n_bodies, args.sym_tol)
            t_bp, located_bps = 0.0, []
            if candidates and not args.no_locate_bp and not args.bp_detection and not timed_out:
                t_bp, located_bps = locate(args, exe, exe_name, workdir, irs, ICP_OUT, common,
                                           c_branch, candidates, tmo)
            totals.append(t_hom + t_br + t_bp)
    best = min(times)
    hom_rows = parse_b(os.path.join(workdir, "b.hom"))
    for c in candidates:
        if "located" not in c:
            special.append({"kind": c["kind"], "parameter_over_omega0": 0.5 * (c["w_before"] + c["w_after"]),
                            "label": None, "auto_type": None, "run": "branch", "located": False,
                            "between_branch_pts": [c["pt_before"], c["pt_after"]],
                            "omega_interval": [c["w_before"], c["w_after"]]})
    special.extend(located_bps)
    special.sort(key=lambda s: s["pt"] if "pt" in s else s["between_branch_pts"][1])

    # ---- 4. secondary branches (information) ---------------------------------
    secondary = []
    t_sec = 0.0
    if args.secondary:
        for i, bp in enumerate(located_bps):
            if bp["auto_type"] != "BP":
                continue
            for sign in (1,):  # ISW=-1 picks the direction itself; -1 gave the same branch
                name = f"sec{i}{'p' if sign > 0 else 'm'}"
                text = constants(e=exe_name, s=bp["run"], sv=name, IRS=bp["label"], ISW=-1,
                                 ICP=f"[1, 11, {ICP_OUT}]", NMX=args.secondary_nmx,
                                 DS=sign * args.ds, DSMAX=args.dsmax, SP="['BP0']",
                                 UZSTOP="{1: [0.45, 1.55]}", **common)
                try:
                    dt, _ = run_exe(exe, workdir, text, name)
                except RuntimeError as e:
                    secondary.append({"from": bp["parameter_over_omega0"], "direction": sign,
                                      "error": str(e)})
                    continue
                t_sec += dt
                srows = parse_b(os.path.join(workdir, f"b.{name}"))
                sp = [{"kind": KINDS[TYPES[r["ty"]]], "parameter_over_omega0": r["par1"],
                       "label": r["lab"]} for r in srows if TYPES.get(r["ty"]) in KINDS]
                secondary.append({
                    "from_bp": bp["parameter_over_omega0"], "direction": sign, "run": name,
                    "points": len(srows), "seconds": dt,
                    "omega_range": [min(r["par1"] for r in srows), max(r["par1"] for r in srows)],
                    "end": TYPES.get(srows[-1]["ty"]), "end_omega": srows[-1]["par1"],
                    "special_points": sp,
                    # every 5th point and every labelled one, 7 digits (information only)
                    "branch": [{"omega_over_omega0": float("%.7g" % r["par1"]),
                                "max_u1": float("%.7g" % (GAP * max(abs(r["maxx1"]), abs(r["minx1"])))),
                                key_last: float("%.7g" % (GAP * max(abs(r["maxx2"]), abs(r["minx2"])))),
                                "stable": r["pt"] < 0}
                               for k, r in enumerate(srows) if k % 5 == 0 or r["lab"] > 0],
                })

    last = rows[-1]
    peak = max(branch, key=lambda b: max(b["max_u1"], b[key_last]))
    defects = [defect_of(r) for r in rows]
    asym = [r["par1"] for r, d in zip(rows, defects) if not d < args.sym_tol]
    reached = (not timed_out and TYPES.get(last["ty"]) == "UZ"
               and abs(last["par1"] - w_end) < 1e-6)
    stab_int = []
    for b in branch:
        if stab_int and stab_int[-1]["stable"] == b["stable"]:
            stab_int[-1]["to"] = b["omega_over_omega0"]
        else:
            stab_int.append({"stable": b["stable"], "from": b["omega_over_omega0"],
                             "to": b["omega_over_omega0"]})
    result = {
        "solver": "AUTO-07p 0.9.2 (Debian auto-07p), IPS=2 orthogonal collocation",
        "seconds": best[0],
        "seconds_hom": best[1],
        "seconds_branch": best[2],
        "seconds_all_repeats": [t[0] for t in times],
        "repeats": len(times),
        "omp_num_threads": args.threads,
        "n": n_bodies,
        "exe": exe_name,
        "points": abs(last["pt"]),
        "points_hom": abs(hom_rows[-1]["pt"]),
        "end": {"type": TYPES.get(last["ty"]), "omega_over_omega0": last["par1"]},
        "reached_wmax": reached,
        "timed_out": timed_out,
        "nan_points": sum(1 for r in rows if r["par1"] != r["par1"]),
        "max_symmetry_defect": max((d if d == d else float("inf")) for d in defects),
        "first_asymmetric_omega": asym[0] if asym else None,
        "symmetric_to_wmax": reached and not asym,
        "settings": {"NTST": args.ntst, "NCOL": args.ncol, "IAD": 3, "ISP": 2, "ILP": 1,
                     "DS": args.ds, "DSMIN": args.dsmin, "DSMAX": args.dsmax,
                     "EPSL": args.eps, "EPSU": args.eps, "EPSS": args.epss, "JAC": 1,
                     "NMX": args.nmx, "SP": "['BP']" if args.bp_detection else "['BP0']",
                     "start": args.start, "wmin": args.wmin, "wmax": args.wmax},
        "seconds_bp_location": t_bp,
        "seconds_total": min(totals),
        "seconds_total_all_repeats": totals,
        "bp_candidates": candidates,
        "special_points": special,
        "stability_intervals": stab_int,
        "peak": {"omega_over_omega0": peak["omega_over_omega0"],
                 "max_u1": peak["max_u1"], key_last: peak[key_last]},
        "units": "max_u in m; omega in omega0 = 7.41 rad/s; clearance g = 1e-3 m",
    }
    if not args.no_branch:
        result["branch"] = branch
    if args.secondary:
        result["secondary"] = secondary
        result["seconds_secondary"] = t_sec
    print(json.dumps(result, separators=(",", ":")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
