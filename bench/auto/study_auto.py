#!/usr/bin/env python3
"""Sensitivity of the AUTO-07p branch to its settings: runs run_auto.py
(--repeats 1, with BP location) over a set of NTST / NCOL / DSMAX / EPS
variations and writes one summary JSON line per setting to
results/auto-study.jsonl (and stdout): time, points, whether 1.5 omega0 was
reached, the special points (kind, Omega/omega0), the stability intervals and
the peak of max|u|. Standard library only; about 2-5 minutes.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BASE = dict(ntst=300, ncol=4, dsmax=0.005, eps=1e-7)
VARIANTS = ([dict(ntst=n) for n in (50, 100, 150, 200, 300, 400)]
            + [dict(ncol=c) for c in (3, 5)]
            + [dict(dsmax=d) for d in (0.002, 0.01, 0.02, 0.05)]
            + [dict(eps=e) for e in (1e-6, 1e-8)])


def main():
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    out = open(os.path.join(HERE, "results", "auto-study.jsonl"), "w")
    for v in VARIANTS:
        s = dict(BASE, **v)
        cmd = [sys.executable, os.path.join(HERE, "run_auto.py"), "--repeats", "1",
               "--ntst", str(s["ntst"]), "--ncol", str(s["ncol"]), "--dsmax", str(s["dsmax"]),
               "--eps", str(s["eps"]), "--workdir", os.path.join(HERE, "build", "study")]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            rec = {"settings": s, "error": p.stderr[-2000:]}
        else:
            r = json.loads(p.stdout)
            rec = {"settings": s, "seconds": r["seconds"], "seconds_bp_location": r["seconds_bp_location"],
                   "points": r["points"], "reached_wmax": r["reached_wmax"], "end": r["end"],
                   "special_points": [[x["kind"], round(x["parameter_over_omega0"], 6), x["located"]]
                                      for x in r["special_points"]],
                   "stability_intervals": [[x["stable"], round(x["from"], 5), round(x["to"], 5)]
                                           for x in r["stability_intervals"]],
                   "peak": r["peak"]}
        line = json.dumps(rec, separators=(",", ":"))
        print(line, flush=True)
        out.write(line + "\n")
        out.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
