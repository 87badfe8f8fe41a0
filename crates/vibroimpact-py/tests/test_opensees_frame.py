"""OpenSees (openseespy) as the peer of a frame with P-Δ (issue 37): the
4-storey steel special moment frame (SMF) archetype of
examples/moment-frame-4.toml (P-Δ from its weight and a leaning column's
loads) with elastic, bilinear (Steel01) and IMK (IMKBilin) storeys under
FEMA P695 far-field record 1a, built in OpenSees by
bench/opensees/opensees_frame.py; bench/opensees/frame_peer.py is the
full convergence and speed study (bench/opensees/README.md, "A frame with
P-Δ")."""

import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "bench" / "opensees"))

from opensees_pair import import_opensees, storey_material  # noqa: E402

try:
    import_opensees()
except (ImportError, OSError, RuntimeError) as e:  # openseespy absent or not loadable
    pytest.skip(f"openseespy: {e}", allow_module_level=True)

from frame_peer import case_with, errors, peaks_of_ours, row_text  # noqa: E402
from opensees_frame import period, rayleigh, run, yield_drifts  # noqa: E402

records = pytest.importorskip("vibroimpact.records")


@pytest.fixture(scope="module")
def northridge():
    # Far-field record 1, component a: Northridge 1994, Beverly Hills - Mulholland.
    return records.fema_p695("farfield")[0]


def _opensees(text, record, scale, m, **kw):
    t, a = np.asarray(record["times"]), np.asarray(record["acceleration"])
    return run(text, t, a, scale, record["dt"] / m, **kw)


# OpenSees' converged step per case (the coarsest within 1 % of its own
# dt_rec/64 run, frame_peer.py --no-timing; of its dt_rec/16 run for
# elastic), and the errors there against ours measured (peak drift ratios
# relative; residual drift ratios over the yield drift ratio, over the
# peak drift ratio for elastic storeys): elastic x 1.0 dt_rec, 3.5e-3 and
# 9.8e-5; bilinear x 1.0 dt_rec/2, 4.7e-3 and 5.1e-3; IMK x 0.9 dt_rec,
# 4.8e-3 (its residuals 5.6e-2, reported, not judged: the issue asks the
# peaks; 1.2e-2 at dt_rec/2, 2.7e-3 at dt_rec/4). At twice the step
# OpenSees is further off (bilinear 2.0e-2), at half of it nearer
# (elastic 9.8e-4, IMK 9.4e-4): about second order, towards ours.
CONVERGED = {"elastic": 1, "bilinear": 2, "imk": 1}


@pytest.mark.parametrize("name", sorted(CONVERGED))
def test_the_frame_with_p_delta_agrees_with_opensees_at_its_converged_step(northridge, name):
    building, text, scale, judge_residual = case_with(name)
    dt = northridge["dt"]
    doc = vi.pounding(text, northridge, scale=scale, sample=dt, rtol=1e-8, free=False)
    ours = peaks_of_ours(doc, building)
    uy = yield_drifts(building)
    # The case is what the study needs.
    if name == "bilinear":
        # Every storey yields (peak drift over yield drift 1.40 to 3.95).
        ductility = np.divide(ours["peak_drift"], uy)
        assert 1.2 < ductility.min() and 3.5 < ductility.max() < 4.5, ductility
    if name == "imk":
        # Storey 4 passes its cap (u_y + d_p = 4.33 u_y: measured 5.29 u_y,
        # 1.22 x the cap; a drift ratio of 3.96 %) and the frame stands
        # (ours and OpenSees both collapse between x 1.43 and x 1.44); the
        # storeys' work stays far below IMKBilin's energy-exhaustion window
        # (at most 0.113 lambda F_y, storey 4; the peer notes: it fails
        # near 0.78).
        caps = [s["yield_drift"] + s["plastic_drift"] for s in building["storeys"]]
        assert ours["peak_drift"][3] > 1.15 * caps[3] and max(ours["peak_drift_ratio"]) < 0.05, ours
        work = doc["runs"][0]["pounding"]["hysteretic_energy"][building["name"]]
        ref_energy = [s["lambda_s"] * k * s["yield_drift"] for s, k in zip(building["storeys"], building["stiffnesses"])]
        assert max(w / e for w, e in zip(work, ref_energy)) < 0.2
    # The period (with P-Δ: the tail's and the residual window's) and the
    # Rayleigh coefficients are ours.
    row = doc["row"]["buildings"][0]
    assert period(building) == pytest.approx(row["period"], rel=1e-12)
    alpha, beta = rayleigh(building)
    assert alpha == pytest.approx(row["rayleigh"]["alpha"], rel=1e-12)
    assert beta == pytest.approx(row["rayleigh"]["beta"], rel=1e-12)
    m = CONVERGED[name]
    e = errors(_opensees(text, northridge, scale, m), ours, building, judge_residual)
    assert e["drift"] < 0.01, e
    if judge_residual:
        assert e["residual"] < 0.01, e
    # OpenSees converges towards ours as its step shrinks: at twice the
    # converged step (at half of it for the elastic frame, converged at
    # the record's step) it is further off.
    other = _opensees(text, northridge, scale, m // 2 if m > 1 else 2)
    e2 = errors(other, ours, building, judge_residual)
    if m > 1:
        assert e2["error"] > 3 * e["error"], (e, e2)
    else:
        assert e2["error"] < e["error"] / 3, (e, e2)


@pytest.mark.parametrize("name", ["bilinear", "imk"])
def test_our_fast_setting_agrees_with_converged_opensees(northridge, name):
    # The speed study's pick on both cases (frame_peer.py, on the previous
    # archetype): DOPRI5 at rtol 1e-3, drifts sampled at the record's step
    # (the global integrator ends a step on every record sample, so it is
    # within 3.2e-5 of the rtol 1e-10 reference anyway). Within 1 % of
    # OpenSees at its converged step, as judged there (measured: bilinear
    # 5.1e-3, IMK 4.8e-3).
    building, text, scale, judge_residual = case_with(name)
    dt = northridge["dt"]
    fast = peaks_of_ours(vi.pounding(text, northridge, scale=scale, sample=dt, rtol=1e-3, method="dopri5",
                                     free=False), building)
    e = errors(fast, _opensees(text, northridge, scale, CONVERGED[name]), building, judge_residual)
    assert e["error"] < 0.01, e


def test_the_leaning_column_is_the_p_delta_spring(northridge):
    # The first 10 s of the record, IMK storeys (all four yield): the 2-D
    # model with a leaning column (geomTransf PDelta, the gravity loads
    # applied statically first) and the 1-D one with a spring -P/h beside
    # each storey give the same drifts (measured 2e-14); without P-Δ the
    # drifts differ by far more (1 to 30 %).
    building, text, scale, _ = case_with("imk")
    rec = {"times": np.asarray(northridge["times"][:1000]), "acceleration": np.asarray(northridge["acceleration"][:1000]),
           "dt": northridge["dt"]}
    spring = _opensees(text, rec, scale, 2)
    lean = _opensees(text, rec, scale, 2, p_delta="leaning-column")
    peak = np.asarray(spring["peak_drift"])
    assert np.max(peak / yield_drifts(building)) > 1.2
    np.testing.assert_allclose(lean["peak_drift"], peak, rtol=1e-6)
    np.testing.assert_allclose(lean["residual_drift"], spring["residual_drift"], rtol=0, atol=1e-6 * peak.max())
    none = dict(tomllib.loads(text)["building"][0], p_delta=False)
    del none["leaning_loads"]
    bare = _opensees(row_text(none), rec, scale, 2)
    assert np.max(np.abs(np.asarray(bare["peak_drift"]) / peak - 1)) > 0.02


@pytest.mark.parametrize("deteriorating", [False, True])
def test_an_imk_storey_is_imkbilin(deteriorating):
    # opensees_pair.storey_material's IMKBilin for the frame's storey 2
    # (lambda 4 m; absent: no deterioration, lambda 1e30 there) under
    # cycles to 0.18 m (the cap at 0.13 m), driven in 2e-5 m increments
    # (testUniaxialMaterial), against our law (vibroimpact.hysteresis)
    # along the same drifts: within 1e-6 of F_y (OpenSees takes the
    # excursion energy at its increments; measured 4e-20 without
    # deterioration, 1.5e-8 with it).
    import openseespy.opensees as ops

    building, _, _, _ = case_with("imk")
    spec = dict(building["storeys"][1])
    if not deteriorating:
        for key in ("lambda_s", "lambda_c", "lambda_k"):
            del spec[key]
    k = building["stiffnesses"][1]
    turns = [0.0]
    for amp in (0.03, 0.06, 0.1, 0.14, 0.18):
        turns += [amp, -amp]
    turns.append(0.0)
    drift = np.concatenate([np.linspace(a, b, int(abs(b - a) / 2e-5) + 1)[1:] for a, b in zip(turns, turns[1:])])
    name, args = storey_material(spec, k)
    ops.wipe()
    ops.uniaxialMaterial(name, 1, *args)
    ops.testUniaxialMaterial(1)
    theirs = []
    for d in drift:
        ops.setStrain(float(d))
        theirs.append(ops.getStress())
    keys = {key: v for key, v in spec.items() if key != "law"}
    ours = vi.hysteresis(stiffness=k, law="imk", drift=drift, **keys)
    fy = k * spec["yield_drift"]
    assert np.max(np.abs(np.asarray(theirs) - ours["force"])) < 1e-6 * fy
    # The protocol reaches the cap, 1.1 F_y; with deterioration the
    # strength has dropped by then (measured 1.055 F_y).
    peak = np.max(np.abs(theirs)) / fy
    if deteriorating:
        assert 1.0 < peak < 1.09, peak
    else:
        assert peak == pytest.approx(1.1, rel=1e-9)
