"""Timing shared by the OpenSees studies (pounding_peer.py, isolated_peer.py):
medians of repeated runs, OpenSees' solver settings scanned, the two best
settings retimed alternately, and a watch that polls whether the machine
is busy while a study runs. ``busy``
is each study's own test (a function returning the busy process ids)."""

from __future__ import annotations

import os
import statistics
import threading
import time


def timed(f, repeats):
    """The median wall time of ``repeats`` calls of ``f`` and its last result."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


# OpenSees' settings both studies scan: every equation solver, Newton
# variant and test tolerance with Newmark's average acceleration, and the
# explicit CentralDifference.
OPENSEES_VARIANTS = [
    {"system": s, "algorithm": alg, "tol": tol, "integrator": "Newmark"}
    for s in ("BandGeneral", "FullGeneral", "ProfileSPD", "UmfPack")
    for alg in ("Newton", "ModifiedNewton", "KrylovNewton")
    for tol in (1e-10, 1e-6)
] + [{"system": "BandGeneral", "algorithm": "Linear", "tol": 0.0, "integrator": "CentralDifference"}]


def scan_opensees(run_at, judged, m, repeats, keep_errors=True):
    """Every one of ``OPENSEES_VARIANTS`` timed (median of ``repeats``) by
    ``run_at(mm, variant)`` at the step dt_rec/``m`` (the explicit one at
    dt_rec/1 ... dt_rec/16) and judged by ``judged(output) -> (error,
    errors)``; a run that fails has an infinite error. Returns the
    settings with their times and errors (``errors`` kept if
    ``keep_errors``)."""
    settings = []
    for v in OPENSEES_VARIANTS:
        steps = (1, 2, 4, 8, 16) if v["integrator"] == "CentralDifference" else (m,)
        for mm in steps:
            e = {}
            try:
                secs, o = timed(lambda: run_at(mm, v), repeats)
                err, e = judged(o)
            except (RuntimeError, ValueError) as ex:
                secs, err = float("nan"), float("inf")
                print(f"  {v} m={mm}: failed ({ex})")
            else:
                print(f"  {v} m={mm}: {secs * 1e3:8.2f} ms  error {err:.2e}")
            settings.append({**v, "m": mm, "seconds": secs, "error": err, **({"errors": e} if keep_errors else {})})
    return settings


def retime(opensees, ours, rounds, repeats, busy):
    """The two best settings timed again, alternating, in ``rounds`` rounds
    of ``repeats`` runs each (medians); a round is idle when ``busy`` saw
    nothing at its start, between the two sides or at its end: the ratio of
    the medians over the idle rounds (None if none was) and over all."""
    out = []
    for _ in range(rounds):
        seen = busy()
        os_secs, _ = timed(opensees, repeats)
        seen += busy()
        our_secs, _ = timed(ours, repeats)
        seen += busy()
        out.append({"opensees": os_secs, "vibroimpact": our_secs, "idle": not seen})
    idle = [r for r in out if r["idle"]]

    def ratio(rows):
        return statistics.median(r["opensees"] for r in rows) / statistics.median(r["vibroimpact"] for r in rows)

    return {"rounds": out, "idle_rounds": len(idle), "ratio_idle": ratio(idle) if idle else None, "ratio_all": ratio(out)}


class Watch:
    """Polls ``busy`` every ``every`` seconds in a thread while the study
    runs: the processes seen, and how many polls saw one."""

    def __init__(self, busy, every=2.0):
        self.busy, self.every, self.polls, self.busy_polls, self.seen = busy, every, 0, 0, set()
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._poll, daemon=True)

    def _poll(self):
        while not self.stop.is_set():
            pids = self.busy()
            self.polls += 1
            self.busy_polls += bool(pids)
            self.seen.update(pids)
            self.stop.wait(self.every)

    def __enter__(self):
        self.load_before = os.getloadavg()
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join()
        self.load_after = os.getloadavg()

    def report(self):
        return {
            "idle": self.busy_polls == 0,
            "polls": self.polls,
            "polls_busy": self.busy_polls,
            "busy_pids": sorted(self.seen),
            "load_before": self.load_before,
            "load_after": self.load_after,
        }
