#!/usr/bin/env python3
"""vibroimpact against OpenSees (openseespy) on the two-frame pounding run,
in one run (docs/earthquakes.md, "OpenSees as the peer"):

* the pair of examples/pounding-frames.toml (3 + 2 storeys, 2 cm joint at
  floors 1 and 2) under a FEMA P695 far-field record (default: record 1,
  component a, Northridge 1994 at Beverly Hills - Mulholland), with the two
  contact laws OpenSees has exactly: a linear spring (our ``kelvin-voigt``
  with damping 0 = ``ElasticPPGap``) and Hertz with nonlinear damping (our
  ``lankarani-nikravesh`` = ``Hertzdamp``; bench/opensees/opensees_pair.py);
* the reference: vibroimpact at rtol 1e-10, drifts sampled at dt_rec / 32;
* OpenSees' time-step convergence: dt = dt_rec / m, m = 1 ... 32, each
  run's peak impact force and peak storey drifts against the reference;
* OpenSees at its best: at the coarsest converged step, its solver settings
  scanned (equation solver, Newton variant, test tolerance, the explicit
  central-difference integrator), the fastest kept if it is still within
  1 %; vibroimpact's settings scanned the same way (integrator global or
  local, method DOP853 or DOPRI5, rtol, sampling step);
* speed: each side's fastest setting with peak force and every peak drift
  within 1 % of the reference, median wall time of repeated runs (ours the
  pounding run alone, ``vi.pounding(free=False)``; OpenSees' model build
  and analysis); target ratio >= 10.

Run it in the checkout's virtual environment after ``bash scripts/test.sh``:
``.venv/bin/python bench/opensees/pounding_peer.py [--quick] [--out FILE]``
(openseespy is installed by scripts/test.sh). The machine should be idle.
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import statistics
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import vibroimpact as vi  # noqa: E402
from vibroimpact.records import fema_p695  # noqa: E402

from opensees_pair import import_opensees, run  # noqa: E402

PAIR = ROOT / "examples" / "pounding-frames.toml"
LAWS = {
    "linear": {"law": "kelvin-voigt", "stiffness": 5e8, "damping": 0.0},
    "hertzdamp": {"law": "lankarani-nikravesh", "stiffness": 2.75e9, "exponent": 1.5, "restitution": 0.6},
}
TARGET_ACCURACY = 0.01
TARGET_RATIO = 10.0


def pair_with(law):
    """(parsed pair, TOML text) of the example pair with ``law``."""
    pair = tomllib.loads(PAIR.read_text())
    pair["law"] = law
    inline = ", ".join(f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v!r}" for k, v in law.items())
    lines = [line for line in PAIR.read_text().splitlines() if not line.startswith("law =")]
    at = lines.index("[left]")
    lines.insert(at, f"law = {{ {inline} }}")
    return pair, "\n".join(lines) + "\n"


def peaks_of_ours(result):
    p = result["runs"][0]["pounding"]
    drift = p["peak_drift"]
    return float(p["peak_impact_force"]), [list(map(float, drift[side])) for side in ("left", "right")]


def error(force, drift, ref):
    """Largest relative difference of the peak force and every peak drift."""
    rf, rd = ref
    worst = abs(force - rf) / rf
    for side, rside in zip(drift, rd):
        for d, r in zip(side, rside):
            worst = max(worst, abs(d - r) / r)
    return worst


def timed(f, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def study(name, law, record, quick):
    pair, text = pair_with(law)
    t, a = np.asarray(record["times"]), np.asarray(record["acceleration"])
    rec_dt = record["dt"]
    ref_result = vi.pounding(text, record, sample=rec_dt / 32, rtol=1e-10, free=False)
    ref = peaks_of_ours(ref_result)
    print(f"\n== {name}: {law}")
    print(f"reference (vibroimpact rtol 1e-10, sample dt/32): peak force {ref[0]:.6e} N, "
          f"{ref_result['runs'][0]['pounding']['impacts']} impacts, drifts {ref[1]}")

    convergence = []
    print("OpenSees time-step convergence (Newmark average acceleration, Newton, BandGeneral):")
    for m in (1, 2, 4, 8, 16, 32)[: 5 if quick else 6]:
        o = run(pair, t, a, 1.0, rec_dt / m)
        err = error(o["peak_impact_force"], o["peak_drift"], ref)
        convergence.append({**o, "m": m, "error": err})
        print(f"  dt = dt_rec/{m:<2d} {o['seconds']:7.3f} s  peak force {o['peak_impact_force']:.6e} N  error {err:.2e}")
    converged = [c for c in convergence if c["error"] <= TARGET_ACCURACY]
    if not converged:
        raise SystemExit(f"{name}: OpenSees did not reach {TARGET_ACCURACY:.0%} at any step")
    m = converged[0]["m"]

    repeats = 3 if quick else 7
    settings = []
    variants = [
        {"system": s, "algorithm": alg, "tol": tol, "integrator": "Newmark"}
        for s in ("BandGeneral", "FullGeneral", "ProfileSPD", "UmfPack")
        for alg in ("Newton", "ModifiedNewton", "KrylovNewton")
        for tol in (1e-10, 1e-6)
    ]
    variants += [{"system": "BandGeneral", "algorithm": "Linear", "tol": 0.0, "integrator": "CentralDifference"}]
    print(f"OpenSees settings at dt = dt_rec/{m} (median of {repeats}); the explicit one at every step:")
    for v in variants:
        steps = (1, 2, 4, 8, 16) if v["integrator"] == "CentralDifference" else (m,)
        for mm in steps:
            try:
                secs, o = timed(lambda: run(pair, t, a, 1.0, rec_dt / mm, **v), repeats)
                err = error(o["peak_impact_force"], o["peak_drift"], ref)
            except (RuntimeError, ValueError) as e:
                secs, err = float("nan"), float("inf")
                print(f"  {v} m={mm}: failed ({e})")
            else:
                print(f"  {v} m={mm}: {secs * 1e3:8.2f} ms  error {err:.2e}")
            settings.append({**v, "m": mm, "seconds": secs, "error": err})
    ok = [s for s in settings if s["error"] <= TARGET_ACCURACY]
    best_os = min(ok, key=lambda s: s["seconds"])

    ours = []
    print(f"vibroimpact settings (pounding run alone, median of {repeats}):")
    for integrator in ("global", "local"):
        for method in ("dop853", "dopri5"):
            for rtol in (1e-3, 1e-4, 1e-6, 1e-8):
                for div in (1, 2, 4):
                    sample = rec_dt / div
                    secs, res = timed(
                        lambda: vi.pounding(
                            text, record, sample=sample, rtol=rtol, method=method, integrator=integrator, free=False
                        ),
                        repeats,
                    )
                    err = error(*peaks_of_ours(res), ref)
                    ours.append(
                        {"integrator": integrator, "method": method, "rtol": rtol, "sample": sample,
                         "seconds": secs, "error": err}
                    )
                    print(f"  {integrator} {method} rtol {rtol:.0e} sample dt_rec/{div}: "
                          f"{secs * 1e3:8.2f} ms  error {err:.2e}")
    best_ours = min((s for s in ours if s["error"] <= TARGET_ACCURACY), key=lambda s: s["seconds"])
    ratio = best_os["seconds"] / best_ours["seconds"]
    finest = convergence[-1]
    agreement = error(finest["peak_impact_force"], finest["peak_drift"], ref)
    print(f"OpenSees at dt_rec/{finest['m']} against the reference: {agreement:.2e}")
    print(f"best OpenSees {best_os['seconds'] * 1e3:.2f} ms ({best_os}), best vibroimpact "
          f"{best_ours['seconds'] * 1e3:.2f} ms ({best_ours}): ratio {ratio:.1f} (target >= {TARGET_RATIO:g})")
    return {
        "law": law,
        "reference": {"peak_impact_force": ref[0], "peak_drift": ref[1], "impacts": ref_result["runs"][0]["pounding"]["impacts"]},
        "opensees_convergence": convergence,
        "opensees_settings": settings,
        "vibroimpact_settings": ours,
        "opensees_finest_vs_reference": agreement,
        "best_opensees": best_os,
        "best_vibroimpact": best_ours,
        "ratio": ratio,
        "meets_target": ratio >= TARGET_RATIO and agreement <= TARGET_ACCURACY,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", type=int, default=0, help="index in the far-field set (0: record 1, component a)")
    ap.add_argument("--quick", action="store_true", help="fewer repeats and steps (a smoke run)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / f"pounding-{datetime.date.today()}.json")
    args = ap.parse_args()
    record = fema_p695("farfield")[args.record]
    ops = import_opensees()
    print(f"record {record['source']}: {'; '.join(record['header'])}; dt {record['dt']} s, "
          f"{len(record['times'])} samples, PGA {record['pga']:.3f} m/s2")
    results = {name: study(name, law, record, args.quick) for name, law in LAWS.items()}
    out = {
        "command": " ".join([".venv/bin/python", "bench/opensees/pounding_peer.py", *sys.argv[1:]]),
        "date": str(datetime.date.today()),
        "machine": platform.platform(),
        "python": platform.python_version(),
        "opensees": ops.version(),
        "vibroimpact": vi.__version__,
        "record": {k: record[k] for k in ("source", "header", "dt", "pga")},
        "results": results,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(args.out)
    print(f"\nwrote {args.out}")
    failed = [n for n, r in results.items() if not r["meets_target"]]
    if failed:
        raise SystemExit(f"targets not met: {', '.join(failed)}")


if __name__ == "__main__":
    main()
