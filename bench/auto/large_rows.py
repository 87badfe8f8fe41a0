#!/usr/bin/env python3
"""Matrix-free continuation on long rows (issue 11, item 3): R2 with N bodies.

    python3 bench/auto/large_rows.py [--n 64,100,1000] [--budget 180]
        [--integrators global,local] [--out bench/auto/results/large-rows-DATE]

Four tasks, all with `vibroimpact continue ROW --parameter frequency`
(ROW = examples/fujita-row-n2.toml with `count = N`), each by every
integrator of --integrators (`--integrator global|local`, docs/theory.md
§10):

1. The window 0.5 -> 0.537 omega0 (the piece of the symmetric branch every
   N follows before its fold at 0.538, bench/auto/README.md "Any N") for
   every N of --n, matrix-free (`--krylov`), and at the smallest N also
   dense (`--dense`): wall time, points, special points, the largest
   multiplier at both ends, peak memory. Matrix-free and dense must give
   the same special points to 1e-6 omega0 and the same largest multiplier
   to 1e-6 (checked, printed).
2. N = 100 from 0.5 omega0 towards 1.5, the first 800 points (`--krylov
   --max-points 800`, the default start): wall time of the whole command
   per point; the integrators' special points matched by kind over the
   parameter range both covered (the largest and median distance).
3. N = 100 from 0.5 omega0 towards 1.5 (`--to 11.115`), stopped by SIGINT
   after --budget seconds (Ctrl-C keeps the points): how far the branch
   gets in that time, its folds and special points.
3. N = 100 at 0.9 omega0: the branch in the forcing amplitude from 0 (the
   rest state) towards the model's 0.05 m/s^2 (what `--start homotopy`
   follows), stopped by SIGINT after --budget seconds: how far it gets,
   its folds, how many of its points are unstable and its largest
   multiplier (issue 11 asks for the branch over 0.9 -> 1.1 omega0 at
   N = 1000, which starts there).

AUTO-07p is not run here: at N = 16 one of its branch steps takes ~1.8 s
(bench/auto/README.md), so these rows are out of its reach.

Writes OUT.json (everything, with load averages and the commit) and OUT.txt
(the table). Standard library only; needs a release build of the CLI.
"""
import argparse
import datetime
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OMEGA0 = 7.41
EXE = os.path.join(ROOT, "target", "release", "vibroimpact")


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def row_file(n, workdir, omega=None):
    """The example row with `count = n` (and the forcing frequency
    `omega` in rad/s if given)."""
    src = open(os.path.join(ROOT, "examples", "fujita-row-n2.toml")).read()
    src = src.replace("count = 2", f"count = {n}", 1)
    if omega is not None:
        old = "frequency = 7.0395"
        assert old in src, "the example's forcing frequency changed"
        src = src.replace(old, f"frequency = {omega!r}", 1)
    path = os.path.join(workdir, f"row-n{n}-{omega}.toml")
    with open(path, "w") as f:
        f.write(src)
    return path


def run(cmd, budget=None):
    """Runs `cmd`; with `budget`, sends SIGINT after that many seconds.
    Returns (seconds, returncode, stdout, stderr, peak RSS of the child in
    MB, whether the budget ran out and SIGINT was sent)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    streams = {}
    readers = [threading.Thread(target=lambda k=k, f=f: streams.__setitem__(k, f.read()))
               for k, f in (("out", p.stdout), ("err", p.stderr))]
    for r in readers:
        r.start()
    interrupted = threading.Event()

    def interrupt():
        # os.kill, not Popen.send_signal (whose poll() could reap the
        # child before wait4 below); the pid stays ours until wait4.
        interrupted.set()
        os.kill(p.pid, signal.SIGINT)

    timer = threading.Timer(budget, interrupt) if budget else None
    if timer:
        timer.start()
    _, status, usage = os.wait4(p.pid, 0)
    seconds = time.perf_counter() - t0
    if timer:
        timer.cancel()
    for r in readers:
        r.join()
    p.returncode = os.waitstatus_to_exitcode(status)
    return (seconds, p.returncode, streams["out"], streams["err"], usage.ru_maxrss / 1024,
            interrupted.is_set())


def shown(cmd):
    """The command as recorded: the executable relative to the checkout, the
    temporary model file as ROW."""
    return " ".join([os.path.relpath(cmd[0], ROOT), cmd[1], "ROW"] + cmd[3:])


def largest(point):
    return max(abs(complex(re, im)) for re, im in point["floquet_multipliers"])


def summary(doc):
    points = doc["points"]
    return {
        "points": len(points),
        "stop": doc["stop"],
        "omega_range": [min(p["parameter"] for p in points) / OMEGA0,
                        max(p["parameter"] for p in points) / OMEGA0],
        "last_omega": points[-1]["parameter"] / OMEGA0,
        "largest_multiplier_ends": [largest(points[0]), largest(points[-1])],
        "special_points": [{"label": s["label"], "kind": s["kind"],
                            "omega_over_omega0": s["parameter"] / OMEGA0}
                           for s in doc["special_points"]],
    }


def window(n, linear, integrator, workdir):
    cmd = [EXE, "continue", row_file(n, workdir), "--parameter", "frequency",
           "--from", str(0.5 * OMEGA0), "--to", str(0.537 * OMEGA0), "--start", "homotopy",
           f"--{linear}", "--integrator", integrator, "--format", "json"]
    seconds, rc, out, err, mb, _ = run(cmd)
    if rc != 0:
        return {"n": n, "linear": linear, "integrator": integrator,
                "error": err.strip()[-500:], "command": shown(cmd)}
    return {"n": n, "linear": linear, "integrator": integrator, "seconds": seconds,
            "peak_mb": mb, "command": shown(cmd), **summary(json.loads(out))}


def points800(n, integrator, workdir):
    """Task 2: the first 800 points from 0.5 omega0, whole command."""
    cmd = [EXE, "continue", row_file(n, workdir), "--parameter", "frequency",
           "--from", str(0.5 * OMEGA0), "--to", str(1.5 * OMEGA0), "--krylov",
           "--max-points", "800", "--integrator", integrator, "--format", "json"]
    seconds, rc, out, err, mb, _ = run(cmd)
    if rc != 0:
        return {"n": n, "integrator": integrator, "error": err.strip()[-500:],
                "command": shown(cmd)}
    doc = summary(json.loads(out))
    return {"n": n, "integrator": integrator, "seconds": seconds,
            "seconds_per_point": seconds / doc["points"], "peak_mb": mb,
            "command": shown(cmd), **doc}


def matched(a, b):
    """Special points of `a` matched by kind to the nearest of `b`, over
    the parameter range both runs covered: the distances (omega0)."""
    top = min(a["omega_range"][1], b["omega_range"][1])
    gaps = []
    for s in a["special_points"]:
        if s["omega_over_omega0"] > top:
            continue
        near = [abs(s["omega_over_omega0"] - t["omega_over_omega0"])
                for t in b["special_points"] if t["kind"] == s["kind"]]
        gaps.append(min(near, default=float("inf")))
    gaps.sort()
    return {"compared": len(gaps), "median_gap_omega0": gaps[len(gaps) // 2] if gaps else None,
            "largest_gaps_omega0": gaps[-3:]}


def budgeted(n, budget, integrator, workdir):
    cmd = [EXE, "continue", row_file(n, workdir), "--parameter", "frequency",
           "--from", str(0.5 * OMEGA0), "--to", str(1.5 * OMEGA0), "--start", "homotopy",
           "--krylov", "--integrator", integrator, "--format", "json"]
    seconds, rc, out, err, mb, interrupted = run(cmd, budget)
    if not out.strip():
        return {"n": n, "error": err.strip()[-500:], "returncode": rc}
    doc = json.loads(out)
    # A stop request can end the run inside a correction, which then reads
    # as a corrector that does not converge: `interrupted` says it was ours.
    return {"n": n, "integrator": integrator, "budget_seconds": budget, "seconds": seconds,
            "returncode": rc, "interrupted_by_budget": interrupted,
            "peak_mb": mb, "command": shown(cmd),
            "folds": [s["omega_over_omega0"] for s in summary(doc)["special_points"]
                      if s["kind"] == "fold"],
            **summary(doc)}


def amplitude_branch(n, budget, integrator, workdir):
    """Task 4: the branch in the forcing amplitude at 0.9 omega0."""
    cmd = [EXE, "continue", row_file(n, workdir, 0.9 * OMEGA0), "--parameter", "amplitude",
           "--from", "0", "--to", "0.05", "--krylov", "--max-points", "100000",
           "--integrator", integrator, "--format", "json"]
    seconds, rc, out, err, mb, interrupted = run(cmd, budget)
    if not out.strip():
        return {"n": n, "error": err.strip()[-500:], "returncode": rc, "command": shown(cmd)}
    doc = json.loads(out)
    points = doc["points"]
    amplitudes = [p["parameter"] for p in points]
    return {"n": n, "integrator": integrator, "omega_over_omega0": 0.9,
            "budget_seconds": budget, "seconds": seconds,
            "returncode": rc, "interrupted_by_budget": interrupted, "peak_mb": mb,
            "command": shown(cmd), "points": len(points), "stop": doc["stop"],
            "amplitude_range": [min(amplitudes), max(amplitudes)],
            "last_amplitude": amplitudes[-1],
            "unstable_points": sum(not p["stable"] for p in points),
            "largest_multiplier": max(largest(p) for p in points),
            "folds": [s["parameter"] for s in doc["special_points"] if s["kind"] == "fold"],
            "special_points": len(doc["special_points"])}


def compare(dense, krylov):
    """Largest differences between the dense and matrix-free windows."""
    a, b = dense["special_points"], krylov["special_points"]
    same_kinds = [s["kind"] for s in a] == [s["kind"] for s in b]
    gap = max((abs(x["omega_over_omega0"] - y["omega_over_omega0"]) for x, y in zip(a, b)),
              default=0.0)
    rel = max(abs(x / y - 1) for x, y in zip(krylov["largest_multiplier_ends"],
                                              dense["largest_multiplier_ends"]))
    return {"same_kinds": same_kinds, "special_point_gap_omega0": gap,
            "largest_multiplier_rel_diff": rel,
            "passed": same_kinds and gap < 1e-6 and rel < 1e-6}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", default="64,100,1000")
    ap.add_argument("--budget", type=float, default=180.0)
    ap.add_argument("--integrators", default="global,local")
    ap.add_argument("--out", default=os.path.join(
        HERE, "results", f"large-rows-{datetime.date.today().isoformat()}"))
    args = ap.parse_args()
    if not os.path.exists(EXE):
        sys.exit(f"{EXE} missing: run `cargo build --release` first")
    ns = [int(x) for x in args.n.split(",")]
    integrators = args.integrators.split(",")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    result = {"commit": commit, "load_before": loadavg(), "windows": [], "checks": [],
              "points800": [], "budgeted": [], "amplitude_branch": []}
    with tempfile.TemporaryDirectory() as workdir:
        smallest = min(ns)
        for integrator in integrators:
            dense = window(smallest, "dense", integrator, workdir)
            result["windows"].append(dense)
            first = None
            for n in sorted(ns):
                result["windows"].append(window(n, "krylov", integrator, workdir))
                first = first or result["windows"][-1]
                print(json.dumps(result["windows"][-1])[:300], file=sys.stderr)
            if "error" not in dense and "error" not in first:
                result["checks"].append({"integrator": integrator, **compare(dense, first)})
        for integrator in integrators:
            result["points800"].append(points800(100, integrator, workdir))
            print(json.dumps(result["points800"][-1])[:300], file=sys.stderr)
        done = [r for r in result["points800"] if "error" not in r]
        if len(done) == 2:
            result["points800_match"] = matched(done[0], done[1])
        if args.budget > 0:
            for integrator in integrators:
                result["budgeted"].append(budgeted(100, args.budget, integrator, workdir))
                result["amplitude_branch"].append(
                    amplitude_branch(100, args.budget, integrator, workdir))
    result["load_after"] = loadavg()
    lines = ["| N | linear algebra | integrator | window 0.5 -> 0.537 (s) | points "
             "| special points (omega/omega0) | largest multiplier at 0.537 | peak MB |",
             "|---|---|---|---|---|---|---|---|"]
    for w in result["windows"]:
        if "error" in w:
            lines.append(f"| {w['n']} | {w['linear']} | {w['integrator']} "
                         f"| error: {w['error'][:80]} | | | | |")
            continue
        sp = ", ".join(f"{s['label']} {s['omega_over_omega0']:.7f}" for s in w["special_points"])
        mb = f"{w['peak_mb']:.0f}"
        lines.append(f"| {w['n']} | {w['linear']} | {w['integrator']} | {w['seconds']:.2f} "
                     f"| {w['points']} | {sp} | {w['largest_multiplier_ends'][1]:.6f} | {mb} |")
    for c in result["checks"]:
        lines.append(f"\nN = {min(ns)} dense vs matrix-free ({c['integrator']}): special points "
                     f"{c['special_point_gap_omega0']:.1e} omega0 apart, largest multiplier "
                     f"{c['largest_multiplier_rel_diff']:.1e} relative: "
                     f"{'PASS' if c['passed'] else 'FAIL'}")
    lines.append("\nN = 100 from 0.5 omega0, the first 800 points (whole command):")
    for r in result["points800"]:
        if "error" in r:
            lines.append(f"- {r['integrator']}: error {r['error'][:200]}")
            continue
        lines.append(f"- {r['integrator']}: {r['seconds']:.1f} s, {r['seconds_per_point']:.4f} s "
                     f"a point, omega {r['omega_range'][0]:.4f}-{r['omega_range'][1]:.4f} (last "
                     f"{r['last_omega']:.4f}), {len(r['special_points'])} special points, peak "
                     f"{r['peak_mb']:.0f} MB")
    if "points800_match" in result:
        m = result["points800_match"]
        lines.append(f"- special points of the first matched by kind in the second, over the range "
                     f"both covered: {m['compared']}, median {m['median_gap_omega0']:.1e} omega0, "
                     "largest " + ", ".join(f"{g:.1e}" for g in m["largest_gaps_omega0"]))
    for b in result["budgeted"]:
        if "error" in b:
            lines.append(f"\nN = 100 budgeted run: error {b['error']}")
            continue
        how = "stopped by SIGINT" if b["interrupted_by_budget"] else "ended"
        lines.append(f"\nN = 100 from 0.5 omega0 towards 1.5 ({b['integrator']}), {how} after "
                     f"{b['seconds']:.0f} s: {b['points']} points, omega {b['omega_range'][0]:.4f}-"
                     f"{b['omega_range'][1]:.4f} (last {b['last_omega']:.4f}), "
                     f"{len(b['special_points'])} special points, folds "
                     + ", ".join(f"{f:.7f}" for f in b["folds"]))
    for a in result["amplitude_branch"]:
        if "error" in a:
            lines.append(f"\nN = 100 amplitude branch: error {a['error']}")
            continue
        how = "stopped by SIGINT" if a["interrupted_by_budget"] else "ended"
        lines.append(f"\nN = 100 at 0.9 omega0 ({a['integrator']}), forcing amplitude from 0 towards "
                     f"0.05 m/s^2, {how} after {a['seconds']:.0f} s: {a['points']} points, amplitude "
                     f"{a['amplitude_range'][0]:.4f}-{a['amplitude_range'][1]:.4f} (last "
                     f"{a['last_amplitude']:.4f}), {a['unstable_points']} unstable, largest "
                     f"multiplier {a['largest_multiplier']:.1f}, {len(a['folds'])} folds "
                     + ", ".join(f"{f:.5f}" for f in a["folds"]))
    text = "\n".join(lines)
    print(text)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out + ".json.tmp", "w") as f:
        json.dump(result, f, indent=1)
    os.replace(args.out + ".json.tmp", args.out + ".json")
    with open(args.out + ".txt.tmp", "w") as f:
        f.write(text + "\n")
    os.replace(args.out + ".txt.tmp", args.out + ".txt")


if __name__ == "__main__":
    main()
