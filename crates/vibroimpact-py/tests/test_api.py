"""Vectorised calls, models from Python values, error mapping, the GIL,
Ctrl-C and progress."""

import os
import pickle
import signal
import threading
import time
import warnings

import numpy as np
import pytest

import vibroimpact as vi
from conftest import EXAMPLES

ROW = EXAMPLES / "fujita-row.toml"


def test_impact_is_vectorised_and_equals_scalar_calls():
    v = np.logspace(-5, 2, 100_000)
    r = vi.impact(v)
    assert r.restitution.shape == v.shape
    for k in (0, 4_321, 99_999):
        one = vi.impact(v[k])
        assert one.restitution[0] == r.restitution[k]
        assert one.peak_force[0] == r.peak_force[k]
    # e(V) decreases from 1 (seed fig. 3) and F_max grows.
    assert np.all(np.diff(r.restitution) < 0) and r.restitution[0] > 0.99
    assert np.all(np.diff(r.peak_force) > 0)


def test_contact_force_derivatives_against_differences():
    s = np.linspace(-2e-5, 2e-5, 7)
    sdot = np.full_like(s, 0.3)
    f = vi.contact_force(s, sdot)
    h = 1e-10
    fd = (vi.contact_force(s + h, sdot).force - vi.contact_force(s - h, sdot).force) / (2 * h)
    np.testing.assert_allclose(f.d_ds, fd, rtol=1e-6)
    fv = (vi.contact_force(s, sdot + 1e-7).force - vi.contact_force(s, sdot - 1e-7).force) / 2e-7
    np.testing.assert_allclose(f.d_dsdot, fv, rtol=1e-6)
    # F = (a + b sdot) exp(alpha s), a = 1 N, b = a / (a/b).
    np.testing.assert_allclose(f.force, (1 + sdot / 1.2) * np.exp(1.3e5 * s), rtol=1e-14)
    # Broadcasting keeps the shape.
    g = vi.contact_force(np.zeros((2, 3)), 0.1, law="hertz", stiffness=1e9)
    assert g.force.shape == (2, 3) and np.all(g.force == 0)


def test_any_array_like_is_accepted():
    base = np.logspace(-3, 0, 9)
    want = vi.impact(base).restitution
    # A list, a strided view, integers, float32, and a misaligned buffer.
    assert np.array_equal(vi.impact(list(base)).restitution, want)
    wide = np.empty(18)
    wide[::2] = base
    assert np.array_equal(vi.impact(wide[::2]).restitution, want)
    assert vi.impact(np.array([1, 2])).restitution.shape == (2,)
    raw = np.zeros(9 * 8 + 1, dtype=np.uint8)
    mis = raw[1:].view(np.float64)
    mis[:] = base
    assert not mis.flags.aligned
    assert np.array_equal(vi.impact(mis).restitution, want)


@pytest.mark.parametrize(
    "bad, name",
    [
        ([0.1, np.nan], "velocity[1]"),
        ([[0.1, 0.2]], "velocity: expected a 1-D array"),
        (["a", "b"], "velocity: expected numbers"),
        ([1 + 2j], "complex"),
        ("0.1", "velocity"),
    ],
)
def test_bad_arrays_name_the_argument(bad, name):
    with pytest.raises((ValueError, TypeError), match=name.replace("[", r"\[").replace("]", r"\]")):
        vi.impact(bad)


def test_bad_arguments():
    with pytest.raises(TypeError, match="unexpected keyword argument 'colour'"):
        vi.impact([0.1], colour=1)
    with pytest.raises(ValueError, match="law='hertz' needs stiffness"):
        vi.impact([0.1], law="hertz")
    with pytest.raises(ValueError, match="closed-form"):
        vi.impact([0.1], law="hertz", stiffness=1e9, method="closed-form")
    with pytest.raises(ValueError, match="mass1 = -1.0"):
        vi.impact([0.1], mass1=-1)
    with pytest.raises(ValueError, match="give exactly one of periods= and duration="):
        vi.simulate(ROW)
    with pytest.raises(ValueError, match="method = 'rk4'"):
        vi.simulate(ROW, periods=1, method="rk4")
    with pytest.raises(TypeError, match="model"):
        vi.simulate(42, periods=1)
    with pytest.raises(ValueError, match="nothing to identify"):
        vi.identify()
    with pytest.raises(ValueError, match=r"acceleration: give"):
        vi.identify(acceleration=np.ones((3, 3)))


def test_model_errors_name_the_key():
    text = ROW.read_text()
    with pytest.raises(ValueError, match=r"<string>:\d+: \[row\] mass = -1"):
        vi.Model.from_toml(text.replace("mass = 0.227", "mass = -1"))
    with pytest.raises(ValueError, match="masss"):
        vi.Model.from_toml(text.replace("mass = 0.227", "mass = 0.227\nmasss = 1"))
    m = vi.Model.load(ROW)
    with pytest.raises(ValueError, match="row.colour"):
        m.with_({"row.colour": 1.0})
    with pytest.raises(ValueError, match=r"fujita-row.toml:8: \[row\] mass = -1"):
        m.with_({"row.mass": -1.0})
    with pytest.raises(ValueError, match="whole numbers"):
        m.with_({"row.count": 2.5})
    with pytest.raises(ValueError, match="clearance"):
        vi.Model.from_dict({"row": {"count": 2, "mass": 1.0, "contact": {"law": "hertz", "stiffness": 1e9}}})
    with pytest.raises(OSError, match="nope.toml"):
        vi.Model.load("nope.toml")
    # A device or a folder is refused without reading (a FIFO would block).
    with pytest.raises(ValueError, match="not a regular file"):
        vi.Model.load("/dev/zero")


def test_models_from_python_values_and_pickling():
    m = vi.Model.load(ROW)
    assert m.bodies == ["p1", "p2", "p3"] and len(m) == 3
    m2 = m.with_(frequency=7.5, **{"row.clearance": 2e-3})
    assert m2.forcing_frequency == 7.5 and m2.get("row.clearance") == 2e-3
    assert m.get("row.clearance") == 1e-3, "models are immutable"
    d = m.to_dict()
    assert d["row"]["count"] == 3
    d["row"]["count"] = 4
    assert len(vi.Model.from_dict(d)) == 4
    assert pickle.loads(pickle.dumps(m2)) == m2
    # A recorded excitation travels inline.
    q = vi.Model.load(EXAMPLES / "pounding-buildings.toml")
    q2 = pickle.loads(pickle.dumps(q))
    a = vi.simulate(q, duration=1.0)
    b = vi.simulate(q2, duration=1.0)
    assert np.array_equal(a.displacement, b.displacement)


def test_simulate_history_and_failure_reporting():
    h = vi.simulate(ROW, periods=3, energy=True)
    assert h.completed and h.error is None
    assert h.displacement.shape == (h.t.size, 3) == h.velocity.shape
    assert abs(h.energy.residual) < 1e-6 * max(1.0, abs(h.energy.input_work))
    # An excitation strong enough to stall the step budget is reported, not raised.
    m = vi.Model.load(ROW).with_(amplitude=5e3)
    r = vi.simulate(m, periods=2)
    assert isinstance(r.completed, bool)
    if not r.completed:
        assert r.error


def test_periodic_non_convergence_raises_with_the_result():
    with pytest.raises(vi.VibroimpactError, match="Newton did not converge") as e:
        vi.periodic(ROW, guess_periods=1, rtol=1e-10)
    assert e.value.result.converged is False
    with pytest.raises(ValueError, match="no periodic forcing"):
        vi.periodic(EXAMPLES / "pounding-buildings.toml")


def _long_simulation(**kw):
    return vi.simulate(ROW, periods=600, rtol=1e-12, **kw)


def test_gil_is_released():
    # While a worker thread is inside a long call, the main thread keeps
    # running Python: the longest pause it sees is far shorter than the
    # call. Holding the GIL would make that pause the whole call. (A
    # serial-versus-parallel wall-clock ratio measures the machine's load
    # as much as the binding, and failed on a busy CI machine.)
    span = {}

    def worker():
        start = time.perf_counter()
        _long_simulation()
        span["call"] = time.perf_counter() - start

    thread = threading.Thread(target=worker)
    last = time.perf_counter()
    longest_pause = 0.0
    thread.start()
    while thread.is_alive():
        now = time.perf_counter()
        longest_pause = max(longest_pause, now - last)
        last = now
    thread.join()
    assert span["call"] > 0.2, span
    assert longest_pause < 0.25 * span["call"], (longest_pause, span)


def test_ctrl_c_interrupts_a_long_call():
    # A process started in the background by a non-interactive shell
    # inherits SIGINT ignored, and Python then installs no handler: the
    # test installs Python's own, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.perf_counter()
        timer.start()
        with pytest.raises(KeyboardInterrupt), pytest.warns(vi.LongRunWarning):
            vi.simulate(ROW, periods=1e6, output_step=0)
        assert time.perf_counter() - start < 5.0
        # Impacts by integration stop between chunks of velocities.
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.perf_counter()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            vi.impact(np.linspace(0.01, 1.0, 400_000), method="integrate")
        assert time.perf_counter() - start < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)


def test_progress_is_reported():
    seen = []
    vi.sweep(ROW, "frequency", from_=6.0, to=8.0, points=6, transient=5, record=2,
             progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (6, 6)
    assert all(b[0] >= a[0] for a, b in zip(seen, seen[1:]))
    with pytest.raises(ZeroDivisionError):
        vi.sweep(ROW, "frequency", from_=6.0, to=8.0, points=4, transient=5, record=2,
                 progress=lambda d, t: 1 / 0)


def test_simulate_reports_the_time_reached():
    seen = []
    vi.simulate(ROW, periods=400, output_step=0, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (1000, 1000) and all(t == 1000 for _, t in seen)


def test_strict_arguments():
    with pytest.raises(TypeError, match="energy: expected True or False"):
        vi.simulate(ROW, periods=1, energy="no")
    with pytest.raises(ValueError, match="alpha: not a parameter of law='hertz'"):
        vi.impact([0.1], law="hertz", stiffness=1e9, alpha=1e5)
    with pytest.raises(ValueError, match="transient = 4611686018427387904: must be from 0 to"):
        vi.sweep(ROW, "frequency", values=[6.0, 7.0], transient=2**62)
    with pytest.raises(ValueError, match="tasks: applies with a Dask client only"):
        vi.sweep(ROW, "frequency", values=[6.0, 7.0], tasks=3)
    with pytest.raises(ValueError, match="output step"):
        vi.simulate(ROW, duration=1.0, output_step=1e-9)
    with pytest.raises(ValueError, match="whole numbers"):
        vi.continue_(EXAMPLES / "fujita-row-n2.toml", "row.count", 2, 4)
    with pytest.raises(ValueError, match=r"rtol = 1e-30 is invalid: must lie in \(1e-15, 0.1\)"):
        vi.impact([1.0], method="integrate", rtol=1e-30)


def test_from_dict_takes_numpy_and_names_bad_keys():
    d = vi.Model.load(EXAMPLES / "pounding-buildings.toml").to_dict()
    d["excitation"]["time"] = np.asarray(d["excitation"]["time"])
    d["excitation"]["acceleration"] = np.asarray(d["excitation"]["acceleration"])
    assert vi.Model.from_dict(d) == vi.Model.load(EXAMPLES / "pounding-buildings.toml")
    d["excitation"]["acceleration"][3] = np.nan
    with pytest.raises(ValueError, match=r"excitation.acceleration\[3\]: NaN is not a finite number"):
        vi.Model.from_dict(d)
    d["excitation"]["acceleration"] = d["excitation"]["acceleration"][:-1]
    d["excitation"]["acceleration"][3] = 0.0
    with pytest.raises(ValueError, match="`time` has"):
        vi.Model.from_dict(d)
    # A value of the wrong type names its key, not a line of TOML the user
    # never wrote alone.
    row = vi.Model.load(EXAMPLES / "fujita-row.toml").to_dict()
    row["row"]["mass"] = "0.2"
    with pytest.raises(ValueError, match=r"key `row.mass`: invalid type: string"):
        vi.Model.from_dict(row)


def test_a_panic_is_an_exception_not_a_crash():
    # The library validates what it receives; what reaches it here is an
    # ordinary error, and the interpreter survives any failure.
    with pytest.raises(ValueError):
        vi.sweep(ROW, "frequency", values=[6.0, -1.0], transient=1, record=2)
    assert vi.impact([0.1]).restitution.size == 1


def test_a_long_run_warns_before_it_starts():
    """simulate over 1e7 periods (about 1.6e9 steps) warns up front with
    the estimated steps, time and the step limit that ends it; as an error
    the warning stops the call before any work. A short run is silent."""
    m = vi.Model.load(EXAMPLES / "fujita-row-n2.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("error", vi.LongRunWarning)
        vi.simulate(m, periods=20)
        t0 = time.perf_counter()
        with pytest.raises(vi.LongRunWarning, match=r"integration steps.*step limit") as e:
            vi.simulate(m, periods=1e7, output_step=0)
        assert time.perf_counter() - t0 < 5.0
    steps = float(str(e.value).split("about ")[1].split(" ")[0])
    assert 5e8 < steps < 5e9, str(e.value)
