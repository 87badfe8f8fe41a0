#!/usr/bin/env python3
"""Settings scan of the AUTO-07p peer (run_auto.py) for R2 with N bodies: which
AUTO settings give the primary (symmetric) branch with its special points, and
which of those is fastest.

    python3 bench/auto/scan_auto.py [--n 2] [--repeats 2] [--out FILE.jsonl] [--quick]
        [--factors ntst,ncol,...] [--timeout 300] [--compute-reference] [--threads-top 3]

Configurations (one-factor-at-a-time around the baseline NTST 400, NCOL 4,
IAD 3, DS 0.005, DSMAX 0.05, EPSL = EPSU 1e-7, EPSS 1e-5, each in both
branch-point modes):
  mode "detect":  in-run BP detection (ISP 2, SP default: run_auto.py
                  --bp-detection); time = homotopy + branch;
  mode "locate":  BP detection off in the branch run (SP=['BP0']) and the
                  separate BP-location reruns of run_auto.py; time = homotopy
                  + branch + location (run_auto.py --repeat-location).
  factors: NTST {100,150,200,300}, NCOL {3,5}, DSMAX {0.005,0.01,0.02,0.1},
  DS {0.001}, EPS {1e-6}, EPSS {1e-4}; then combinations of the cheapest
  passing levels (per mode: the 3 factors whose cheapest passing level saved
  most, all 2^3 subsets), then OMP_NUM_THREADS = 2 for the --threads-top
  fastest passing configurations (all others run with 1 thread).

Per configuration one JSON line: settings, wall time (best of --repeats),
all repeat times, steps, end, reached_wmax, symmetric (the whole branch
symmetric: u_(N+1-i)(t) = -u_i(t + T/2), run_auto.py's symmetry defect),
special points, the comparison with the reference set and "pass", load
averages before/after. Last line: {"summary": ...} naming the fastest
configuration that passes.

Pass = the branch ends where the reference branch ends (for N = 2: reaches
1.5 omega0) and is symmetric throughout, and its special points of kinds
LP/BP/PD/TR match the reference set one to one: every reference point has a
located point of the same kind within --tol (1e-5) in Omega/omega0, and there
is no other (located or not) special point.

Reference set: for N = 2 the seven points of README.md (TR 0.5024794, BP
0.5094748, 0.5340433, 0.5524972, 0.7945276, 0.9493928, 0.9831002; branch to
1.5). For N > 2, results/scan-auto-ref-N<N>.json, computed with
--compute-reference (or when missing) from the finest settings: locate mode,
NTST 400, NCOL 5, DS 0.002, DSMAX 0.005, EPS 1e-8, EPSS 1e-6 (--ref-* to
change). Standard library only.
"""
import argparse
import itertools
import json
import os
import subprocess
import sys
import time

from run_auto import command_text

HERE = os.path.dirname(os.path.abspath(__file__))
RUN_AUTO = os.path.join(HERE, "run_auto.py")
KINDS = {"LP": "fold", "BP": "branch-point", "PD": "period-doubling", "TR": "neimark-sacker"}

BASE = dict(ntst=400, ncol=4, ds=0.005, dsmax=0.05, eps=1e-7, epss=1e-5, threads=1)
FACTORS = {
    "ntst": [100, 150, 200, 300],
    "ncol": [3, 5],
    "dsmax": [0.005, 0.01, 0.02, 0.1],
    "ds": [0.001],
    "eps": [1e-6],
    "epss": [1e-4],
}
QUICK = {"ntst": [200], "ncol": [3], "dsmax": [0.1]}
REF_N2 = {
    "source": "README.md (N = 2, NTST 300, DSMAX 0.005, located)",
    "end": {"type": "UZ", "omega_over_omega0": 1.5},
    "special_points": [["neimark-sacker", 0.5024794], ["branch-point", 0.5094748],
                       ["branch-point", 0.5340433], ["branch-point", 0.5524972],
                       ["branch-point", 0.7945276], ["branch-point", 0.9493928],
                       ["branch-point", 0.9831002]],
}


def loadavg():
    try:
        return open("/proc/loadavg").read().split()[:3]
    except OSError:
        return None


def key_of(cfg):
    return (cfg["mode"], cfg["ntst"], cfg["ncol"], cfg["ds"], cfg["dsmax"], cfg["eps"], cfg["epss"],
            cfg["threads"])


def run_config(cfg, args, workdir, repeats):
    cmd = [sys.executable, RUN_AUTO, "--n", str(args.n), "--repeats", str(repeats),
           "--ntst", str(cfg["ntst"]), "--ncol", str(cfg["ncol"]), "--ds", str(cfg["ds"]),
           "--dsmax", str(cfg["dsmax"]), "--eps", str(cfg["eps"]), "--epss", str(cfg["epss"]),
           "--threads", str(cfg["threads"]), "--nmx", str(args.nmx), "--no-branch",
           "--workdir", workdir, "--start", str(args.start), "--wmin", str(args.wmin)]
    if args.timeout:
        cmd += ["--timeout", str(args.timeout)]
    if cfg["mode"] == "detect":
        cmd.append("--bp-detection")
    else:
        cmd.append("--repeat-location")
    la0 = loadavg()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rec = {"config": cfg, "loadavg_before": la0, "loadavg_after": loadavg(),
           "wall_of_script": wall, "command": command_text(cmd)}
    if p.returncode not in (0, 3) or not p.stdout.strip():
        rec["error"] = (p.stderr or p.stdout)[-1500:]
        rec["pass"] = False
        return rec, None
    r = json.loads(p.stdout.strip().splitlines()[-1])
    if r.get("error"):
        rec["error"] = r.get("message", r["error"])
        rec["pass"] = False
        return rec, None
    if cfg["mode"] == "detect":
        rec["seconds"] = r["seconds"]
        rec["seconds_all_repeats"] = r["seconds_all_repeats"]
    else:
        rec["seconds"] = r["seconds_total"]
        rec["seconds_all_repeats"] = r["seconds_total_all_repeats"]
        rec["seconds_branch_only"] = r["seconds"]
    rec.update({"steps": r["points"], "end": r["end"], "reached_wmax": r["reached_wmax"],
                "timed_out": r.get("timed_out", False), "nan_points": r.get("nan_points", 0),
                "symmetric": r["max_symmetry_defect"] < 1e-3,
                "max_symmetry_defect": r["max_symmetry_defect"],
                "first_asymmetric_omega": r["first_asymmetric_omega"],
                "special_points": [[s["kind"], s["parameter_over_omega0"], s["located"],
                                    s.get("auto_type"), s.get("symmetric")]
                                   for s in r["special_points"]]})
    return rec, r


def compare(rec, ref, tol):
    """Match rec's special points with the reference set; sets rec["match"], rec["pass"]."""
    found = [dict(kind=s[0], w=s[1], located=s[2], type=s[3]) for s in rec.get("special_points", [])]
    used = set()
    matched, missing = [], []
    for kind, w in ref["special_points"]:
        best = None
        for i, f in enumerate(found):
            if i in used or f["kind"] != kind or not f["located"]:
                continue
            d = abs(f["w"] - w)
            if d <= tol and (best is None or d < abs(found[best]["w"] - w)):
                best = i
        if best is None:
            near = min((f for f in found), key=lambda f: abs(f["w"] - w), default=None)
            missing.append({"kind": kind, "reference": w,
                            "nearest": None if near is None else [near["kind"], near["w"], near["located"],
                                                                  near["type"]]})
        else:
            used.add(best)
            matched.append({"kind": kind, "reference": w, "found": found[best]["w"],
                            "difference": found[best]["w"] - w})
    extra = [[f["kind"], f["w"], f["located"], f["type"]] for i, f in enumerate(found) if i not in used]
    end_ok = (rec.get("end") is not None and rec["end"]["type"] == ref["end"]["type"]
              and abs(rec["end"]["omega_over_omega0"] - ref["end"]["omega_over_omega0"]) < 1e-6
              and not rec.get("timed_out"))
    rec["match"] = {"matched": len(matched), "of": len(ref["special_points"]), "missing": missing,
                    "extra": extra, "end_as_reference": end_ok,
                    "max_abs_difference": max((abs(m["difference"]) for m in matched), default=None)}
    rec["pass"] = bool(end_ok and rec.get("symmetric") and not missing and not extra)


def reference(args):
    if args.n == 2 and not args.compute_reference:
        return REF_N2
    path = args.reference or os.path.join(HERE, "results", f"scan-auto-ref-N{args.n}.json")
    if os.path.exists(path) and not args.compute_reference:
        return json.load(open(path))
    cfg = dict(mode="locate", ntst=args.ref_ntst, ncol=args.ref_ncol, ds=args.ref_ds,
               dsmax=args.ref_dsmax, eps=args.ref_eps, epss=args.ref_epss, threads=1)
    sys.stderr.write(f"scan_auto.py: computing the reference set for N = {args.n}: {cfg}\n")
    rec, r = run_config(cfg, args, os.path.join(args.workdir, "ref"), 1)
    if r is None:
        sys.exit(f"scan_auto.py: reference run failed: {rec.get('error')}")
    ref = {"source": f"scan_auto.py --compute-reference, N = {args.n}", "config": cfg,
           "command": rec["command"], "seconds": rec["seconds"], "steps": rec["steps"],
           "loadavg_before": rec["loadavg_before"], "loadavg_after": rec["loadavg_after"],
           "end": rec["end"], "reached_wmax": rec["reached_wmax"], "symmetric": rec["symmetric"],
           "max_symmetry_defect": rec["max_symmetry_defect"],
           "all_special_points": rec["special_points"],
           "special_points": [[s[0], s[1]] for s in rec["special_points"] if s[2]],
           "unlocated": [s for s in rec["special_points"] if not s[2]],
           "stability_intervals": r["stability_intervals"], "peak": r["peak"]}
    os.makedirs(os.path.dirname(path), exist_ok=True)
    json.dump(ref, open(path, "w"), indent=1)
    sys.stderr.write(f"scan_auto.py: reference written to {path}\n")
    return ref


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=2, help="timed repetitions per configuration (best)")
    ap.add_argument("--out", default=None, help="JSONL output (default results/scan-auto-N<N>.jsonl)")
    ap.add_argument("--quick", action="store_true", help="baseline + NTST 200, NCOL 3, DSMAX 0.1, "
                    "both modes, no combinations, threads 2 for the fastest only")
    ap.add_argument("--factors", default=None, help="comma list of factors to vary (default all)")
    ap.add_argument("--modes", default="detect,locate")
    ap.add_argument("--no-combinations", action="store_true")
    ap.add_argument("--threads-top", type=int, default=3,
                    help="rerun the K fastest passing configurations with OMP_NUM_THREADS=2")
    ap.add_argument("--tol", type=float, default=1e-5, help="match tolerance in Omega/omega0")
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds per AUTO run (run_auto.py; default 60 x N)")
    ap.add_argument("--nmx", type=int, default=3000,
                    help="NMX of the branch run (default 3000: a run that left the symmetric branch "
                         "wanders over asymmetric branches until NMX)")
    ap.add_argument("--start", type=float, default=0.5)
    ap.add_argument("--wmin", type=float, default=0.45)
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--reference", default=None, help="reference JSON (default results/scan-auto-ref-N<N>.json)")
    ap.add_argument("--compute-reference", action="store_true")
    ap.add_argument("--reference-only", action="store_true", help="compute the reference and stop")
    ap.add_argument("--ref-ntst", type=int, default=400)
    ap.add_argument("--ref-ncol", type=int, default=5)
    ap.add_argument("--ref-ds", type=float, default=0.002)
    ap.add_argument("--ref-dsmax", type=float, default=0.005)
    ap.add_argument("--ref-eps", type=float, default=1e-8)
    ap.add_argument("--ref-epss", type=float, default=1e-6)
    args = ap.parse_args(argv[1:])
    if args.timeout is None:
        args.timeout = 60.0 * args.n
    args.workdir = os.path.abspath(args.workdir or os.path.join(HERE, "build", f"scan-N{args.n}"))
    os.makedirs(args.workdir, exist_ok=True)
    if args.reference_only:
        args.compute_reference = True
    ref = reference(args)
    if args.reference_only:
        print(json.dumps(ref))
        return 0
    out_path = args.out or os.path.join(HERE, "results", f"scan-auto-N{args.n}.jsonl")
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    out = open(out_path, "w")
    factors = QUICK if args.quick else FACTORS
    if args.factors:
        keep = args.factors.split(",")
        factors = {k: v for k, v in factors.items() if k in keep}
    modes = args.modes.split(",")
    records = {}

    def emit(rec):
        line = json.dumps(rec, separators=(",", ":"))
        print(line, flush=True)
        out.write(line + "\n")
        out.flush()

    def do(cfg, phase):
        k = key_of(cfg)
        if k in records:
            return records[k]
        # one run first; the remaining --repeats only if it passed (a run that
        # wandered off the branch would cost its full time again)
        rec, _ = run_config(cfg, args, os.path.join(args.workdir, "run"), 1)
        if "error" not in rec:
            compare(rec, ref, args.tol)
            if rec["pass"] and args.repeats > 1:
                more, r2 = run_config(cfg, args, os.path.join(args.workdir, "run"), args.repeats - 1)
                if r2 is not None:
                    rec["seconds_all_repeats"] = rec["seconds_all_repeats"] + more["seconds_all_repeats"]
                    rec["seconds"] = min(rec["seconds_all_repeats"])
                    rec["loadavg_after"] = more["loadavg_after"]
        rec["phase"] = phase
        records[k] = rec
        emit(rec)
        return rec

    # ---- one factor at a time ------------------------------------------------
    for mode in modes:
        base = dict(BASE, mode=mode)
        do(base, "baseline")
        for f, levels in factors.items():
            for v in levels:
                do(dict(base, **{f: v}), "one-factor")

    # ---- combinations of the cheapest passing levels ----------------------------
    if not args.quick and not args.no_combinations:
        for mode in modes:
            base_rec = records[key_of(dict(BASE, mode=mode))]
            t_base = base_rec.get("seconds") if base_rec.get("pass") else None
            savings = []
            for f in factors:
                best = None
                for v in factors[f]:
                    r = records.get(key_of(dict(BASE, mode=mode, **{f: v})))
                    if r and r.get("pass") and (best is None or r["seconds"] < best[1]):
                        best = (v, r["seconds"])
                if best and (t_base is None or best[1] < t_base):
                    savings.append(((t_base or 1e9) - best[1], f, best[0]))
            savings.sort(reverse=True)
            top = savings[:3]
            for subset in itertools.product([False, True], repeat=len(top)):
                if sum(subset) < 2:
                    continue
                cfg = dict(BASE, mode=mode)
                for use, (_, f, v) in zip(subset, top):
                    if use:
                        cfg[f] = v
                do(cfg, "combination")

    # ---- threads 2 for the fastest passing ------------------------------------------
    passing = sorted((r for r in records.values() if r.get("pass")), key=lambda r: r["seconds"])
    for r in passing[:(1 if args.quick else args.threads_top)]:
        do(dict(r["config"], threads=2), "threads")

    passing = sorted((r for r in records.values() if r.get("pass")), key=lambda r: r["seconds"])
    fastest_1t = [r for r in passing if r["config"]["threads"] == 1]
    summary = {
        "summary": True, "n": args.n, "configurations": len(records), "passing": len(passing),
        "reference": {"source": ref["source"], "end": ref["end"], "special_points": ref["special_points"]},
        "fastest_passing": None if not passing else {
            "config": passing[0]["config"], "seconds": passing[0]["seconds"],
            "steps": passing[0]["steps"], "loadavg_before": passing[0]["loadavg_before"],
            "max_abs_difference": passing[0]["match"]["max_abs_difference"]},
        "fastest_passing_1_thread": None if not fastest_1t else {
            "config": fastest_1t[0]["config"], "seconds": fastest_1t[0]["seconds"],
            "steps": fastest_1t[0]["steps"], "loadavg_before": fastest_1t[0]["loadavg_before"]},
        "ranking": [[r["config"]["mode"], r["config"]["ntst"], r["config"]["ncol"], r["config"]["ds"],
                     r["config"]["dsmax"], r["config"]["eps"], r["config"]["epss"],
                     r["config"]["threads"], round(r["seconds"], 3), r["steps"]] for r in passing],
        "repeats": args.repeats, "loadavg_end": loadavg(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S"),
    }
    emit(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
