#!/usr/bin/env python3
"""Markdown tables for README.md from results/: the AUTO branch (auto-default.json)
at the sweep frequencies (linear interpolation between AUTO points) next to the
SciPy sweeps (sweep-*.jsonl). Standard library only.

Usage: python3 summarize.py [--step 0.05]
"""
import argparse
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
G = 1e-3


def interp(branch, w):
    for a, b in zip(branch, branch[1:]):
        if a["omega_over_omega0"] <= w <= b["omega_over_omega0"]:
            f = (w - a["omega_over_omega0"]) / max(b["omega_over_omega0"] - a["omega_over_omega0"], 1e-300)
            m = max(a["max_u1"] + f * (b["max_u1"] - a["max_u1"]), a["max_u2"] + f * (b["max_u2"] - a["max_u2"]))
            st = a["stable"] if f < 0.5 else b["stable"]
            mu = b["max_abs_multiplier"] if f >= 0.5 else a["max_abs_multiplier"]
            return m, st, mu
    last = branch[-1]
    if abs(w - last["omega_over_omega0"]) < 1e-6:
        return max(last["max_u1"], last["max_u2"]), last["stable"], last["max_abs_multiplier"]
    return None, None, None


def load_sweep(name):
    p = os.path.join(HERE, "results", name)
    if not os.path.exists(p):
        return {}
    out = {}
    for line in open(p):
        r = json.loads(line)
        out[round(r["omega_over_omega0"], 6)] = r
    return out


def cell(r):
    if not r:
        return "-"
    m = max(r["max_u"]) / G
    per = r["period"]
    tag = "P%d" % per if per else ("~" if r["poincare_diff_last2_scaled"] < 1e-2 else "irr")
    return "%.3f %s (%.0e)" % (m, tag, r["poincare_diff_last2_scaled"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--step", type=float, default=0.05)
    args = ap.parse_args()
    auto = json.load(open(os.path.join(HERE, "results", "auto-default.json")))
    br = auto["branch"]
    sweeps = [("rest", load_sweep("sweep-rest.jsonl")), ("continue up", load_sweep("sweep-continue-up.jsonl")),
              ("continue down", load_sweep("sweep-continue-down.jsonl"))]
    print("| Omega/omega0 | AUTO max u/g | AUTO stable | AUTO max abs(mu) | " +
          " | ".join("sweep %s: max u/g, kind (d1)" % n for n, _ in sweeps) + " |")
    print("|---" * (4 + len(sweeps)) + "|")
    n = int(round(1.0 / args.step))
    for i in range(n + 1):
        w = round(0.5 + i * args.step, 6)
        m, st, mu = interp(br, w)
        print("| %.2f | %s | %s | %s | %s |" % (
            w, "%.4f" % (m / G) if m else "-", {True: "yes", False: "no", None: "-"}[st],
            "%.3g" % mu if mu else "-", " | ".join(cell(s.get(w)) for _, s in sweeps)))


if __name__ == "__main__":
    main()
