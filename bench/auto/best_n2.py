#!/usr/bin/env python3
"""R2 N = 2, 0.5 -> 1.5 omega0: our continuation against AUTO-07p at the
fastest passing configuration of the settings scan, in one run.

    python3 bench/auto/best_n2.py [--scan bench/auto/results/scan-auto-N2.jsonl]
        [--repeats 5] [--out bench/auto/results/best-n2-DATE.json]

AUTO's configuration is read from the scan's summary line (scan_auto.py: the
fastest configuration that reaches 1.5 on the symmetric branch with the seven
special points within 1e-5 and nothing extra) and run here with 1 and with 2
OpenMP threads; the faster counts. Ours: `target/release/vibroimpact continue
examples/fujita-row-n2.toml --parameter frequency --from 3.705 --to 11.115
--format json` (default settings, simulated start, whole process), best of
--repeats. Prints the table and both tools' special points side by side.
Standard library only.
"""
import argparse
import json
import os
import subprocess
import sys
import time

from run_auto import command_text

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OMEGA0 = 7.41


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def ours(repeats):
    exe = os.path.join(ROOT, "target", "release", "vibroimpact")
    cmd = [exe, "continue", os.path.join(ROOT, "examples", "fujita-row-n2.toml"), "--parameter",
           "frequency", "--from", "3.705", "--to", "11.115", "--format", "json"]
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True, check=True)
        times.append(time.perf_counter() - t0)
    out = json.loads(p.stdout)
    return {"seconds": min(times), "seconds_all": times, "points": len(out["points"]),
            "special_points": [(s["label"], s["parameter"] / OMEGA0) for s in out["special_points"]]}


def auto(cfg, threads, repeats):
    cmd = [sys.executable, os.path.join(HERE, "run_auto.py"), "--n", "2", "--ntst", str(cfg["ntst"]),
           "--ncol", str(cfg["ncol"]), "--ds", str(cfg["ds"]), "--dsmax", str(cfg["dsmax"]),
           "--eps", str(cfg["eps"]), "--epss", str(cfg["epss"]), "--repeats", str(repeats),
           "--threads", str(threads), "--no-branch"]
    if cfg["mode"] == "detect":
        cmd += ["--bp-detection", "--no-locate-bp"]
    else:
        cmd += ["--repeat-location"]
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    d = json.loads(p.stdout.strip().splitlines()[-1])
    seconds = d["seconds"] if cfg["mode"] == "detect" else d["seconds_total"]
    return {"threads": threads, "seconds": seconds, "steps": d["points"],
            "special_points": [(s["kind"], s["parameter_over_omega0"], s["located"])
                               for s in d["special_points"]], "command": command_text(cmd)}


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scan", default=os.path.join(HERE, "results", "scan-auto-N2.jsonl"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=os.path.join(HERE, "results", "best-n2-" + time.strftime("%Y-%m-%d") + ".json"))
    args = ap.parse_args(argv)
    summary = [json.loads(l) for l in open(args.scan) if '"summary"' in l][-1]
    cfg = summary["fastest_passing"]["config"]
    rec = {"load_before": loadavg(), "auto_config": cfg}
    rec["ours"] = ours(args.repeats)
    rec["auto"] = [auto(cfg, t, min(args.repeats, 3)) for t in (1, 2)]
    best = min(rec["auto"], key=lambda a: a["seconds"])
    rec["ratio"] = best["seconds"] / rec["ours"]["seconds"]
    rec["load_after"] = loadavg()
    print("ours: %.3f s (%d points); AUTO at its best: %.3f s (%d threads, %d steps); AUTO / ours = %.2f; load %s"
          % (rec["ours"]["seconds"], rec["ours"]["points"], best["seconds"], best["threads"], best["steps"],
             rec["ratio"], rec["load_before"]))
    for a in rec["auto"]:
        print("  AUTO %d thread(s): %.3f s" % (a["threads"], a["seconds"]))
    print("special points (Omega/omega0): ours | AUTO")
    ours_sp = [s for s in rec["ours"]["special_points"] if not s[0].startswith("GR")]
    for o, a in zip(ours_sp, best["special_points"]):
        print("  %-4s %.7f | %-15s %.7f  diff %+.1e" % (o[0], o[1], a[0], a[1], o[1] - a[1]))
    with open(args.out + ".tmp", "w") as f:
        json.dump(rec, f, indent=1)
    os.replace(args.out + ".tmp", args.out)


if __name__ == "__main__":
    main(sys.argv[1:])
