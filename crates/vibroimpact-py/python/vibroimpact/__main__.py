"""``python -m vibroimpact sweep MODEL.toml --parameter frequency --from 5.9
--to 8.9 --points 64 [--scheduler tcp://HOST:PORT] [--tasks K] [--out FILE]``

The brute-force sweep of ``vibroimpact sweep``, run here (all cores) or on
a Dask cluster given by its scheduler address; prints (or writes atomically)
the JSON summary of the CLI's ``--format json``: the same fields and values
(keys in alphabetical order).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m vibroimpact")
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("sweep", help="brute-force bifurcation diagram (Poincaré samples)")
    s.add_argument("model", help="model file (TOML)")
    s.add_argument("--parameter", required=True)
    s.add_argument("--from", dest="from_", type=float, required=True)
    s.add_argument("--to", type=float, required=True)
    s.add_argument("--points", type=int, required=True)
    s.add_argument("--transient", type=int, default=100)
    s.add_argument("--settle", type=int, help="periods added at most while a value still settles (default 9 × --transient)")
    s.add_argument("--record", type=int, default=20)
    s.add_argument("--up-down", action="store_true")
    s.add_argument("--rtol", type=float)
    s.add_argument("--atol", type=float)
    s.add_argument("--method", default="dop853", choices=["dop853", "dopri5", "rodas", "auto"])
    s.add_argument("--cluster-tolerance", type=float)
    s.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://HOST:8786")
    s.add_argument("--tasks", type=int, help="Dask tasks (default: 4 per worker thread)")
    s.add_argument("--timeout", type=float, default=10.0, help="seconds to reach the scheduler")
    s.add_argument("--out", help="write the JSON here (atomically) instead of standard output")
    return p


def _write(path: str, text: str) -> None:
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".vibroimpact-")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def main(argv=None) -> int:
    import vibroimpact as vi

    a = _parser().parse_args(argv)
    client = None
    try:
        if a.scheduler:
            try:
                from dask.distributed import Client
            except ImportError:
                print("error: --scheduler needs dask[distributed] installed", file=sys.stderr)
                return 2
            try:
                client = Client(a.scheduler, timeout=a.timeout)
            except (OSError, TimeoutError) as e:
                print(f"error: --scheduler {a.scheduler}: cannot connect: {e}", file=sys.stderr)
                return 2
        r = vi.sweep(
            a.model,
            a.parameter,
            from_=a.from_,
            to=a.to,
            points=a.points,
            transient=a.transient,
            settle=a.settle,
            record=a.record,
            up_down=a.up_down,
            rtol=a.rtol,
            atol=a.atol,
            method=a.method,
            cluster_tolerance=a.cluster_tolerance,
            client=client,
            tasks=a.tasks,
        )
    except (ValueError, TypeError, OSError, vi.VibroimpactError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    finally:
        if client is not None:
            client.close()
    doc = r.to_dict()
    for p in doc["points"]:
        p.pop("sections", None)
    text = json.dumps(doc, indent=2)
    if a.out:
        try:
            _write(a.out, text + "\n")
        except OSError as e:
            print(f"error: --out {a.out}: {e}", file=sys.stderr)
            return 1
    else:
        print(text)
    failed = [p for p in doc["points"] if p["error"]]
    if failed:
        print(f"error: {len(failed)} sweep values failed (kept in the output)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
