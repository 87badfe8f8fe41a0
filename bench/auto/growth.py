#!/usr/bin/env python3
"""Cost growth with N: vibroimpact continuation against AUTO-07p on R2 with N
bodies (N = 2, 4, 8, 16), the same task in one run.

    python3 bench/auto/growth.py [--n 2,4,8,16,32] [--repeats 2] [--ntst 200,400]
        [--timeout 900] [--integrators global,local] [--threads 1,2]
        [--out bench/auto/results/growth-DATE]

The task, the same for every N and both tools: from the rest state (exact at
zero forcing) a homotopy in the forcing amplitude at 0.5 omega0, then the
symmetric branch of T-periodic orbits in Omega from 0.5 to 0.537 omega0 with
the Floquet multipliers at every point and the special points detected. The
window ends below the fold at 0.538 omega0 where the branch of every N >= 4
turns back (bench/auto/README.md, "Any N"), so both tools cover the same
piece of the same branch at every N.

- ours: `target/release/vibroimpact continue ROW.toml --parameter frequency
  --from 3.705 --to 3.97917 --start homotopy --integrator I --format json`
  (ROW = the N = 2 example with `count = N`) for each integrator I of
  --integrators, best wall time of --repeats, whole process; the table's
  "ours" is the faster integrator.
- AUTO-07p: run_auto.py --n N (rn.exe) with BP detection off (in-run
  detection leaves the symmetric branch at N = 4, README), DS 0.005, DSMAX
  0.05, EPSL/EPSU 1e-6, EPSS 1e-5, NCOL 4, for each NTST of --ntst and
  each OpenMP thread count of --threads (ours finishes points on a second
  thread, so AUTO gets its second one too); a run passes if it ends at the user stop (UZ) with every point
  symmetric; AUTO's time is the fastest passing NTST and thread count (best of --repeats,
  homotopy + branch). These are the N = 2 scan's fastest settings
  (scan_auto.py) with the BP handling that stays on the branch; the scan
  over NTST is repeated per N, the other factors are not (a full scan at
  N = 16 takes hours).

Writes OUT.json (everything, with load averages and versions), OUT.txt (the
table) and OUT.svg (time against N, log-log, both tools). Standard library
only; needs build/rn.exe (build.sh) and a release build of the CLI.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

from run_auto import command_text

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OMEGA0 = 7.41
W_END = 0.537


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def ours(n, repeats, workdir, integrator):
    """Best wall time of our continuation on the window by `integrator`,
    and its output."""
    src = open(os.path.join(ROOT, "examples", "fujita-row-n2.toml")).read()
    model = os.path.join(workdir, f"row-n{n}.toml")
    with open(model, "w") as f:
        f.write(src.replace("count = 2", f"count = {n}", 1))
    exe = os.path.join(ROOT, "target", "release", "vibroimpact")
    cmd = [exe, "continue", model, "--parameter", "frequency", "--from", str(0.5 * OMEGA0),
           "--to", str(W_END * OMEGA0), "--start", "homotopy", "--integrator", integrator,
           "--format", "json"]
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        times.append(time.perf_counter() - t0)
        if p.returncode != 0:
            return {"error": p.stderr.strip(), "command": " ".join(cmd)}
        out = json.loads(p.stdout)
    return {
        "integrator": integrator,
        "seconds": min(times),
        "seconds_all": times,
        "points": len(out["points"]),
        "stop": out["stop"],
        "symmetric": out["symmetric"],
        "special_points": [{"label": s["label"], "omega_over_omega0": s["parameter"] / OMEGA0}
                           for s in out["special_points"]],
        "command": command_text(cmd),
    }


def auto(n, ntst, threads, repeats, timeout, workdir):
    cmd = [sys.executable, os.path.join(HERE, "run_auto.py"), "--n", str(n), "--exe", "rn",
           "--ntst", str(ntst), "--ncol", "4", "--ds", "0.005", "--dsmax", "0.05",
           "--eps", "1e-6", "--epss", "1e-5", "--wmax", str(W_END), "--no-locate-bp",
           "--repeats", str(repeats), "--threads", str(threads), "--no-branch",
           "--timeout", str(timeout),
           "--workdir", os.path.join(workdir, f"auto-n{n}-{ntst}-{threads}")]
    os.makedirs(cmd[-1], exist_ok=True)
    p = subprocess.run(cmd, capture_output=True, text=True)
    try:
        d = json.loads(p.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return {"ntst": ntst, "threads": threads, "error": p.stderr.strip()[-500:], "passed": False}
    end = d.get("end") or {}
    passed = (not d.get("error") and end.get("type") == "UZ" and d.get("nan_points", 0) == 0
              and d.get("first_asymmetric_omega") is None)
    return {
        "ntst": ntst,
        "threads": threads,
        "passed": passed,
        "seconds": d.get("seconds"),
        "seconds_all": d.get("seconds_all_repeats"),
        "steps": d.get("points"),
        "end": end,
        "max_symmetry_defect": d.get("max_symmetry_defect"),
        "special_points": [{"kind": s["kind"], "omega_over_omega0": s["parameter_over_omega0"],
                            "located": s["located"]} for s in d.get("special_points", [])],
        "error": d.get("error"),
        "settings": d.get("settings"),
    }


def svg(rows, path):
    """Time against N, log-log, both tools."""
    pts = [(r["n"], r["ours"]["seconds"], r["auto_best"]["seconds"] if r.get("auto_best") else None)
           for r in rows if "seconds" in r["ours"]]
    ts = [t for _, a, b in pts for t in (a, b) if t]
    if not ts:
        return
    w, h, m = 560, 400, 70
    x0, x1 = math.log10(min(p[0] for p in pts)) - 0.1, math.log10(max(p[0] for p in pts)) + 0.1
    y0, y1 = math.floor(math.log10(min(ts))), math.ceil(math.log10(max(ts)))
    X = lambda n: m + (math.log10(n) - x0) / (x1 - x0) * (w - 1.5 * m)
    Y = lambda t: h - m - (math.log10(t) - y0) / max(y1 - y0, 1) * (h - 1.7 * m)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{w / 2}" y="20" text-anchor="middle" font-size="14">R2 symmetric branch 0.5-0.537 omega0: wall time against N</text>']
    for e in range(y0, y1 + 1):
        out.append(f'<line x1="{m}" x2="{w - m / 2}" y1="{Y(10 ** e):.1f}" y2="{Y(10 ** e):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{m - 6}" y="{Y(10 ** e) + 4:.1f}" text-anchor="end">1e{e} s</text>')
    for n, _, _ in pts:
        out.append(f'<text x="{X(n):.1f}" y="{h - m + 18}" text-anchor="middle">{n}</text>')
    out.append(f'<text x="{w / 2}" y="{h - m + 38}" text-anchor="middle">bodies N</text>')
    for k, (color, name) in enumerate([("#1f77b4", "vibroimpact"), ("#d62728", "AUTO-07p (fastest passing NTST)")]):
        xy = [(X(n), Y(t)) for n, *ts_ in pts for t in [ts_[k]] if t]
        out.append('<polyline fill="none" stroke="%s" stroke-width="2" points="%s"/>'
                   % (color, " ".join(f"{a:.1f},{b:.1f}" for a, b in xy)))
        for a, b in xy:
            out.append(f'<circle cx="{a:.1f}" cy="{b:.1f}" r="3.5" fill="{color}"/>')
        out.append(f'<text x="{m + 10}" y="{45 + 16 * k}" fill="{color}">{name}</text>')
    out.append("</svg>")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(path + ".tmp", path)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", default="2,4,8,16")
    ap.add_argument("--ntst", default="200,400")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--integrators", default="global,local")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "growth-" + time.strftime("%Y-%m-%d")))
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as workdir:
        for n in [int(x) for x in args.n.split(",")]:
            row = {"n": n, "load_before": loadavg()}
            row["ours_by_integrator"] = [ours(n, args.repeats, workdir, i)
                                         for i in args.integrators.split(",")]
            timed = [o for o in row["ours_by_integrator"] if "seconds" in o]
            row["ours"] = (min(timed, key=lambda o: o["seconds"]) if timed
                           else row["ours_by_integrator"][0])
            row["auto"] = [auto(n, int(t), int(k), args.repeats, args.timeout, workdir)
                           for t in args.ntst.split(",") for k in args.threads.split(",")]
            passing = [a for a in row["auto"] if a["passed"]]
            row["auto_best"] = min(passing, key=lambda a: a["seconds"]) if passing else None
            if row["auto_best"] and "seconds" in row["ours"]:
                row["ratio"] = row["auto_best"]["seconds"] / row["ours"]["seconds"]
            row["load_after"] = loadavg()
            rows.append(row)
            print(json.dumps({k: row.get(k) for k in ("n", "ratio")}), file=sys.stderr, flush=True)
    lines = ["| N | ours (s) | integrator | our points | AUTO best (s) | AUTO NTST, threads "
             "| AUTO steps | AUTO / ours | load |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        o, a = r["ours"], r.get("auto_best") or {}
        lines.append("| %d | %s | %s | %s | %s | %s | %s | %s | %.1f |" % (
            r["n"], "%.3f" % o["seconds"] if "seconds" in o else "error",
            o.get("integrator", "-"),
            o.get("points", "-"), "%.2f" % a["seconds"] if a else "none passed",
            "%s, %s" % (a.get("ntst", "-"), a.get("threads", "-")), a.get("steps", "-"),
            "%.1f" % r["ratio"] if "ratio" in r else "-", r["load_before"][0]))
    table = "\n".join(lines)
    print(table)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    with open(args.out + ".json.tmp", "w") as f:
        json.dump({"task": f"homotopy at 0.5, symmetric branch 0.5 -> {W_END} omega0", "commit": commit,
                   "rows": rows}, f, indent=1)
    os.replace(args.out + ".json.tmp", args.out + ".json")
    with open(args.out + ".txt", "w") as f:
        f.write(table + "\n")
    svg(rows, args.out + ".svg")


if __name__ == "__main__":
    main(sys.argv[1:])
