#!/usr/bin/env python3
"""One-run comparison of our continuation of the R2 N = 2 frequency-response
branch against the peers AUTO-07p (run_auto.py) and a SciPy brute-force sweep
(sweep_scipy.py) of the same resolution. Standard library only (the SciPy part
runs in bench/auto/build/venv).

  python3 bench/auto/compare_branch.py [--no-build] [--repeats 3]
      [--scipy-sample M | --no-scipy] [--out FILE]

Steps (sequential, so that the timings do not disturb each other):
  1. cargo build --release -p vibroimpact-cli (unless --no-build); then
     target/release/vibroimpact continue MODEL --parameter frequency
     --from 0.5*omega0 --to 1.5*omega0 --format json, --repeats times; our time
     is the best wall time of the whole process (start simulation, shooting,
     continuation with Floquet multipliers at every point, location of the
     special points, JSON output).
  2. python3 run_auto.py --repeats R: AUTO's time for the same job is
     "seconds" (best of R runs of homotopy + branch) + "seconds_bp_location"
     (locating the branch points; one run); "seconds" alone is reported too.
  3. sweep_scipy.py with K = number of points of our branch, from rest, K
     frequencies evenly spread over [0.5, 1.5] omega0; its "seconds_total"
     (solve_ivp time summed over the frequencies). With --scipy-sample M only
     M frequencies are run and the time is extrapolated to K (marked
     "extrapolated" everywhere).
  4. Special points: every AUTO special point is matched to the nearest
     unmatched one of ours of the same kind (AUTO TR = our neimark-sacker)
     within --match-tol (Omega/omega0); unmatched ones of both sides are
     listed; our grazing points separately (AUTO has no grazing detection).
  5. Branch: our max_displacement (body 1, 2) interpolated (cubic Lagrange on
     4 neighbouring points, only inside a run of our points that is monotone
     in Omega, i.e. where our branch is single-valued) at AUTO's branch
     points; max relative difference, where, and the interpolation-error
     estimate (cubic - linear) there. Stability: intervals with the number of
     multipliers outside the unit circle on both sides, their boundaries
     (bracketing points and the located special point inside), and the AUTO
     points whose stability differs from ours.
  6. A table on stdout and one JSON document to --out (default
     bench/auto/results/compare-<date>.json); next to it the raw outputs:
     <stem>.ours.json, <stem>.auto.json, <stem>.scipy.jsonl (+ .summary.json).
Progress goes to stderr.
"""
import argparse
import bisect
import datetime
import hashlib
import json
import math
import os
import platform
import resource
import subprocess
import sys
import time

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
GAP = 1.0e-3
TARGET_AUTO = 3.0
TARGET_SCIPY = 100.0


def log(msg):
    sys.stderr.write("compare_branch: %s\n" % msg)
    sys.stderr.flush()


def cpu_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_timed(cmd, cwd=ROOT, env=None, stdout=subprocess.PIPE, stderr=subprocess.PIPE):
    """Run CMD; returns (wall seconds, cpu seconds of the children, CompletedProcess)."""
    c0 = cpu_children()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, stdout=stdout, stderr=stderr, text=True)
    dt = time.perf_counter() - t0
    return dt, cpu_children() - c0, p


def sh(cmd, cwd=ROOT):
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
        return p.stdout.rstrip("\n") if p.returncode == 0 else None
    except OSError:
        return None


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def omega0_of(model):
    if tomllib is None:
        return 7.41
    with open(model, "rb") as f:
        d = tomllib.load(f)
    row = d.get("row", {})
    if "natural_frequency" in row:
        return float(row["natural_frequency"])
    return math.sqrt(float(row["stiffness"]) / float(row["mass"]))


# run by the venv python: one period of each of our orbits with SciPy DOP853
ORBIT_CHECK = r"""
import json, math, sys
import numpy as np
from scipy.integrate import solve_ivp
sys.path.insert(0, sys.argv[1])
import sweep_scipy as S
out = []
for o in json.load(sys.stdin):
    om = o["omega"]; T = 2 * math.pi / om; y0 = np.array(o["state"])
    sol = solve_ivp(S.make_rhs(2, om, [0]), (0, T), y0, method="DOP853", rtol=1e-12, atol=1e-15,
                    dense_output=True)
    u = sol.sol(np.linspace(0, T, 200001))[:2]
    m = np.maximum(np.abs(u).max(axis=1), np.abs(sol.y[:2]).max(axis=1))
    sc = np.array([S.GAP, S.GAP, S.GAP * S.OMEGA0, S.GAP * S.OMEGA0])
    out.append({"omega": om, "periodicity_residual": float((np.abs(sol.y[:, -1] - y0) / sc).max()),
                "max_u_scipy": [float(x) for x in m], "max_u_ours": o["ours"],
                "rel_diff_max_u": float(max(abs(a / b - 1) for a, b in zip(o["ours"], m)))})
print(json.dumps(out))
"""


# ---------------------------------------------------------------------------
# interpolation on our branch
# ---------------------------------------------------------------------------

def monotone_runs(ws):
    """Maximal index ranges [i0, i1] on which ws is strictly monotone."""
    runs = []
    i0 = 0
    direction = 0
    for i in range(1, len(ws)):
        d = (ws[i] > ws[i - 1]) - (ws[i] < ws[i - 1])
        if d == 0 or (direction and d != direction):
            runs.append((i0, i - 1))
            i0 = i - 1 if d != 0 else i
            direction = d
        else:
            direction = d
    runs.append((i0, len(ws) - 1))
    return [r for r in runs if r[1] > r[0]]


def lagrange(xs, ys, x):
    s = 0.0
    for j, (xj, yj) in enumerate(zip(xs, ys)):
        l = 1.0
        for m, xm in enumerate(xs):
            if m != j:
                l *= (x - xm) / (xj - xm)
        s += l * yj
    return s


class Branch:
    """Our branch as a function of W, where single-valued."""

    def __init__(self, ws, values):
        self.ws = ws
        self.values = values  # list of tuples per point
        self.runs = monotone_runs(ws)

    def covering(self, w):
        """Intervals (i, i+1) containing w, over the whole branch."""
        out = []
        for i in range(len(self.ws) - 1):
            a, b = self.ws[i], self.ws[i + 1]
            if min(a, b) <= w <= max(a, b):
                out.append(i)
        return out

    def at(self, w):
        """(cubic values, linear values, stencil) or None if not single-valued here."""
        cov = self.covering(w)
        # w exactly at a point shared by two intervals counts once
        cov = sorted(set(cov))
        if len(cov) == 2 and cov[1] == cov[0] + 1 and self.ws[cov[1]] == w:
            cov = [cov[1]]
        if len(cov) != 1:
            return None
        i = cov[0]
        run = next((r for r in self.runs if r[0] <= i and i + 1 <= r[1]), None)
        if run is None:
            return None
        # the neighbourhood must be monotone too: stencil i-1 .. i+2 inside the run
        lo, hi = max(run[0], i - 1), min(run[1], i + 2)
        if hi - lo < 3:  # near an end or a fold: shift the stencil inside the run
            lo = max(run[0], min(lo, hi - 3))
            hi = min(run[1], lo + 3)
        a, b = self.ws[i], self.ws[i + 1]
        f = (w - a) / (b - a)
        lin = tuple(va + f * (vb - va) for va, vb in zip(self.values[i], self.values[i + 1]))
        if hi - lo == 3:
            xs = self.ws[lo:hi + 1]
            cub = tuple(lagrange(xs, [v[k] for v in self.values[lo:hi + 1]], w)
                        for k in range(len(lin)))
        else:
            cub = lin
        return cub, lin, (lo, hi)


# ---------------------------------------------------------------------------
# stability
# ---------------------------------------------------------------------------

def count_runs(seq):
    """seq of (w, n) -> [{"from", "to", "unstable_multipliers"}] (by points)."""
    out = []
    for w, n in seq:
        if out and out[-1]["unstable_multipliers"] == n:
            out[-1]["to"] = w
        else:
            out.append({"from": w, "to": w, "unstable_multipliers": n})
    return out


def boundaries(runs, specials):
    """Stability-count changes: bracket between the last point of one run and the
    first of the next, with the special points inside the bracket."""
    out = []
    for a, b in zip(runs, runs[1:]):
        lo, hi = a["to"], b["from"]
        inside = [s for s in specials if min(lo, hi) - 1e-12 <= s[1] <= max(lo, hi) + 1e-12]
        out.append({"bracket": [lo, hi], "unstable_before": a["unstable_multipliers"],
                    "unstable_after": b["unstable_multipliers"],
                    "special_points": [{"kind": k, "omega_over_omega0": w, "label": lab}
                                       for k, w, lab in inside]})
    return out


def stable_intervals(runs):
    out = []
    for r in runs:
        st = r["unstable_multipliers"] == 0
        if out and out[-1]["stable"] == st:
            out[-1]["to"] = r["to"]
        else:
            out.append({"stable": st, "from": r["from"], "to": r["to"]})
    return out


# ---------------------------------------------------------------------------

def fmt_s(x):
    return "-" if x is None else ("%.3g s" % x if x < 100 else "%.0f s" % x)


def main(argv):
    today = datetime.date.today().isoformat()
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=os.path.join(ROOT, "examples", "fujita-row-n2.toml"))
    ap.add_argument("--wmin", type=float, default=0.5, help="Omega/omega0 start")
    ap.add_argument("--wmax", type=float, default=1.5, help="Omega/omega0 end")
    ap.add_argument("--no-build", action="store_true", help="do not run cargo build")
    ap.add_argument("--repeats", type=int, default=3,
                    help="runs of our continuation, and --repeats of run_auto.py")
    ap.add_argument("--scipy-sample", type=int, default=None, metavar="M",
                    help="time only M sweep frequencies and extrapolate to K")
    ap.add_argument("--no-scipy", action="store_true", help="skip the SciPy sweep")
    ap.add_argument("--match-tol", type=float, default=0.02,
                    help="max |difference| in Omega/omega0 for matching special points")
    ap.add_argument("--check-orbits", type=int, default=11,
                    help="integrate this many of our orbits with SciPy as a check (0: off)")
    ap.add_argument("--auto-args", default="", help="extra arguments for run_auto.py (one string)")
    ap.add_argument("--out", default=os.path.join(HERE, "results", f"compare-{today}.json"))
    args = ap.parse_args(argv[1:])

    out_path = os.path.abspath(args.out)
    stem = out_path[:-5] if out_path.endswith(".json") else out_path
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    omega0 = omega0_of(args.model)
    p_from, p_to = args.wmin * omega0, args.wmax * omega0
    build = os.path.join(HERE, "build")
    venv_py = os.path.join(build, "venv", "bin", "python")
    loads = {}

    # ---- 0. peers built? ----------------------------------------------------
    need = not os.path.exists(os.path.join(build, "r2n2.exe")) or \
        (not args.no_scipy and not os.path.exists(venv_py))
    if need:
        log("peers missing: running bench/auto/build.sh")
        p = subprocess.run([os.path.join(HERE, "build.sh")] + ([] if not args.no_scipy else ["--no-python"]),
                           cwd=ROOT)
        if p.returncode != 0:
            log("build.sh failed")
            return 2

    # ---- 1. ours ------------------------------------------------------------
    if not args.no_build:
        log("cargo build --release -p vibroimpact-cli")
        for attempt in range(6):
            p = subprocess.run(["cargo", "build", "--release", "-p", "vibroimpact-cli"], cwd=ROOT,
                               capture_output=True, text=True)
            if p.returncode == 0:
                break
            log("cargo build failed (attempt %d; concurrent edits?), retrying in 60 s:\n%s"
                % (attempt + 1, p.stderr[-2000:]))
            time.sleep(60)
        else:
            log("cargo build keeps failing; giving up")
            return 2
    exe = os.path.join(ROOT, "target", "release", "vibroimpact")
    cmd_ours = [exe, "continue", os.path.relpath(args.model, ROOT), "--parameter", "frequency",
                "--from", "%.6g" % p_from, "--to", "%.6g" % p_to, "--format", "json"]
    loads["ours"] = os.getloadavg()
    ours_times, ours_cpu, ours = [], [], None
    for r in range(max(1, args.repeats)):
        dt, cpu, p = run_timed(cmd_ours)
        if p.returncode != 0:
            log("our continuation failed (exit %d):\n%s" % (p.returncode, p.stderr[-3000:]))
            return 2
        ours_times.append(dt)
        ours_cpu.append(cpu)
        if ours is None:
            ours_text = p.stdout
            ours = json.loads(p.stdout)
        log("ours run %d: %.3f s wall, %.3f s cpu" % (r + 1, dt, cpu))
    with open(stem + ".ours.json", "w") as f:
        f.write(ours_text)
    t_ours = min(ours_times)
    pts = ours["points"]
    K = len(pts)
    ours_w = [p["parameter"] / omega0 for p in pts]

    # ---- 2. AUTO ------------------------------------------------------------
    cmd_auto = [sys.executable, os.path.join(HERE, "run_auto.py"), "--repeats", str(args.repeats),
                "--workdir", os.path.join(build, "run-compare")] + args.auto_args.split()
    log("AUTO-07p: " + " ".join(cmd_auto[1:]))
    loads["auto"] = os.getloadavg()
    dt_auto_proc, cpu_auto_proc, p = run_timed(cmd_auto)
    if p.returncode != 0:
        log("run_auto.py failed (exit %d):\n%s" % (p.returncode, p.stderr[-3000:]))
        return 2
    auto_line = p.stdout.strip().splitlines()[-1]
    auto = json.loads(auto_line)
    with open(stem + ".auto.json", "w") as f:
        f.write(auto_line + "\n")
    t_auto_branch = auto["seconds"]
    t_auto_bp = auto.get("seconds_bp_location") or 0.0
    t_auto = t_auto_branch + t_auto_bp
    log("AUTO: %.3f s branch + %.3f s BP location (process %.1f s)" % (t_auto_branch, t_auto_bp, dt_auto_proc))

    # ---- 3. SciPy -----------------------------------------------------------
    scipy_res = None
    if not args.no_scipy:
        M = args.scipy_sample or K
        extrap = args.scipy_sample is not None and M != K
        sweep_out = stem + ".scipy.jsonl"
        cmd_sc = [venv_py, os.path.join(HERE, "sweep_scipy.py"), "--k", str(M),
                  "--wmin", repr(args.wmin), "--wmax", repr(args.wmax), "--out", sweep_out]
        log("SciPy sweep, %d frequencies%s (about %.0f-%.0f min): %s"
            % (M, " (sample, extrapolated to %d)" % K if extrap else "", M * 4.4 / 60, M * 7.2 / 60,
               " ".join(cmd_sc[1:])))
        loads["scipy"] = os.getloadavg()
        # the sweep's per-frequency progress goes straight to our stderr
        dt_sc_proc, cpu_sc_proc, p = run_timed(cmd_sc, stderr=None)
        if p.returncode != 0:
            log("sweep_scipy.py failed (exit %d)" % p.returncode)
            return 2
        summ = json.loads(p.stdout.strip().splitlines()[-1])
        with open(stem + ".scipy.summary.json", "w") as f:
            f.write(json.dumps(summ) + "\n")
        rows = [json.loads(l) for l in open(sweep_out)]
        t_meas = summ["seconds_total"]
        t_sc = t_meas * K / M if extrap else t_meas
        # where the sweep reached a period-1 state and our branch is stable there:
        # agreement of max|u| (information)
        ob = Branch(ours_w, [tuple(p["max_displacement"]) + (1.0 if p["stable"] else 0.0,) for p in pts])
        agree = []
        for r in rows:
            v = ob.at(r["omega_over_omega0"])
            if r["period"] == 1 and v and v[1][2] == 1.0:
                rel = max(abs(r["max_u"][k] - v[0][k]) / v[0][k] for k in (0, 1))
                agree.append((rel, r["omega_over_omega0"]))
        scipy_res = {
            "frequencies_run": M, "frequencies_branch": K, "extrapolated": extrap,
            "seconds_measured": t_meas,
            "seconds": t_sc,
            "seconds_per_frequency_mean": summ["seconds_per_frequency_mean"],
            "seconds_per_frequency_min": summ["seconds_per_frequency_min"],
            "seconds_per_frequency_max": summ["seconds_per_frequency_max"],
            "seconds_process_wall": dt_sc_proc, "seconds_process_cpu": cpu_sc_proc,
            "start": summ["start"], "periods_transient": summ["periods_transient"],
            "periods_recorded": summ["periods_recorded"], "rtol": summ["rtol"], "atol": summ["atol"],
            "rhs_evaluations_total": summ["rhs_evaluations_total"], "steps_total": summ["steps_total"],
            "steady_count": summ["steady_count"], "period_counts": summ["period_counts"],
            "period1_on_our_stable_branch": {
                "count": len(agree),
                "max_rel_diff_max_u": max(agree)[0] if agree else None,
                "at_omega_over_omega0": max(agree)[1] if agree else None,
            },
            "solver": summ["solver"], "raw": os.path.basename(sweep_out),
        }
        log("SciPy: %.1f s measured for %d frequencies%s" % (t_meas, M, ", %.1f s extrapolated to %d" % (t_sc, K) if extrap else ""))

    # ---- 4. special points --------------------------------------------------
    ours_sp = [{"kind": s["kind"], "label": s["label"], "omega_over_omega0": s["parameter"] / omega0,
                "symmetry_breaking": s.get("symmetry_breaking")} for s in ours["special_points"]]
    auto_sp = [{"kind": s["kind"], "auto_type": s.get("auto_type"), "label": s.get("label"),
                "run": s.get("run"), "located": s.get("located", True),
                "omega_over_omega0": s["parameter_over_omega0"]} for s in auto["special_points"]]
    grazing = [s for s in ours_sp if s["kind"] == "grazing"]
    ours_cmp = [s for s in ours_sp if s["kind"] != "grazing"]
    pairs = sorted(((abs(a["omega_over_omega0"] - o["omega_over_omega0"]), ia, io)
                    for ia, a in enumerate(auto_sp) for io, o in enumerate(ours_cmp)
                    if a["kind"] == o["kind"]), key=lambda t: t[0])
    used_a, used_o, match = set(), set(), {}
    for d, ia, io in pairs:
        if d <= args.match_tol and ia not in used_a and io not in used_o:
            used_a.add(ia)
            used_o.add(io)
            match[ia] = io
    sp_table = []
    for ia, a in enumerate(auto_sp):
        o = ours_cmp[match[ia]] if ia in match else None
        sp_table.append({"kind": a["kind"], "auto_type": a["auto_type"],
                         "auto_omega_over_omega0": a["omega_over_omega0"], "auto_located": a["located"],
                         "auto_run_label": "%s %s" % (a["run"], a["label"]),
                         "ours_label": o["label"] if o else None,
                         "ours_omega_over_omega0": o["omega_over_omega0"] if o else None,
                         "ours_symmetry_breaking": o["symmetry_breaking"] if o else None,
                         "difference": (o["omega_over_omega0"] - a["omega_over_omega0"]) if o else None})
    unmatched_auto = [a for ia, a in enumerate(auto_sp) if ia not in match]
    unmatched_ours = [o for io, o in enumerate(ours_cmp) if io not in used_o]
    for u in unmatched_auto:  # nearest of ours of any kind, as a hint
        near = min(ours_sp, key=lambda o: abs(o["omega_over_omega0"] - u["omega_over_omega0"]), default=None)
        u["nearest_ours_any_kind"] = near
    diffs = [abs(r["difference"]) for r in sp_table if r["difference"] is not None]

    # ---- 5. branch ----------------------------------------------------------
    ob = Branch(ours_w, [tuple(p["max_displacement"]) for p in pts])
    worst = None
    rels = []
    skipped_range, skipped_multi = 0, 0
    exact = []
    for b in auto["branch"]:
        w = b["omega_over_omega0"]
        if w < min(ours_w) or w > max(ours_w):
            skipped_range += 1
            continue
        v = ob.at(w)
        if v is None:
            skipped_multi += 1
            continue
        cub, lin, _ = v
        av = (b["max_u1"], b["max_u2"])
        for k in (0, 1):
            rel = abs(cub[k] - av[k]) / abs(av[k])
            rels.append(rel)
            item = (rel, w, k + 1, cub[k], av[k], abs(cub[k] - lin[k]) / abs(av[k]))
            if worst is None or rel > worst[0]:
                worst = item
        j = min(range(len(ours_w)), key=lambda i: abs(ours_w[i] - w))
        if abs(ours_w[j] - w) < 1e-9:
            exact.append({"omega_over_omega0": w,
                          "rel_diff": [abs(pts[j]["max_displacement"][k] - av[k]) / av[k] for k in (0, 1)]})
    rels_sorted = sorted(rels)

    def pct(q):
        return rels_sorted[min(len(rels_sorted) - 1, int(q * len(rels_sorted)))] if rels_sorted else None

    # stability
    def n_unstable(p):
        return sum(1 for z in p["floquet_multipliers"] if math.hypot(z[0], z[1]) > 1.0)

    # largest multiplier modulus (information): log-linear interpolation between
    # two of our points that have the same number of unstable multipliers as
    # AUTO's point (the modulus is not smooth across a crossing)
    mult_rels = []
    for b in auto["branch"]:
        w = b["omega_over_omega0"]
        if not b.get("max_abs_multiplier") or not (min(ours_w) <= w <= max(ours_w)):
            continue
        cov = [i for i in range(len(ours_w) - 1) if min(ours_w[i], ours_w[i + 1]) <= w <= max(ours_w[i], ours_w[i + 1])]
        if len(cov) != 1:
            continue
        i = cov[0]
        if not (n_unstable(pts[i]) == n_unstable(pts[i + 1]) == b["unstable_multipliers"]):
            continue
        f = (w - ours_w[i]) / (ours_w[i + 1] - ours_w[i])
        m = math.exp((1 - f) * math.log(pts[i]["spectral_radius"]) + f * math.log(pts[i + 1]["spectral_radius"]))
        mult_rels.append((abs(m - b["max_abs_multiplier"]) / b["max_abs_multiplier"], w, m, b["max_abs_multiplier"]))
    mult_worst = max(mult_rels) if mult_rels else None
    mult_median = sorted(r[0] for r in mult_rels)[len(mult_rels) // 2] if mult_rels else None

    ours_runs = count_runs([(w, n_unstable(p)) for w, p in zip(ours_w, pts)])
    auto_runs = count_runs([(b["omega_over_omega0"], b["unstable_multipliers"]) for b in auto["branch"]])
    ours_bd = boundaries(ours_runs, [(s["kind"], s["omega_over_omega0"], s["label"]) for s in ours_sp])
    auto_bd = boundaries(auto_runs, [(s["kind"], s["omega_over_omega0"], "%s %s" % (s["run"], s["label"]))
                                     for s in auto_sp])
    same_sequence = [r["unstable_multipliers"] for r in ours_runs] == [r["unstable_multipliers"] for r in auto_runs]
    sb = Branch(ours_w, [(1.0 if p["stable"] else 0.0,) for p in pts])
    stab_disagree = []
    for b in auto["branch"]:
        if not (min(ours_w) <= b["omega_over_omega0"] <= max(ours_w)):
            continue
        cov = sb.covering(b["omega_over_omega0"])
        if len(cov) == 1:
            i = cov[0]
            if pts[i]["stable"] == pts[i + 1]["stable"] and pts[i]["stable"] != b["stable"]:
                stab_disagree.append(b["omega_over_omega0"])

    # independent check of some of our orbits with SciPy (not timed): integrate one
    # period from our initial_state; periodicity residual and max|u_i| finely sampled
    orbit_check = None
    if args.check_orbits > 0 and os.path.exists(venv_py):
        idx = sorted({round(j * (K - 1) / max(1, args.check_orbits - 1)) for j in range(args.check_orbits)})
        job = [{"omega": pts[i]["parameter"], "state": pts[i]["initial_state"],
                "ours": pts[i]["max_displacement"]} for i in idx]
        p = subprocess.run([venv_py, "-B", "-c", ORBIT_CHECK, HERE], input=json.dumps(job),
                           capture_output=True, text=True)
        if p.returncode == 0:
            orbits = json.loads(p.stdout)
            for o in orbits:
                o["omega_over_omega0"] = o.pop("omega") / omega0
            rr = sorted(o["rel_diff_max_u"] for o in orbits)
            orbit_check = {"rtol": 1e-12, "samples": 200000, "orbits": orbits,
                           "max_periodicity_residual": max(o["periodicity_residual"] for o in orbits),
                           "max_rel_diff_max_u": rr[-1], "median_rel_diff_max_u": rr[len(rr) // 2]}
        else:
            orbit_check = {"error": p.stderr[-1000:]}

    # ---- 6. document --------------------------------------------------------
    rustc = sh(["rustc", "--version"])
    sc_versions = sh([venv_py, "-c", "import scipy, numpy; print(scipy.__version__, numpy.__version__)"]) \
        if os.path.exists(venv_py) else None
    git_status = sh(["git", "status", "--porcelain", "--", "crates", "Cargo.toml", "Cargo.lock",
                     os.path.relpath(args.model, ROOT)])
    ratio_auto = t_auto / t_ours
    ratio_scipy = scipy_res["seconds"] / t_ours if scipy_res else None
    doc = {
        "date": today,
        "timestamp": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "problem": "R2 (docs/theory.md §6), N = 2, periodic-solution branch in Omega from %g to %g omega0, omega0 = %g rad/s"
                   % (args.wmin, args.wmax, omega0),
        "command": " ".join(["python3", os.path.relpath(os.path.abspath(argv[0]), ROOT)] + argv[1:]),
        "times": {
            "ours": {"seconds": t_ours, "seconds_all": ours_times, "cpu_seconds_all": ours_cpu,
                     "what": "best wall time of the whole process over %d runs (start simulation, shooting, "
                             "continuation with Floquet multipliers at every point, special-point location)"
                             % len(ours_times),
                     "points": K, "command": " ".join(os.path.relpath(c, ROOT) if c == exe else c for c in cmd_ours)},
            "auto": {"seconds": t_auto, "seconds_branch": t_auto_branch, "seconds_bp_location": t_auto_bp,
                     "seconds_hom": auto.get("seconds_hom"), "seconds_all_repeats": auto.get("seconds_all_repeats"),
                     "seconds_process_wall": dt_auto_proc, "seconds_process_cpu": cpu_auto_proc,
                     "what": "best of %s runs of homotopy + branch (\"seconds\") + one BP-location pass "
                             "(\"seconds_bp_location\"); OMP_NUM_THREADS=%s" % (auto.get("repeats"), auto.get("omp_num_threads")),
                     "points": auto.get("points"), "reached_wmax": auto.get("reached_wmax")},
            "scipy": scipy_res,
        },
        "ratios": {
            "auto_over_ours": ratio_auto,
            "auto_branch_only_over_ours": t_auto_branch / t_ours,
            "scipy_over_ours": ratio_scipy,
            "scipy_extrapolated": scipy_res["extrapolated"] if scipy_res else None,
            "targets": {"auto_over_ours": TARGET_AUTO, "scipy_over_ours": TARGET_SCIPY},
            "auto_target_met": ratio_auto >= TARGET_AUTO,
            "scipy_target_met": (ratio_scipy >= TARGET_SCIPY) if ratio_scipy is not None else None,
        },
        "special_points": {
            "matched_by": "same kind (AUTO TR = neimark-sacker), nearest first, |dW| <= %g" % args.match_tol,
            "table": sp_table,
            "max_abs_difference": max(diffs) if diffs else None,
            "unmatched_auto": unmatched_auto,
            "unmatched_ours": unmatched_ours,
            "ours_grazing": grazing,
            "ours_all": ours_sp,
        },
        "branch": {
            "what": "our max_displacement interpolated (cubic Lagrange, 4 points of a monotone run) at AUTO's "
                    "branch points; relative to AUTO's max|u_i| (from its collocation points)",
            "auto_points": len(auto["branch"]), "compared": len(rels) // 2,
            "skipped_outside_our_range": skipped_range, "skipped_not_single_valued": skipped_multi,
            "our_range": [min(ours_w), max(ours_w)],
            "max_rel_diff": worst[0] if worst else None,
            "max_rel_diff_at": {"omega_over_omega0": worst[1], "body": worst[2], "ours": worst[3],
                                "auto": worst[4], "interpolation_error_estimate": worst[5]} if worst else None,
            "median_rel_diff": pct(0.5), "p90_rel_diff": pct(0.9), "p99_rel_diff": pct(0.99),
            "at_common_points": exact,
            "largest_multiplier_modulus": {
                "what": "our spectral_radius, log-linear between two points with AUTO's number of unstable "
                        "multipliers, against AUTO's max_abs_multiplier",
                "compared": len(mult_rels), "median_rel_diff": mult_median,
                "max_rel_diff": mult_worst[0], "omega_over_omega0": mult_worst[1],
                "ours": mult_worst[2], "auto": mult_worst[3]} if mult_worst else None,
            "orbit_check": orbit_check,
            "stability": {
                "ours_unstable_count_runs": ours_runs, "auto_unstable_count_runs": auto_runs,
                "same_sequence_of_unstable_counts": same_sequence,
                "ours_boundaries": ours_bd, "auto_boundaries": auto_bd,
                "ours_stable_intervals": stable_intervals(ours_runs),
                "auto_stable_intervals": stable_intervals(auto_runs),
                "auto_points_with_other_stability": stab_disagree,
            },
        },
        "settings": {
            "ours": {"model": os.path.relpath(args.model, ROOT), "model_sha256": sha256(args.model),
                     "from_rad_s": p_from, "to_rad_s": p_to, "symmetric": ours.get("symmetric"),
                     "stop": ours.get("stop"), "binary_sha256": sha256(exe)},
            "auto": auto.get("settings"), "auto_solver": auto.get("solver"),
            "scipy": {"k": scipy_res["frequencies_run"], "start": scipy_res["start"],
                      "p1": scipy_res["periods_transient"], "p2": scipy_res["periods_recorded"],
                      "rtol": scipy_res["rtol"], "atol": scipy_res["atol"]} if scipy_res else None,
            "repeats": args.repeats,
        },
        "versions": {
            "auto-07p": sh(["dpkg-query", "-W", "-f=${Version}", "auto-07p"]),
            "gfortran": sh(["dpkg-query", "-W", "-f=${Version}", "gfortran"]),
            "scipy_numpy": sc_versions,
            "rustc": rustc,
            "python": platform.python_version(),
            "vibroimpact_git": sh(["git", "rev-parse", "HEAD"]),
            "vibroimpact_uncommitted": git_status.splitlines() if git_status else [],
        },
        "machine": {"cpus": os.cpu_count(), "loadavg_before": loads, "platform": platform.platform()},
        "raw_outputs": [os.path.basename(stem + x) for x in (".ours.json", ".auto.json")] +
                       ([os.path.basename(stem + x) for x in (".scipy.jsonl", ".scipy.summary.json")]
                        if scipy_res else []),
    }
    with open(out_path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")

    # ---- table --------------------------------------------------------------
    P = print
    P("R2, N = 2: branch in Omega/omega0 from %g to %g (omega0 = %g rad/s), %s" % (args.wmin, args.wmax, omega0, today))
    P("")
    P("Times (wall)")
    P("  ours   %-10s best of %d (%s); %d points, %d special points"
      % (fmt_s(t_ours), len(ours_times), ", ".join("%.3f" % t for t in ours_times), K, len(ours_sp)))
    P("  AUTO   %-10s = %.3f s branch (best of %s) + %.3f s BP location; %s steps"
      % (fmt_s(t_auto), t_auto_branch, auto.get("repeats"), t_auto_bp, auto.get("points")))
    if scipy_res:
        P("  SciPy  %-10s %s (%d frequencies%s, %.2f s per frequency)"
          % (fmt_s(scipy_res["seconds"]), "EXTRAPOLATED from %.1f s" % scipy_res["seconds_measured"]
             if scipy_res["extrapolated"] else "measured", scipy_res["frequencies_run"],
             ", extrapolated to %d" % K if scipy_res["extrapolated"] else "",
             scipy_res["seconds_per_frequency_mean"]))
    else:
        P("  SciPy  not run")
    P("")
    P("Ratios (target)")
    P("  AUTO / ours              %6.2f  (>= %g: %s)" % (ratio_auto, TARGET_AUTO,
                                                         "met" if ratio_auto >= TARGET_AUTO else "MISSED"))
    P("  AUTO branch only / ours  %6.2f" % (t_auto_branch / t_ours))
    if ratio_scipy is not None:
        P("  SciPy / ours            %7.0f  (>= %g: %s)%s" % (ratio_scipy, TARGET_SCIPY,
                                                            "met" if ratio_scipy >= TARGET_SCIPY else "MISSED",
                                                            "  [extrapolated]" if scipy_res["extrapolated"] else ""))
    P("")
    P("Special points (Omega/omega0)")
    P("  %-15s %-22s %-12s %-6s %-12s %-10s" % ("kind", "AUTO (run label)", "AUTO", "ours", "ours", "ours-AUTO"))
    for r in sp_table:
        P("  %-15s %-22s %-12.7f %-6s %-12s %-10s" % (
            r["kind"], "%s %s" % (r["auto_type"], r["auto_run_label"]) + ("" if r["auto_located"] else " (unlocated)"),
            r["auto_omega_over_omega0"], r["ours_label"] or "-",
            "%.7f" % r["ours_omega_over_omega0"] if r["ours_label"] else "-",
            "%+.1e" % r["difference"] if r["difference"] is not None else "-"))
    for o in unmatched_ours:
        P("  %-15s %-22s %-12s %-6s %-12.7f %-10s" % (o["kind"], "-", "-", o["label"], o["omega_over_omega0"], "-"))
    P("  unmatched: AUTO %s; ours %s" % (
        ", ".join("%s %.6f" % (u["kind"], u["omega_over_omega0"]) for u in unmatched_auto) or "none",
        ", ".join("%s %s %.6f" % (u["kind"], u["label"], u["omega_over_omega0"]) for u in unmatched_ours) or "none"))
    P("  grazing (ours only, AUTO has no grazing detection): %s" % (
        ", ".join("%s %.7f" % (g["label"], g["omega_over_omega0"]) for g in grazing) or "none"))
    if diffs:
        P("  max |ours - AUTO| over matched points: %.1e" % max(diffs))
    P("")
    P("Branch (max|u_i| of ours interpolated at %d of AUTO's %d points; %d outside our range %.6f..%.6f, %d not single-valued)"
      % (len(rels) // 2, len(auto["branch"]), skipped_range, min(ours_w), max(ours_w), skipped_multi))
    if worst:
        P("  max relative difference %.2e at Omega/omega0 = %.6f, body %d (ours %.7e m, AUTO %.7e m; "
          "interpolation-error estimate %.1e)" % worst)
        P("  median %.1e, 90%% %.1e, 99%% %.1e" % (pct(0.5), pct(0.9), pct(0.99)))
    for e in exact:
        P("  at the common point %.6f (no interpolation): %.1e, %.1e" % (e["omega_over_omega0"], *e["rel_diff"]))
    if mult_worst:
        P("  largest |multiplier| (%d points): median relative difference %.1e, max %.1e at %.6f (ours %.4g, AUTO %.4g)"
          % ((len(mult_rels), mult_median) + mult_worst))
    if orbit_check and orbit_check.get("orbits"):
        oc = orbit_check
        P("  SciPy check of %d of our orbits (one period from our initial_state, DOP853 rtol %g, %d samples):"
          % (len(oc["orbits"]), oc["rtol"], oc["samples"]))
        P("    periodicity residual (u/g, v/(g omega0)) max %.1e; our max_displacement vs the integrated orbit's: "
          "max relative difference %.1e, median %.1e" % (oc["max_periodicity_residual"], oc["max_rel_diff_max_u"],
                                                          oc["median_rel_diff_max_u"]))
    elif orbit_check:
        P("  SciPy check of our orbits failed: %s" % orbit_check.get("error"))
    P("")
    P("Stability (number of multipliers outside the unit circle, by points)")
    for name, runs in (("ours", ours_runs), ("AUTO", auto_runs)):
        P("  %-4s " % name + "  ".join("[%.5f, %.5f]: %d" % (r["from"], r["to"], r["unstable_multipliers"]) for r in runs))
    for name, bd in (("ours", ours_bd), ("AUTO", auto_bd)):
        P("  %-4s changes: " % name + "; ".join(
            "%d->%d in [%.5f, %.5f] at %s" % (b["unstable_before"], b["unstable_after"], b["bracket"][0], b["bracket"][1],
                                             ", ".join("%.6f" % s["omega_over_omega0"] for s in b["special_points"]) or "?")
            for b in bd))
    P("  same sequence of counts: %s; AUTO points with a different stability inside our stable/unstable stretches: %d%s"
      % ("yes" if same_sequence else "NO", len(stab_disagree),
         (" (" + ", ".join("%.5f" % w for w in stab_disagree[:10]) + ")") if stab_disagree else ""))
    P("  stable: ours %s; AUTO %s" % (
        ", ".join("[%.5f, %.5f]" % (i["from"], i["to"]) for i in stable_intervals(ours_runs) if i["stable"]),
        ", ".join("[%.5f, %.5f]" % (i["from"], i["to"]) for i in stable_intervals(auto_runs) if i["stable"])))
    P("")
    P("Versions: auto-07p %s, scipy/numpy %s, %s; written %s"
      % (doc["versions"]["auto-07p"], sc_versions, rustc, os.path.relpath(out_path, ROOT)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
