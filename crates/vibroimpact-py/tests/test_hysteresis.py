"""Storey laws under imposed drift (docs/theory.md §11): Bouc–Wen against
a SciPy integration of its ODE, the bilinear law and Bouc–Wen against
OpenSees' Steel01 and BoucWen materials, and the CLI's document."""

import json
import math
import subprocess

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vibroimpact as vi

K, UY = 1.2e8, 0.01
BW = dict(
    stiffness=K,
    yield_drift=UY,
    post_yield_ratio=0.05,
    exponent=2.0,
    beta=0.55,
    gamma=0.45,
    degradation_nu=0.2 / (K * UY * UY),
    degradation_eta=0.1 / (K * UY * UY),
)


def _scipy_bouc_wen(amplitude, cycles, points, p):
    """z and e at the protocol's samples, d(t) = a sin(2πt), by DOP853 in
    time over each quarter cycle (where ḋ keeps its sign)."""
    a, k, uy = amplitude, p["stiffness"], p["yield_drift"]
    alpha, n = p["post_yield_ratio"], p["exponent"]

    def rhs(t, y):
        z, e = y
        dd = a * 2 * math.pi * math.cos(2 * math.pi * t)
        big_a = 1.0
        nu = 1.0 + p["degradation_nu"] * e
        eta = 1.0 + p["degradation_eta"] * e
        psi = p["gamma"] + p["beta"] * (1.0 if dd * z > 0 else -1.0)
        dz = dd * (big_a - nu * psi * abs(z / uy) ** n) / eta
        return [dz, (1 - alpha) * k * z * dd]

    y = [0.0, 0.0]
    out = []
    quarter = points // 4
    for q in range(4 * cycles):
        t0, t1 = q / 4, (q + 1) / 4
        ts = [(q * quarter + j) / points for j in range(1, quarter + 1)]
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-16, t_eval=ts)
        out.extend(sol.y.T)
        y = sol.y[:, -1]
    return np.array(out)


def test_bouc_wen_matches_scipy():
    # Two cycles at 3 u_y with strength and stiffness degradation: the force
    # to 1e-8 of the yield force at every sample.
    r = vi.hysteresis(law="bouc-wen", amplitudes=[3 * UY], cycles=2, points=200, **BW)
    ref = _scipy_bouc_wen(3 * UY, 2, 200, BW)
    d = r.drift
    force = K * (0.05 * d + 0.95 * ref[:, 0])
    assert np.max(np.abs(r.force - force)) < 1e-8 * K * UY
    # Degradation lowers the second cycle's peak.
    assert r.force[250] < 0.999 * r.force[50]


def test_cli_and_python_give_one_document(cli_exe):
    args = ["--law", "bouc-wen", "--stiffness", str(K), "--yield-drift", str(UY),
            "--amplitudes", "0.005,0.02", "--cycles", "1", "--points", "40", "--format", "json"]
    doc = json.loads(subprocess.run([cli_exe, "hysteresis", *args], capture_output=True,
                                    text=True, check=True).stdout)
    r = vi.hysteresis(law="bouc-wen", stiffness=K, yield_drift=UY, amplitudes=[0.005, 0.02],
                      cycles=1, points=40)
    assert doc["law"] == r.law and doc["peak_force"] == r.peak_force
    assert doc["total_dissipated"] == r.total_dissipated
    assert [row["force"] for row in doc["rows"]] == list(r.force)


def test_bad_settings_name_the_argument(tmp_path):
    with pytest.raises(ValueError, match="post_yield_ratio = 1.5: must be in"):
        vi.hysteresis(stiffness=K, yield_drift=UY, post_yield_ratio=1.5, amplitudes=[UY])
    with pytest.raises(ValueError, match="exponent = 0.5"):
        vi.hysteresis(law="bouc-wen", stiffness=K, yield_drift=UY, exponent=0.5, amplitudes=[UY])
    with pytest.raises(ValueError, match="yield_drift"):
        vi.hysteresis(stiffness=K, amplitudes=[UY])
    with pytest.raises(ValueError, match="points = 10"):
        vi.hysteresis(stiffness=K, yield_drift=UY, amplitudes=[UY], points=10)
    with pytest.raises(ValueError, match="amplitudes"):
        vi.hysteresis(stiffness=K, yield_drift=UY)
    bad = tmp_path / "d.txt"
    bad.write_text("drift\n0.001\nx\n")
    with pytest.raises(ValueError, match="d.txt:3"):
        vi.hysteresis(stiffness=K, yield_drift=UY, drift=bad)
    ok = tmp_path / "ok.txt"
    ok.write_text("drift\n0.02\n-0.02\n")
    r = vi.hysteresis(stiffness=K, yield_drift=UY, drift=ok)
    # One excursion to +2 u_y and back to −2 u_y: 3 u_y of plastic drift.
    assert math.isclose(r.total_dissipated, 0.95 * K * UY * (0.01 + 0.02), rel_tol=1e-12)


IMK = dict(cap_ratio=1.1, plastic_drift=0.03, post_capping_drift=0.1, residual_ratio=0.3,
           ultimate_drift=0.2, lambda_s=4.0, lambda_c=4.0, lambda_k=4.0)


def test_imk_on_both_faces(cli_exe):
    # The IMK storey: the CLI's document equals Python's; its monotonic
    # push reaches the cap F_c = 1.1 F_y at u_y + d_p; a key missing or out
    # of order is named.
    k, uy = 1.2e8, 0.01
    flags = [f"--{key.replace('_', '-')}={value}" for key, value in IMK.items()]
    args = ["--law", "imk", "--stiffness", str(k), "--yield-drift", str(uy), *flags,
            "--amplitudes", "0.02,0.05", "--cycles", "1", "--points", "40", "--format", "json"]
    doc = json.loads(subprocess.run([cli_exe, "hysteresis", *args], capture_output=True,
                                    text=True, check=True).stdout)
    r = vi.hysteresis(law="imk", stiffness=k, yield_drift=uy, amplitudes=[0.02, 0.05],
                      cycles=1, points=40, **IMK)
    assert doc["law"] == r.law and doc["law"]["law"] == "imk"
    assert [row["force"] for row in doc["rows"]] == list(r.force)
    push = vi.hysteresis(law="imk", stiffness=k, yield_drift=uy, drift=[0.04], **IMK)
    assert push.force[-1] == pytest.approx(1.1 * k * uy, rel=1e-12)
    with pytest.raises(ValueError, match="ultimate_drift: give it for law='imk'"):
        vi.hysteresis(law="imk", stiffness=k, yield_drift=uy, amplitudes=[uy],
                      **{key: v for key, v in IMK.items() if key != "ultimate_drift"})
    with pytest.raises(ValueError, match="cap_ratio = 0.9: must be >= 1"):
        vi.hysteresis(law="imk", stiffness=k, yield_drift=uy, amplitudes=[uy], **{**IMK, "cap_ratio": 0.9})
