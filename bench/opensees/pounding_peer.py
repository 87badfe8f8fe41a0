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
  and analysis); target ratio >= 10. The two are then timed again in
  rounds, alternating, and the ratio of the medians over the rounds with
  no compiler running is recorded too (``retimed``).

``--case inelastic``: the same study of bench/opensees/inelastic-pair.toml
(the frames with bilinear storeys, OpenSees ``Steel01``; Hertz-damp
contact) run through its free-vibration tail, the residual drifts compared
too: their difference over the storey's yield drift within 1 % (a residual
drift can be near zero, so relative to itself it is reported but not
judged); OpenSees' steps down to dt_rec / 64, and its agreement also at
its own converged step (the coarsest within 1 % of its finest run);
vibroimpact's integrator global or local; then OpenSees' convergence with the storeys Bouc-Wen (``BoucWen``,
first order in the step: not timed); writes
``results/inelastic-pounding-<date>.json``.

Run it in the checkout's virtual environment after ``bash scripts/test.sh``:
``.venv/bin/python bench/opensees/pounding_peer.py [--case inelastic]
[--quick] [--out FILE]`` (openseespy is installed by scripts/test.sh). The
machine should be idle: the results record whether rustc or cargo ran.
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import vibroimpact as vi  # noqa: E402
from vibroimpact.records import fema_p695  # noqa: E402

from opensees_pair import import_opensees, inelastic, run  # noqa: E402
from timing import Watch, finite, retime, scan_opensees, timed  # noqa: E402

PAIR = ROOT / "examples" / "pounding-frames.toml"
INELASTIC_PAIR = HERE / "inelastic-pair.toml"
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
    """The compared quantities of a one-record pounding document: peak force,
    peak drifts [left, right] and, with yielding storeys, residual drifts."""
    p = result["runs"][0]["pounding"]
    out = {
        "peak_impact_force": float(p["peak_impact_force"]),
        "peak_drift": [list(map(float, p["peak_drift"][side])) for side in ("left", "right")],
    }
    if "residual_drift" in p:
        out["residual_drift"] = [list(map(float, p["residual_drift"][side])) for side in ("left", "right")]
    return out


def yield_drifts(pair):
    """[left, right] yield drifts of a pair's storeys (None if all elastic)."""
    if not any(inelastic(pair[side]) for side in ("left", "right")):
        return None
    return [[s["yield_drift"] for s in pair[side]["storeys"]] for side in ("left", "right")]


def errors(peaks, ref, uy=None):
    """The differences from ``ref``: ``force`` and ``drift`` relative (the
    largest over the storeys), with yield drifts ``uy`` the residual drifts'
    ``residual`` (over the yield drift, judged) and ``residual_self`` (over
    the reference residual itself, reported); ``error`` the judged worst."""
    out = {"force": abs(peaks["peak_impact_force"] - ref["peak_impact_force"]) / ref["peak_impact_force"]}
    out["drift"] = max(
        abs(d - r) / r for side, rside in zip(peaks["peak_drift"], ref["peak_drift"]) for d, r in zip(side, rside)
    )
    if uy is not None:
        pairs = [
            (d, r, y)
            for side, rside, yside in zip(peaks["residual_drift"], ref["residual_drift"], uy)
            for d, r, y in zip(side, rside, yside)
        ]
        out["residual"] = max(abs(d - r) / y for d, r, y in pairs)
        out["residual_self"] = max(abs(d - r) / abs(r) for d, r, _ in pairs)
    out["error"] = max(v for k, v in out.items() if k != "residual_self")
    return out


def study(name, pair, text, record, quick):
    """The study of one pair (parsed, and its TOML text) under ``record``."""
    t, a = np.asarray(record["times"]), np.asarray(record["acceleration"])
    rec_dt = record["dt"]
    uy = yield_drifts(pair)
    ref_result = vi.pounding(text, record, sample=rec_dt / 32, rtol=1e-10, free=False)
    ref = peaks_of_ours(ref_result)
    impacts = ref_result["runs"][0]["pounding"]["impacts"]
    print(f"\n== {name}: {pair['law']}")
    print(f"reference (vibroimpact rtol 1e-10, sample dt/32): peak force {ref['peak_impact_force']:.6e} N, "
          f"{impacts} impacts, drifts {ref['peak_drift']}")
    if uy is not None:
        print(f"  residual drifts {ref['residual_drift']}, yield drifts {uy}, ductility "
              f"{[[round(d / y, 2) for d, y in zip(ds, ys)] for ds, ys in zip(ref['peak_drift'], uy)]}")

    def judged(peaks):
        e = errors(peaks, ref, uy)
        return e["error"], e

    def shown(e):
        return "  ".join(f"{k} {v:.1e}" for k, v in e.items() if k != "error")

    convergence = []
    print("OpenSees time-step convergence (Newmark average acceleration, Newton, BandGeneral):")
    # Yield and contact onsets fall inside steps: the inelastic pair's
    # convergence is irregular, so it is followed one halving further.
    for m in ((1, 2, 4, 8, 16, 32) + ((64,) if uy else ()))[: 5 if quick else None]:
        o = run(pair, t, a, 1.0, rec_dt / m)
        err, e = judged(o)
        convergence.append({**o, "m": m, "error": err, "errors": e})
        print(f"  dt = dt_rec/{m:<2d} {o['seconds']:7.3f} s  peak force {o['peak_impact_force']:.6e} N  "
              f"error {err:.2e} ({shown(e)})")
    converged = [c for c in convergence if c["error"] <= TARGET_ACCURACY]
    if not converged:
        raise SystemExit(f"{name}: OpenSees did not reach {TARGET_ACCURACY:.0%} at any step")
    m = converged[0]["m"]
    finest = convergence[-1]
    # OpenSees converged on its own: the coarsest step within 1 % of its
    # finest run (the reference there OpenSees', not ours).
    own = min(
        (c for c in convergence if errors(c, finest, uy)["error"] <= TARGET_ACCURACY), key=lambda c: c["m"]
    )

    repeats = 3 if quick else 7
    print(f"OpenSees settings at dt = dt_rec/{m} (median of {repeats}); the explicit ones at every step:")
    settings = scan_opensees(
        lambda mm, v: run(pair, t, a, 1.0, rec_dt / mm, **v), judged, m, repeats, keep_errors=bool(uy)
    )
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
                    err, e = judged(peaks_of_ours(res))
                    ours.append(
                        {"integrator": integrator, "method": method, "rtol": rtol, "sample": sample,
                         "seconds": secs, "error": err, **({"errors": e} if uy else {})}
                    )
                    print(f"  {integrator} {method} rtol {rtol:.0e} sample dt_rec/{div}: "
                          f"{secs * 1e3:8.2f} ms  error {err:.2e}")
    best_ours = min((s for s in ours if s["error"] <= TARGET_ACCURACY), key=lambda s: s["seconds"])
    ratio = best_os["seconds"] / best_ours["seconds"]
    speed = retime(
        lambda: run(pair, t, a, 1.0, rec_dt / best_os["m"],
                    **{k: best_os[k] for k in ("system", "algorithm", "tol", "integrator")}),
        lambda: vi.pounding(text, record, free=False,
                            **{k: best_ours[k] for k in ("sample", "rtol", "method", "integrator")}),
        3 if quick else 9,
        repeats,
        busy,
    )
    agreement = finest["error"]
    print(f"OpenSees at dt_rec/{finest['m']} against the reference: {agreement:.2e} ({shown(finest['errors'])})")
    print(f"OpenSees converged on its own (within 1 % of dt_rec/{finest['m']}) at dt_rec/{own['m']}: "
          f"against the reference {own['error']:.2e} ({shown(own['errors'])})")
    print(f"best OpenSees {best_os['seconds'] * 1e3:.2f} ms ({best_os}), best vibroimpact "
          f"{best_ours['seconds'] * 1e3:.2f} ms ({best_ours}): ratio {ratio:.1f} (target >= {TARGET_RATIO:g})")
    print(f"the two best retimed in {len(speed['rounds'])} rounds, {speed['idle_rounds']} with no compiler: "
          f"ratio {speed['ratio_idle']} (idle rounds), {speed['ratio_all']:.1f} (all)")
    reference = {"peak_impact_force": ref["peak_impact_force"], "peak_drift": ref["peak_drift"], "impacts": impacts}
    out = {"law": pair["law"], "reference": reference}
    if uy is not None:
        reference.update(residual_drift=ref["residual_drift"], yield_drift=uy)
        out.update(
            opensees_converged_step={"m": own["m"], "against_reference": own["errors"]},
            opensees_finest_vs_reference_errors=finest["errors"],
        )
    return {
        **out,
        "opensees_convergence": convergence,
        "opensees_settings": settings,
        "vibroimpact_settings": ours,
        "opensees_finest_vs_reference": agreement,
        "best_opensees": best_os,
        "best_vibroimpact": best_ours,
        "ratio": ratio,
        "retimed": speed,
        "meets_target": ratio >= TARGET_RATIO and agreement <= TARGET_ACCURACY,
    }


def boucwen_convergence(record, quick):
    """OpenSees' time-step convergence on the inelastic pair with its
    storeys Bouc-Wen (n = 2, beta = gamma = 1/2: the defaults; the same
    yield drifts): OpenSees' ``BoucWen`` takes one backward-Euler step per
    drift increment, first order in the step, so it is kept out of the
    speed comparison; its errors against our reference and their order."""
    text = INELASTIC_PAIR.read_text().replace('law = "bilinear"', 'law = "bouc-wen"')
    pair = tomllib.loads(text)
    uy = yield_drifts(pair)
    t, a = np.asarray(record["times"]), np.asarray(record["acceleration"])
    rec_dt = record["dt"]
    ref = peaks_of_ours(vi.pounding(text, record, sample=rec_dt / 32, rtol=1e-10, free=False))
    print(f"\n== bouc-wen storeys (OpenSees BoucWen), convergence only; reference residual drifts "
          f"{ref['residual_drift']}")
    rows = []
    for m in (1, 2, 4, 8, 16, 32, 64)[: 5 if quick else 7]:
        o = run(pair, t, a, 1.0, rec_dt / m)
        e = errors(o, ref, uy)
        order = np.log2(rows[-1]["error"] / e["error"]) if rows else float("nan")
        rows.append({**o, "m": m, "error": e["error"], "errors": e, "order": order})
        print(f"  dt = dt_rec/{m:<2d} {o['seconds']:7.3f} s  error {e['error']:.2e} (order {order:.2f}; "
              + "  ".join(f"{k} {v:.1e}" for k, v in e.items() if k != "error") + ")")
    return {"law": pair["law"], "storeys": "bouc-wen, n = 2, beta = gamma = 0.5, the bilinear pair's yield drifts",
            "reference": ref, "opensees_convergence": rows}


def busy():
    """Process ids of running compilers (rustc, cargo): the machine is not
    idle while there are any."""
    found = subprocess.run(["pgrep", "-x", "rustc|cargo"], capture_output=True, text=True).stdout.split()
    return [int(pid) for pid in found]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", type=int, default=0, help="index in the far-field set (0: record 1, component a)")
    ap.add_argument("--quick", action="store_true", help="fewer repeats and steps (a smoke run)")
    ap.add_argument("--case", choices=("elastic", "inelastic"), default="elastic",
                    help="elastic: examples/pounding-frames.toml with both laws; inelastic: inelastic-pair.toml")
    ap.add_argument("--out", type=Path, help="default: results/pounding-<date>.json, "
                    "results/inelastic-pounding-<date>.json with --case inelastic")
    args = ap.parse_args()
    if args.out is None:
        prefix = "inelastic-pounding" if args.case == "inelastic" else "pounding"
        args.out = HERE / "results" / f"{prefix}-{datetime.date.today()}.json"
    record = fema_p695("farfield")[args.record]
    ops = import_opensees()
    print(f"record {record['source']}: {'; '.join(record['header'])}; dt {record['dt']} s, "
          f"{len(record['times'])} samples, PGA {record['pga']:.3f} m/s2")
    with Watch(busy) as watch:
        if args.case == "inelastic":
            text = INELASTIC_PAIR.read_text()
            results = {
                "bilinear-hertzdamp": study("bilinear-hertzdamp", tomllib.loads(text), text, record, args.quick),
                "bouc-wen-convergence": boucwen_convergence(record, args.quick),
            }
        else:
            results = {name: study(name, *pair_with(law), record, args.quick) for name, law in LAWS.items()}
    idle = watch.report()
    print(f"\nmachine idle (no rustc or cargo at any poll): {idle}")
    out = {
        "command": " ".join([".venv/bin/python", "bench/opensees/pounding_peer.py", *sys.argv[1:]]),
        "date": str(datetime.date.today()),
        "machine": platform.platform(),
        "python": platform.python_version(),
        "opensees": ops.version(),
        "vibroimpact": vi.__version__,
        "record": {k: record[k] for k in ("source", "header", "dt", "pga")},
        "machine_idle": idle,
        "results": results,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(finite(out), indent=1, allow_nan=False) + "\n")
    tmp.replace(args.out)
    print(f"\nwrote {args.out}")
    failed = [n for n, r in results.items() if not r.get("meets_target", True)]
    if failed:
        raise SystemExit(f"targets not met: {', '.join(failed)}")


if __name__ == "__main__":
    main()
