"""OpenSees' ``IMKBilin`` (Nov22) under a cyclic drift protocol: the peer
data of the IMK storey's test (crates/vibroimpact/tests/imk_opensees.rs).

One zeroLength spring of the law, displacement-controlled along the
protocol in steps of DU (small against the yield drift, so that
OpenSees' per-step events converge to the exact ones), its force written
at the protocol's points. Symmetric parameters as vibroimpact's ``Imk``:
k, u_y (F_y = k u_y), F_c/F_y, d_p, d_pc, F_r/F_y, d_u, lambda (m; the
reference energy lambda F_y), c; D = 1. The histories stay below the
energy exhaustion window (docs/theory.md §11, and the peer notes).

    .venv/bin/python bench/opensees/imk_reference.py   # a few seconds
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from opensees_pair import import_opensees  # noqa: E402

OUT = HERE.parents[1] / "crates" / "vibroimpact" / "tests" / "data" / "imk-opensees.csv"
# The law (a storey of a 4 m steel moment frame; lambda generous enough
# that the protocol deteriorates without exhausting the energy).
K, UY, CAP, DP, DPC, RES, DU = 1.2e8, 0.01, 1.1, 0.03, 0.1, 0.3, 0.2
CASES = {"no-deterioration": 1e6, "deteriorating": 4.0}
C = 1.0
# A SAC-like protocol: amplitudes (m) and cycles at each, in quarter-cycle
# turning points.
PROTOCOL = [(0.005, 2), (0.0075, 2), (0.01, 2), (0.015, 2), (0.02, 2), (0.03, 2), (0.04, 2), (0.05, 2),
            (0.07, 1), (0.1, 1), (0.13, 1)]
DU_STEP = 2e-6


def turning_points():
    pts = [0.0]
    for a, n in PROTOCOL:
        for _ in range(n):
            pts += [a, 0.0, -a, 0.0]
    return pts


def run(lam):
    ops = import_opensees()
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    fy = K * UY
    ops.uniaxialMaterial("IMKBilin", 1, K, DP, DPC, DU, fy, CAP, RES, DP, DPC, DU, fy, CAP, RES,
                         lam, lam, lam, C, C, C, 1.0, 1.0)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 1.0)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    rows = [(0.0, 0.0)]
    pts = turning_points()
    for a, b in zip(pts, pts[1:]):
        n = max(1, int(round(abs(b - a) / DU_STEP)))
        ops.integrator("DisplacementControl", 2, 1, (b - a) / n)
        ops.analysis("Static")
        for j in range(n):
            if ops.analyze(1) != 0:
                raise RuntimeError(f"OpenSees failed at {a} -> {b}, step {j}")
            if (j + 1) % max(1, n // 20) == 0 or j == n - 1:
                ops.reactions()
                rows.append((ops.nodeDisp(2, 1), -ops.nodeReaction(1, 1)))
    return np.array(rows)


def main():
    blocks = []
    for name, lam in CASES.items():
        r = run(lam)
        blocks.append((name, lam, r))
        print(f"{name}: lambda {lam} m, {len(r)} points, peak force {np.abs(r[:, 1]).max():.6e} N")
    with open(OUT, "w") as f:
        f.write("# OpenSees IMKBilin (Nov22) under bench/opensees/imk_reference.py's protocol\n")
        f.write(f"# k {K}, uy {UY}, cap_ratio {CAP}, dp {DP}, dpc {DPC}, residual_ratio {RES}, du {DU}, c {C}\n")
        f.write("case,lambda,drift,force\n")
        for name, lam, r in blocks:
            for d, fo in r:
                f.write(f"{name},{float(lam)!r},{float(d)!r},{float(fo)!r}\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
