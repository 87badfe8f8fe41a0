#!/usr/bin/env python3
"""vibroimpact against OpenSees (openseespy) on an isolated building striking
its moat wall (issue 27; docs/earthquakes.md, "Isolated buildings";
bench/opensees/ISOLATED.md):

* the building of bench/opensees/isolated-moat.toml (lead-rubber bearings,
  bilinear = ``Steel01``, with a viscous damper; four bilinear storeys; a
  rigid moat wall 30 cm from the slab) under FEMA P695 far-field record 1a
  (Northridge 1994, Beverly Hills - Mulholland) x ``SCALE``, run through
  its free-vibration tail of 5 T, with the two moat laws OpenSees has
  exactly: Lankarani-Nikravesh (the file's; ``Hertzdamp``) and a linear
  spring (``kelvin-voigt`` with damping 0; ``ElasticPPGap``);
  bench/opensees/opensees_isolated.py builds the OpenSees model;
* the reference: vibroimpact at rtol 1e-10, sampled at dt_rec / 32;
* OpenSees' time-step convergence (Newmark average acceleration, Newton,
  ``BandGeneral``, ``NormDispIncr 1e-10``): dt = dt_rec / m, m = 1 ... 64,
  against the reference, and its converged step: the coarsest within 1 %
  of its own finest run;
* compared: every peak storey drift (storey 1 = floor 1 - slab, relative
  to itself), every residual drift (its difference over the storey's
  yield drift: a residual drift can be near zero, where relative to
  itself it is ill-posed; that measure is reported as ``residual_self``,
  not judged), the slab's peak displacement and the peak moat force
  (relative); the moat impacts are counted and reported;
* OpenSees at its best: at the coarsest step within 1 % of the reference,
  its solver settings scanned (timing.OPENSEES_VARIANTS: equation
  solver, Newton variant with or without ``-factoronce``, test
  tolerance; the explicit ``CentralDifference`` (``Linear``, and
  ``Linear -factorOnce``) and ``ExplicitDifference`` (``Linear
  -factorOnce``) at dt_rec / m,
  m = 1 ... 16); ours scanned (integrator global or local; method DOP853
  or DOPRI5; rtol 1e-3 ... 1e-8; drift
  sampling dt_rec, dt_rec / 2, dt_rec / 4); each side's fastest within
  1 % of the reference;
* speed: the ratio of the two best median times (ours the run with its
  contacts alone, ``free=False``; OpenSees' model build and analysis, no
  impact counting), then the two retimed in alternating rounds.

Timing waits for an idle machine: before each timed phase, until no
process named like ``pounding_peer``, ``cargo``, ``rustc`` or ``pytest``
runs (``pgrep -f``, judged on each match's program and script names so
that a process merely carrying such a word in its environment does not
count), and records what it saw.

Run it in the checkout's virtual environment (openseespy installed by
scripts/test.sh): ``.venv/bin/python bench/opensees/isolated_peer.py
[--quick] [--law hertzdamp|linear] [--out FILE]``; writes
``results/isolated-moat-<date>.json`` and prints the tables.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import vibroimpact as vi  # noqa: E402
from vibroimpact.records import fema_p695  # noqa: E402

from opensees_isolated import load, run, yield_drifts  # noqa: E402
from opensees_pair import import_opensees  # noqa: E402
from timing import IdleGate, Watch, finite, retime, scan_opensees, timed  # noqa: E402

CASE = HERE / "isolated-moat.toml"
SCALE = 2.2
"""The record's scale: 1a x 2.2 strikes the moat 4 times and yields every
storey (peak drift 1.3 to 3.3 yield drifts)."""
LAWS = {
    "hertzdamp": None,  # the file's: lankarani-nikravesh, k = 2e10, n = 1.5, e = 0.6
    "linear": {"law": "kelvin-voigt", "stiffness": 3.0e9, "damping": 0.0},
}
TARGET_ACCURACY = 0.01
TARGET_RATIO = 10.0
BUSY = re.compile(r"pounding_peer|cargo|rustc|pytest")


def case_with(law=None):
    """(parsed building, TOML text) of the case with the moat ``law`` (None:
    the file's own)."""
    text = CASE.read_text()
    if law is not None:
        gap = load(text)["isolation"]["moat"]["gap"]
        inline = ", ".join(f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v!r}" for k, v in law.items())
        lines = [
            f"moat = {{ gap = {gap!r}, law = {{ {inline} }} }}" if line.startswith("moat =") else line
            for line in text.splitlines()
        ]
        text = "\n".join(lines) + "\n"
    return load(text), text


def peaks_of_ours(result, name="isolated"):
    """The compared quantities of a one-record pounding document."""
    p = result["runs"][0]["pounding"]
    iso = p["isolators"][name]
    return {
        "peak_drift": [float(d) for d in p["peak_drift"][name]],
        "residual_drift": [float(d) for d in p["residual_drift"][name]],
        "peak_displacement": float(iso["peak_displacement"]),
        "residual_displacement": float(iso["residual_displacement"]),
        "moat_peak_force": float(iso["moat_peak_force"]),
        "moat_impacts": int(iso["moat_impacts"]),
    }


def errors(peaks, ref, uy):
    """The differences from ``ref``: ``drift`` (the largest relative over
    the storeys), ``residual`` (the largest over the storey's yield drift
    ``uy``; judged), ``residual_self`` (relative to the reference residual
    itself; reported, not judged), ``displacement`` and ``force``
    (relative); ``error`` the judged worst."""
    out = {
        "drift": max(abs(d - r) / r for d, r in zip(peaks["peak_drift"], ref["peak_drift"])),
        "residual": max(
            abs(d - r) / y for d, r, y in zip(peaks["residual_drift"], ref["residual_drift"], uy) if y
        ),
        "residual_self": max(abs(d - r) / abs(r) for d, r in zip(peaks["residual_drift"], ref["residual_drift"])),
        "displacement": abs(peaks["peak_displacement"] - ref["peak_displacement"]) / ref["peak_displacement"],
        "force": abs(peaks["moat_peak_force"] - ref["moat_peak_force"]) / ref["moat_peak_force"],
    }
    out["error"] = max(v for k, v in out.items() if k != "residual_self")
    return out


def shown(e):
    return "  ".join(f"{k} {v:.1e}" for k, v in e.items() if k != "error")


GATE = IdleGate(BUSY)
"""The idle machine this study waits for (``timing.IdleGate``)."""
busy = GATE.busy
wait_idle = GATE.wait_idle


def study(name, building, text, record, quick, waits):
    """The study of the case with one moat law."""
    t, a = np.asarray(record["times"]), np.asarray(record["acceleration"])
    rec_dt = record["dt"]
    uy = yield_drifts(building)
    ref = peaks_of_ours(vi.pounding(text, record, scale=SCALE, sample=rec_dt / 32, rtol=1e-10, free=False))
    print(f"\n== {name}: moat {building['isolation']['moat']['law']}, record x {SCALE}")
    print(f"reference (vibroimpact rtol 1e-10, sample dt_rec/32): {ref['moat_impacts']} moat impacts, peak moat "
          f"force {ref['moat_peak_force']:.6e} N, slab peak {ref['peak_displacement']:.6f} m")
    print(f"  peak drifts {np.round(ref['peak_drift'], 6).tolist()} m (ductility "
          f"{[round(d / y, 2) for d, y in zip(ref['peak_drift'], uy)]})")
    print(f"  residual drifts {np.round(ref['residual_drift'], 6).tolist()} m "
          f"({[round(d / y, 3) for d, y in zip(ref['residual_drift'], uy)]} yield drifts)")

    def judged(peaks):
        e = errors(peaks, ref, uy)
        return e["error"], e

    convergence = []
    print("OpenSees time-step convergence (Newmark average acceleration, Newton, BandGeneral, tol 1e-10):")
    for m in (1, 2, 4, 8, 16, 32, 64)[: 5 if quick else None]:
        try:
            o = run(text, t, a, SCALE, rec_dt / m, impacts=True)
        except RuntimeError as ex:
            convergence.append({"m": m, "dt": rec_dt / m, "failed": str(ex), "error": float("inf")})
            print(f"  dt = dt_rec/{m:<2d} failed ({ex})")
            continue
        err, e = judged(o)
        convergence.append({**o, "m": m, "error": err, "errors": e})
        print(f"  dt = dt_rec/{m:<2d} {o['seconds']:7.3f} s  {o['moat_impacts']} impacts  error {err:.2e} ({shown(e)})")
    ran = [c for c in convergence if "failed" not in c]
    finest = ran[-1]
    # OpenSees converged on its own: the coarsest step within 1 % of its
    # finest run (the reference there OpenSees', not ours).
    own = min((c for c in ran if errors(c, finest, uy)["error"] <= TARGET_ACCURACY), key=lambda c: c["m"])
    print(f"OpenSees' converged step (the coarsest within 1 % of its dt_rec/{finest['m']}): dt_rec/{own['m']}; "
          f"there against the reference {own['error']:.2e} ({shown(own['errors'])}), "
          f"{own['moat_impacts']} impacts (ours {ref['moat_impacts']})")
    ok = [c for c in ran if c["error"] <= TARGET_ACCURACY]
    if not ok:
        raise SystemExit(f"{name}: OpenSees did not reach {TARGET_ACCURACY:.0%} at any step")
    m = ok[0]["m"]

    repeats = 2 if quick else 5
    waits.append({"before": f"{name}: OpenSees settings", **wait_idle()})
    print(f"OpenSees settings at dt = dt_rec/{m} (median of {repeats}); the explicit one at every step:")
    settings = scan_opensees(lambda mm, v: run(text, t, a, SCALE, rec_dt / mm, **v), judged, m, repeats)
    best_os = min((s for s in settings if s["error"] <= TARGET_ACCURACY), key=lambda s: s["seconds"])

    waits.append({"before": f"{name}: vibroimpact settings", **wait_idle()})
    ours = []
    print(f"vibroimpact settings (the run with its contacts alone, median of {repeats}):")
    for integrator in ("global", "local"):
        for method in ("dop853", "dopri5"):
            for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
                for div in (1, 2, 4):
                    sample = rec_dt / div
                    secs, res = timed(
                        lambda: vi.pounding(text, record, scale=SCALE, sample=sample, rtol=rtol, method=method,
                                            integrator=integrator, free=False),
                        repeats,
                    )
                    peaks = peaks_of_ours(res)
                    err, e = judged(peaks)
                    ours.append({"integrator": integrator, "method": method, "rtol": rtol, "sample": sample,
                                 "seconds": secs, "error": err, "errors": e,
                                 "moat_impacts": peaks["moat_impacts"]})
                    print(f"  {integrator} {method} rtol {rtol:.0e} sample dt_rec/{div}: {secs * 1e3:8.2f} ms  "
                          f"{peaks['moat_impacts']} impacts  error {err:.2e}")
    best_ours = min((s for s in ours if s["error"] <= TARGET_ACCURACY), key=lambda s: s["seconds"])
    ratio = best_os["seconds"] / best_ours["seconds"]
    # Our best against OpenSees at its converged step and at its finest.
    fast = peaks_of_ours(vi.pounding(text, record, scale=SCALE, free=False,
                                     **{k: best_ours[k] for k in ("sample", "rtol", "method", "integrator")}))
    fast_vs = {f"dt_rec/{c['m']}": errors(fast, c, uy) for c in (own, finest)}
    waits.append({"before": f"{name}: retiming", **wait_idle()})
    speed = retime(
        lambda: run(text, t, a, SCALE, rec_dt / best_os["m"],
                    **{k: best_os[k] for k in ("system", "algorithm", "tol", "integrator")}),
        lambda: vi.pounding(text, record, scale=SCALE, free=False,
                            **{k: best_ours[k] for k in ("sample", "rtol", "method", "integrator")}),
        3 if quick else 7,
        repeats,
        busy,
    )
    print(f"best OpenSees {best_os['seconds'] * 1e3:.2f} ms ({ {k: best_os[k] for k in ('system', 'algorithm', 'tol', 'integrator', 'm')} }, "
          f"error {best_os['error']:.1e}); best vibroimpact {best_ours['seconds'] * 1e3:.2f} ms "
          f"({ {k: best_ours[k] for k in ('method', 'rtol', 'sample')} }, error {best_ours['error']:.1e}): "
          f"ratio {ratio:.1f} (target >= {TARGET_RATIO:g})")
    print(f"the two retimed in {len(speed['rounds'])} rounds, {speed['idle_rounds']} idle: ratio "
          f"{speed['ratio_idle'] if speed['ratio_idle'] is None else round(speed['ratio_idle'], 1)} (idle rounds), "
          f"{speed['ratio_all']:.1f} (all)")
    for k, e in fast_vs.items():
        print(f"our best against OpenSees at {k}: {e['error']:.2e} ({shown(e)})")
    return {
        "law": building["isolation"]["moat"]["law"],
        "reference": {**ref, "yield_drift": uy},
        "opensees_convergence": convergence,
        "opensees_converged_step": {"m": own["m"], "against_reference": own["errors"],
                                    "moat_impacts": own["moat_impacts"]},
        "opensees_finest_vs_reference": finest["errors"],
        "opensees_settings": settings,
        "vibroimpact_settings": ours,
        "best_opensees": best_os,
        "best_vibroimpact": best_ours,
        "best_vibroimpact_vs_opensees": fast_vs,
        "ratio": ratio,
        "retimed": speed,
        "meets_target": ratio >= TARGET_RATIO and own["error"] <= TARGET_ACCURACY,
    }


def table(results):
    """The summary table (markdown) of the results."""
    rows = ["| moat law | impacts (ours / OpenSees) | OpenSees converged step | peak drifts | residual drifts / u_y "
            "(/ themselves) | slab peak | moat force | OpenSees best | ours best | ratio |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, r in results.items():
        c = r["opensees_converged_step"]
        e = c["against_reference"]
        b, o = r["best_opensees"], r["best_vibroimpact"]
        os_set = (f"{b['seconds'] * 1e3:.0f} ms: {b['integrator']}, {b['system']}, {b['algorithm']}, tol {b['tol']:.0e}, "
                  f"dt_rec/{b['m']} ({b['error']:.1e})")
        our_set = (f"{o['seconds'] * 1e3:.1f} ms: {o['method']}, rtol {o['rtol']:.0e}, sample dt_rec/"
                   f"{round(0.01 / o['sample'])} ({o['error']:.1e})")
        rows.append(f"| {name} | {r['reference']['moat_impacts']} / {c['moat_impacts']} | dt_rec/{c['m']} | "
                    f"{e['drift']:.1e} | {e['residual']:.1e} ({e['residual_self']:.1e}) | {e['displacement']:.1e} | "
                    f"{e['force']:.1e} | {os_set} | {our_set} | {r['ratio']:.0f} |")
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats and steps (a smoke run)")
    ap.add_argument("--law", choices=sorted(LAWS), action="append", help="default: both")
    ap.add_argument("--out", type=Path, help="default: results/isolated-moat-<date>.json")
    ap.add_argument("--no-wait", action="store_true", help="time without waiting for an idle machine")
    args = ap.parse_args()
    GATE.no_wait = args.no_wait
    if args.out is None:
        args.out = HERE / "results" / f"isolated-moat-{datetime.date.today()}.json"
    record = fema_p695("farfield")[0]
    ops = import_opensees()
    print(f"record {record['source']}: {'; '.join(record['header'])}; dt {record['dt']} s, "
          f"{len(record['times'])} samples, PGA {record['pga']:.3f} m/s2, x {SCALE}")
    waits = []
    with Watch(busy) as watch:
        results = {name: study(name, *case_with(LAWS[name]), record, args.quick, waits)
                   for name in (args.law or list(LAWS))}
    idle = watch.report()
    print(f"\nmachine idle (nothing busy at any poll): {idle}")
    print("\n" + table(results))
    out = {
        "command": " ".join([".venv/bin/python", "bench/opensees/isolated_peer.py", *sys.argv[1:]]),
        "date": str(datetime.date.today()),
        "machine": platform.platform(),
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "opensees": ops.version(),
        "vibroimpact": vi.__version__,
        "record": {k: record[k] for k in ("source", "header", "dt", "pga")},
        "scale": SCALE,
        "case": str(CASE.relative_to(HERE.parents[1])),
        "machine_idle": idle,
        "waits_for_idle": waits,
        "results": results,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".tmp")
    tmp.write_text(json.dumps(finite(out), indent=1, allow_nan=False) + "\n")
    tmp.replace(args.out)
    print(f"\nwrote {args.out}")
    failed = [n for n, r in results.items() if not r["meets_target"]]
    if failed:
        raise SystemExit(f"targets not met: {', '.join(failed)}")


if __name__ == "__main__":
    main()
