#!/usr/bin/env python3
"""Agreement of our two-parameter curves (fold / branch-point curves of
`vibroimpact continue --parameter2`) with AUTO-07p's (curves_auto.py).

    python3 bench/auto/compare_curves.py [--ours $TMP/ours/curves.json | --run-ours]
        [--auto bench/auto/results/auto-curves-n1.json]
        [--out bench/auto/results/compare-curves-n1.json]
        [--end-skip 0.002] [--interp-tol 1e-6] [--a-ref 0.05]

--run-ours runs our side itself (from the repository root; target/release/
vibroimpact, or `cargo run --release -p vibroimpact-cli --` if that binary is
missing), in a temporary directory:

    sed 's/^count = 2/count = 1/' examples/fujita-row-n2.toml > $TMP/r2n1.toml
    target/release/vibroimpact continue $TMP/r2n1.toml --parameter frequency --from 3.705 \\
        --to 11.115 --start homotopy --parameter2 amplitude --out $TMP/ours

Measure: the plane (x, y) = (frequency/omega0, amplitude/A_ref), A_ref = 0.05
m/s^2 by default. AUTO's curves from one start point (both directions, the
backward one reversed and joined to the forward one; closed loops wrap
around) are dense (steps of a few 1e-3). Each of our points is projected onto
AUTO's curve: the nearest AUTO vertex, then on the four segments around it
the local cubic through the four nearest AUTO points (Lagrange in the
chord-length parameter, i.e. a parametric curve: turning points of the curve
in frequency or amplitude need no special care), minimised by golden-section
search. The deviation of a point is that distance. The interpolation error is
estimated per point as the change of the distance when the stencil is
shifted by one point (a second cubic); points where this estimate exceeds
--interp-tol are skipped (ill-posed interpolation, e.g. at a cusp), and so
are points whose projection lies within --end-skip (arclength in the plane)
of an end of an open AUTO curve (where our curve may extend beyond AUTO's,
both stop at the parameter bounds by interpolation). The skipped counts are
reported per curve. Each of our curves is compared with the AUTO curve of the
same kind that its first point is nearest to.

Also (information): our max displacement of body 1 against AUTO's max |x_1|
(PAR(21), PAR(22), from the collocation points) interpolated with the same
cubic at the projection, in metres.

Prints a table and writes one JSON document (--out). Standard library only.
"""
import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from run_auto import command_text  # noqa: E402

OMEGA0 = 7.41
A_REF = 0.05
GOLD = (math.sqrt(5.0) - 1.0) / 2.0


# ---------------------------------------------------------------------------
# geometry: a dense polyline, local parametric cubics, projection
# ---------------------------------------------------------------------------
class Curve:
    """A curve through points P[i] = (x, y) (plus optional attached values
    V[i], interpolated alike), closed or open, parametrised by cumulative
    chord length."""

    def __init__(self, pts, closed=False, values=None):
        if closed and len(pts) > 2 and math.dist(pts[0], pts[-1]) < 1e-12:
            pts = pts[:-1]
            values = values[:-1] if values else values
        self.p = [tuple(map(float, q)) for q in pts]
        self.v = values
        self.closed = closed
        self.n = len(self.p)
        self.s = [0.0]
        for i in range(1, self.n):
            self.s.append(self.s[-1] + math.dist(self.p[i - 1], self.p[i]))
        self.length = self.s[-1] + (math.dist(self.p[-1], self.p[0]) if closed else 0.0)

    def _node(self, k):
        """(parameter, point, value) of node k; for closed curves any integer
        k (wraps, the parameter continues past the length)."""
        if self.closed:
            q, r = divmod(k, self.n)
            return (self.s[r] + q * self.length, self.p[r],
                    self.v[r] if self.v else None)
        return self.s[k], self.p[k], self.v[k] if self.v else None

    def stencil(self, k, shift=0):
        """Four nodes around segment [k, k+1]: k-1..k+2 (shift 0); shift -1:
        k-2..k+1, +1: k..k+3. Open curves: clamped into range."""
        first = k - 1 + shift
        if not self.closed:
            first = max(0, min(first, self.n - 4))
        return [self._node(j) for j in range(first, first + 4)]

    @staticmethod
    def lagrange(nodes, t, what=1):
        """Value at parameter t of the cubic through the nodes (what = 1:
        point, 2: attached value)."""
        ts = [nd[0] for nd in nodes]
        dims = len(nodes[0][what])
        out = [0.0] * dims
        for i, nd in enumerate(nodes):
            w = 1.0
            for j in range(4):
                if j != i:
                    w *= (t - ts[j]) / (ts[i] - ts[j])
            for d in range(dims):
                out[d] += w * nd[what][d]
        return out

    def _seg_min(self, q, k, shift):
        """min over t in segment k of |c(t) - q| with the cubic of the given
        stencil: (distance, t)."""
        if not self.closed and not 0 <= k < self.n - 1:
            return math.inf, None, None
        nodes = self.stencil(k, shift)
        t0 = self._node(k)[0]
        t1 = self._node(k + 1)[0]

        def f(t):
            c = self.lagrange(nodes, t)
            return (c[0] - q[0]) ** 2 + (c[1] - q[1]) ** 2
        # coarse scan then golden section around the best sample
        m = 16
        ts = [t0 + (t1 - t0) * i / m for i in range(m + 1)]
        fs = [f(t) for t in ts]
        i = min(range(m + 1), key=lambda j: fs[j])
        a, b = ts[max(0, i - 1)], ts[min(m, i + 1)]
        c, d = b - GOLD * (b - a), a + GOLD * (b - a)
        fc, fd = f(c), f(d)
        for _ in range(60):
            if fc < fd:
                b, d, fd = d, c, fc
                c = b - GOLD * (b - a)
                fc = f(c)
            else:
                a, c, fc = c, d, fd
                d = a + GOLD * (b - a)
                fd = f(d)
            if b - a < 1e-15 * max(1.0, abs(b)):
                break
        t = 0.5 * (a + b)
        best = min((f(t), t), (fs[0], t0), (fs[-1], t1))
        return math.sqrt(best[0]), best[1], nodes

    def project(self, q, shift=0):
        """Nearest point of the curve to q: dict(distance, t (arclength from
        node 0), k (segment), point, value, end_distance (open curves: the
        arclength to the nearer end))."""
        i = min(range(self.n), key=lambda j: (self.p[j][0] - q[0]) ** 2 + (self.p[j][1] - q[1]) ** 2)
        best = (math.inf, None, None, None)
        for k in range(i - 2, i + 2):
            kk = k % self.n if self.closed else k
            dist, t, nodes = self._seg_min(q, kk, shift)
            if dist < best[0]:
                best = (dist, t, kk, nodes)
        dist, t, k, nodes = best
        out = {"distance": dist, "t": t, "k": k, "point": self.lagrange(nodes, t)}
        if self.v:
            out["value"] = self.lagrange(nodes, t, what=2)
        if self.closed:
            out["end_distance"] = math.inf
        else:
            out["end_distance"] = min(t - self.s[0], self.s[-1] - t)
        return out

    def distance(self, q):
        """(distance, interpolation-error estimate, projection)."""
        pr = self.project(q)
        alt = [self.project(q, shift=s)["distance"] for s in (-1, 1)]
        err = max(abs(a - pr["distance"]) for a in alt)
        return pr["distance"], err, pr


def curve_from_auto(c, a_ref=A_REF):
    """A Curve in the plane (W, amplitude/a_ref) from an AUTO curve of
    auto-curves-*.json, with max |x_1| (m) attached."""
    pts = [(p["W"], p["amplitude"] / a_ref) for p in c["points"]]
    vals = [(p.get("max_u1", float("nan")),) for p in c["points"]]
    return Curve(pts, closed=c.get("closed", False), values=vals)


def distances(curve_pts, ref, end_skip=0.0, interp_tol=math.inf):
    """Deviation of every point (x, y) of curve_pts from the Curve ref:
    list of dicts (index, distance, interp_error, skipped reason or None,
    projection)."""
    rows = []
    for i, q in enumerate(curve_pts):
        d, err, pr = ref.distance(q)
        why = None
        if pr["end_distance"] < end_skip:
            why = "end"
        elif err > interp_tol:
            why = "interpolation"
        rows.append({"index": i, "distance": d, "interp_error": err, "skipped": why,
                     "projection": pr})
    return rows


def summary(rows):
    """max / median of the deviations of the points that count."""
    ds = [r["distance"] for r in rows if r["skipped"] is None]
    return {"compared": len(ds), "max": max(ds) if ds else None,
            "median": statistics.median(ds) if ds else None,
            "skipped_end": sum(1 for r in rows if r["skipped"] == "end"),
            "skipped_interpolation": sum(1 for r in rows if r["skipped"] == "interpolation"),
            "max_interp_error": max((r["interp_error"] for r in rows if r["skipped"] is None),
                                    default=None),
            "max_of_skipped": max((r["distance"] for r in rows if r["skipped"]), default=None)}


# ---------------------------------------------------------------------------
# our side
# ---------------------------------------------------------------------------
def run_ours(workdir):
    """Our continuation with --parameter2 amplitude for R2, N = 1; returns
    (path of curves.json, [command texts], seconds)."""
    src = open(os.path.join(ROOT, "examples", "fujita-row-n2.toml")).read()
    model = os.path.join(workdir, "r2n1.toml")
    lines = [("count = 1" + ln[len("count = 2"):]) if ln.startswith("count = 2") else ln
             for ln in src.split("\n")]
    with open(model, "w") as f:
        f.write("\n".join(lines))
    exe = os.path.join(ROOT, "target", "release", "vibroimpact")
    base = [exe] if os.path.exists(exe) else ["cargo", "run", "--release", "-q", "-p",
                                             "vibroimpact-cli", "--"]
    out = os.path.join(workdir, "ours")
    cmd = base + ["continue", model, "--parameter", "frequency", "--from", "3.705", "--to",
                  "11.115", "--start", "homotopy", "--parameter2", "amplitude", "--out", out]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        raise RuntimeError("our continuation failed")
    sed = ("sed 's/^count = 2/count = 1/' examples/fujita-row-n2.toml > "
           + command_text([model]))
    return os.path.join(out, "curves.json"), [sed, command_text(cmd)], dt, p.stdout + p.stderr


def provenance():
    """git HEAD, whether crates/ has uncommitted changes, and the time of the
    release binary (our side may be built from a working tree)."""
    info = {}
    try:
        info["git_head"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                          capture_output=True, text=True).stdout.strip()
        st = subprocess.run(["git", "status", "--porcelain", "--", "crates"], cwd=ROOT,
                            capture_output=True, text=True).stdout
        info["crates_dirty"] = bool(st.strip())
    except OSError:
        pass
    exe = os.path.join(ROOT, "target", "release", "vibroimpact")
    if os.path.exists(exe):
        info["binary_mtime"] = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(os.path.getmtime(exe)))
    return info


# ---------------------------------------------------------------------------
def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ours", help="our curves.json")
    ap.add_argument("--run-ours", action="store_true", help="run our continuation first")
    ap.add_argument("--auto", default=os.path.join(HERE, "results", "auto-curves-n1.json"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "compare-curves-n1.json"))
    ap.add_argument("--a-ref", type=float, default=A_REF, help="amplitude scale (m/s^2)")
    ap.add_argument("--end-skip", type=float, default=2e-3,
                    help="skip points projecting within this arclength of an open AUTO curve's end")
    ap.add_argument("--interp-tol", type=float, default=1e-6,
                    help="skip points whose interpolation-error estimate exceeds this")
    ap.add_argument("--target", type=float, default=1e-5)
    ap.add_argument("--keep", action="store_true", help="keep the --run-ours directory")
    args = ap.parse_args(argv[1:])
    if not args.ours and not args.run_ours:
        ap.error("give --ours curves.json or --run-ours")

    ours_cmds, ours_seconds, tmp, ours_log = None, None, None, None
    if args.run_ours:
        tmp = tempfile.mkdtemp(prefix="compare-curves-")
        args.ours, ours_cmds, ours_seconds, ours_log = run_ours(tmp)
    ours = json.load(open(args.ours))
    auto = json.load(open(args.auto))
    a_ref = args.a_ref

    # AUTO: one curve per start point and kind
    auto_curves = [(c, curve_from_auto(c, a_ref)) for c in auto["curves"]]

    results = []
    for ci, oc in enumerate(ours["curves"]):
        pts = [(p["frequency"] / OMEGA0, p["amplitude"] / a_ref) for p in oc["points"]]
        cands = [(ac, cv) for ac, cv in auto_curves if ac["kind"] == oc["kind"]]
        if not cands or not pts:
            results.append({"index": ci, "kind": oc["kind"], "from": oc.get("from"),
                            "error": "no AUTO curve of this kind"})
            continue
        ac, cv = min(cands, key=lambda c: c[1].distance(pts[0])[0])
        rows = distances(pts, cv, args.end_skip, args.interp_tol)
        s = summary(rows)
        # componentwise and max-displacement differences at the projections
        dmax_u = []
        for r, p in zip(rows, oc["points"]):
            pr = r["projection"]
            r["dW"] = pts[r["index"]][0] - pr["point"][0]
            r["dA"] = pts[r["index"]][1] - pr["point"][1]
            mu = p.get("max_displacement")
            if mu and "value" in pr and pr["value"][0] == pr["value"][0]:
                r["d_max_u1"] = mu[0] - pr["value"][0]
                if r["skipped"] is None:
                    dmax_u.append(abs(r["d_max_u1"]))
        worst = max((r for r in rows if r["skipped"] is None), key=lambda r: r["distance"],
                    default=None)
        results.append({
            "index": ci, "kind": oc["kind"], "from": oc.get("from"), "stop": oc.get("stop"),
            "points": len(pts), "auto_curve": ac["from"], "auto_closed": ac.get("closed", False),
            "auto_points": len(ac["points"]),
            **s,
            "max_abs_dW": max((abs(r["dW"]) for r in rows if r["skipped"] is None), default=None),
            "max_abs_dA": max((abs(r["dA"]) for r in rows if r["skipped"] is None), default=None),
            "max_abs_d_max_u1_m": max(dmax_u, default=None),
            "worst_point": None if worst is None else {
                "index": worst["index"], "W": pts[worst["index"]][0],
                "A_over_Aref": pts[worst["index"]][1], "distance": worst["distance"]},
            "start_dW": pts[0][0] - ac["start"].get("W_corrected", ac["start"]["W"]),
            "first": {"W": pts[0][0], "A_over_Aref": pts[0][1]},
            "last": {"W": pts[-1][0], "A_over_Aref": pts[-1][1]},
            "deviations": [{"W": pts[r["index"]][0], "A_over_Aref": pts[r["index"]][1],
                            "distance": r["distance"], "dW": r["dW"], "dA": r["dA"],
                            "interp_error": r["interp_error"], "skipped": r["skipped"],
                            **({"d_max_u1_m": r["d_max_u1"]} if "d_max_u1" in r else {})}
                           for r in rows],
        })

    counted = [r for r in results if r.get("max") is not None]
    overall = max((r["max"] for r in counted), default=None)
    doc = {
        "what": "deviation of our two-parameter curves from AUTO-07p's, R2 N = %s" % auto.get("n"),
        "plane": "(frequency/omega0, amplitude/A_ref)", "omega0": OMEGA0, "a_ref": a_ref,
        "method": "distance to AUTO's dense curve through local parametric cubics (chord-length "
                  "Lagrange, 4 points), golden-section projection; interpolation error estimated "
                  "by shifting the stencil",
        "end_skip": args.end_skip, "interp_tol": args.interp_tol, "target": args.target,
        "max_deviation": overall,
        "meets_target": overall is not None and overall <= args.target,
        "ours": {"file": command_text([os.path.abspath(args.ours)]),
                 "commands": ours_cmds, "seconds": ours_seconds,
                 **(provenance() if args.run_ours else {}),
                 "log": ours_log.strip().split("\n") if ours_log else None},
        "auto": {"file": command_text([os.path.abspath(args.auto)]),
                 "settings": auto.get("settings"),
                 "ntst_refinement": auto.get("refinement", {}).get("max_distance")},
        "ours_skipped": ours.get("skipped"),
        "curves": results,
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")

    # table
    print("plane: (frequency/omega0, amplitude/%g m/s^2); target %.0e" % (a_ref, args.target))
    hdr = "%-3s %-13s %-5s %-12s %6s %8s %10s %10s %10s %10s %5s %5s %10s %10s" % (
        "#", "kind", "from", "stop", "ours", "AUTO", "max", "median", "max|dW|", "max|dA|",
        "skE", "skI", "interp", "start dW")
    print(hdr)
    for r in results:
        if r.get("max") is None:
            print("%-3d %-13s %-5s  %s" % (r["index"], r["kind"], r.get("from"), r.get("error", "-")))
            continue
        print("%-3d %-13s %-5s %-12s %6d %8d %10.2e %10.2e %10.2e %10.2e %5d %5d %10.1e %10.1e" % (
            r["index"], r["kind"], r["from"], r["stop"], r["points"], r["auto_points"], r["max"],
            r["median"], r["max_abs_dW"], r["max_abs_dA"], r["skipped_end"],
            r["skipped_interpolation"], r["max_interp_error"], r["start_dW"]))
    print("(max, median: distance in the plane; dW, dA: its components; skE/skI: points skipped "
          "near an AUTO curve end / for interpolation error > %g; interp: largest "
          "interpolation-error estimate of the compared points; start dW: our start point "
          "minus AUTO's LP / corrected BP, in W)" % args.interp_tol)
    print("max deviation %.2e: %s" % (overall if overall is not None else float("nan"),
                                      "meets" if doc["meets_target"] else "MISSES"),
          "the target; AUTO NTST refinement (coarse vs fine) max %s" %
          doc["auto"]["ntst_refinement"])
    print("wrote", command_text([os.path.abspath(args.out)]))
    if tmp and not args.keep:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
