#!/usr/bin/env python3
"""The IMK frame of ``frame_peer.py`` counted, not timed: the instructions
a call takes on each side, under valgrind's callgrind (deterministic where
the machine's speed is not: on the 2-vCPU machines the two sides' times
moved unevenly with the machine's phase, the ratio from 8.7 to 15.2 within
the hour; bench/results/journal-storeys.md).

Each side's call is the one ``frame_peer.py`` keeps as its best: ours
``vi.pounding(..., free=False)``, the exact run (``integrator="local"``,
DOPRI5, rtol 1e-3, sampled at dt_rec); OpenSees ``ExplicitDifference``
with ``Diagonal`` and ``Linear -factorOnce`` at dt_rec (its model build
and analysis), both on ``examples/moment-frame-4.toml`` under FEMA P695
far-field record 1a × 0.9. A side's count is the difference between a
process that warms the call once and makes N more and one that makes
none, over N.

    .venv/bin/python bench/opensees/frame_count.py [--calls N]

prints both counts and their ratio (OpenSees' over ours). Needs valgrind.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASE = HERE.parents[1] / "examples" / "moment-frame-4.toml"


def call(side: str, calls: int) -> None:
    """Makes the side's call once to warm it, then `calls` times."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    sys.path.insert(0, str(HERE))
    import vibroimpact as vi
    from vibroimpact.records import fema_p695

    record = fema_p695("farfield")[0]
    text = CASE.read_text()
    if side == "ours":
        def f():
            return vi.pounding(text, record, scale=0.9, sample=record["dt"], rtol=1e-3, method="dopri5",
                               integrator="local", free=False)
    else:
        from opensees_frame import run

        def f():
            return run(text, record["times"], record["acceleration"], 0.9, record["dt"], system="Diagonal",
                       algorithm="Linear -factorOnce", tol=0.0, integrator="ExplicitDifference")
    for _ in range(calls + 1):
        f()


def counted(side: str, calls: int) -> int:
    """Instructions of a process making the side's call `calls` times
    after the warming one."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        done = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
             "--side", side, "--calls", str(calls)],
            capture_output=True, text=True, check=False,
        )
        found = re.search(r"Collected : (\d+)", done.stderr)
        if done.returncode != 0 or not found:
            raise SystemExit(f"valgrind on {side} failed ({done.returncode}): {done.stderr[-2000:]}")
        return int(found.group(1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=2, help="calls counted per side (default 2)")
    parser.add_argument("--side", choices=("ours", "opensees"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.side:
        call(args.side, args.calls)
        return
    if args.calls < 1:
        raise SystemExit("--calls: give at least 1")
    per = {}
    for side in ("ours", "opensees"):
        per[side] = (counted(side, args.calls) - counted(side, 0)) / args.calls
        print(f"{side}: {per[side] / 1e6:.2f}M instructions a call")
    print(f"ratio (OpenSees / ours): {per['opensees'] / per['ours']:.2f}")


if __name__ == "__main__":
    main()
