"""Timing shared by the OpenSees studies (pounding_peer.py, isolated_peer.py):
medians of repeated runs, OpenSees' solver settings scanned, the two best
settings retimed alternately, and a watch that polls whether the machine
is busy while a study runs. ``busy``
is each study's own test (a function returning the busy process ids)."""

from __future__ import annotations

import math
import os
import statistics
import threading
import time
from pathlib import Path


def timed(f, repeats):
    """The median wall time of ``repeats`` calls of ``f`` and its last result."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


# OpenSees' settings the studies scan: every equation solver, Newton
# variant and test tolerance with Newmark's average acceleration; the
# explicit CentralDifference; and ExplicitDifference on the lumped mass
# (system Diagonal). "-factorOnce" (Linear) and "-factoronce"
# (ModifiedNewton; the spellings OpenSees 3.7.1 reads, others are ignored
# silently) factor the matrix once: exact where it does not change (an
# explicit rule's M/dt^2 + C/(2 dt) with constant damping; on the IMK
# frame on 2026-12-01 the same drifts to the last digit in 14.9 ms
# against 19.9 ms), judged like the rest where it does.
EXPLICIT = ("CentralDifference", "ExplicitDifference")
OPENSEES_VARIANTS = [
    {"system": s, "algorithm": alg, "tol": tol, "integrator": "Newmark"}
    for s in ("BandGeneral", "FullGeneral", "ProfileSPD", "UmfPack")
    for alg in ("Newton", "ModifiedNewton", "ModifiedNewton -factoronce", "KrylovNewton")
    for tol in (1e-10, 1e-6)
] + [
    {"system": "BandGeneral", "algorithm": alg, "tol": 0.0, "integrator": "CentralDifference"}
    for alg in ("Linear", "Linear -factorOnce")
] + [{"system": "Diagonal", "algorithm": "Linear -factorOnce", "tol": 0.0, "integrator": "ExplicitDifference"}]


def scan_opensees(run_at, judged, m, repeats, keep_errors=True):
    """Every one of ``OPENSEES_VARIANTS`` timed (median of ``repeats``) by
    ``run_at(mm, variant)`` at the step dt_rec/``m`` (the explicit ones at
    dt_rec/1 ... dt_rec/16) and judged by ``judged(output) -> (error,
    errors)``; a run that fails has an infinite error. Returns the
    settings with their times and errors (``errors`` kept if
    ``keep_errors``)."""
    settings = []
    for v in OPENSEES_VARIANTS:
        steps = (1, 2, 4, 8, 16) if v["integrator"] in EXPLICIT else (m,)
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


def _ancestors():
    """This process and those that started it: `cargo run -p
    vibroimpact-bench -- --check` runs a study under `cargo`, which the
    gate would otherwise wait for until its limit (an hour)."""
    pids, pid = set(), os.getpid()
    while pid > 1 and pid not in pids:
        pids.add(pid)
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
            pid = int(stat.rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            break
    return pids


class IdleGate:
    """What a study waits for before each timed phase: no process that
    ``pgrep -f`` lists for ``pattern`` (a compiled regular expression)
    whose program or script (its first three arguments' base names)
    matches it, this one and its ancestors excepted; a plain ``pgrep -f`` also lists
    processes that only carry such a word in their environment, and is
    never empty here. ``no_wait`` (``--no-wait``) times at once (smoke
    runs)."""

    def __init__(self, pattern):
        self.pattern = pattern
        self.no_wait = False

    def busy(self):
        """Process ids of what makes the machine busy."""
        import subprocess
        from pathlib import Path

        found = subprocess.run(["pgrep", "-f", self.pattern.pattern], capture_output=True,
                               text=True).stdout.split()
        pids = []
        mine = _ancestors()
        for pid in map(int, found):
            if pid in mine:
                continue
            try:
                argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")[:3]
            except OSError:
                continue
            if any(self.pattern.search(os.path.basename(a.decode(errors="replace"))) for a in argv):
                pids.append(pid)
        return pids

    def wait_idle(self, limit=3600.0, settle=10.0, every=5.0):
        """Waits until :meth:`busy` has been empty for ``settle`` seconds
        (at most ``limit``); returns how long it waited and what it saw."""
        if self.no_wait:
            return {"waited_s": 0.0, "busy_pids_seen": [], "idle": not self.busy(), "no_wait": True}
        t0 = time.monotonic()
        quiet_since, seen = None, set()
        while True:
            pids = self.busy()
            seen.update(pids)
            now = time.monotonic()
            if pids:
                quiet_since = None
            elif quiet_since is None:
                quiet_since = now
            if quiet_since is not None and now - quiet_since >= settle:
                break
            if now - t0 > limit:
                break
            time.sleep(every)
        waited = time.monotonic() - t0
        entry = {"waited_s": round(waited, 1), "busy_pids_seen": sorted(seen), "idle": not self.busy()}
        if seen:
            print(f"  (waited {waited:.0f} s for an idle machine: {sorted(seen)})", flush=True)
        return entry


def finite(x):
    """``x`` with every non-finite float (a failed run's time or error in
    a settings scan) replaced by None, for strict JSON that serde reads."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    return x
