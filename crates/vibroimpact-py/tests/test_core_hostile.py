"""Hostile and odd inputs to the core faces (issue 38, "the core faces
never mislead"): each silently wrong answer becomes right or a refusal
that names the argument or key, as the CLI's does (its tests:
crates/vibroimpact-cli/tests/core_hostile.rs)."""

from pathlib import Path

import numpy as np
import pytest

import vibroimpact as vi

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
ROW = (EXAMPLES / "fujita-row.toml").read_text()


def test_a_mass_lost_in_rounding_is_refused_by_name():
    # 1e-100 kg "completed" with every body exactly at rest in 10 steps.
    with pytest.raises(ValueError, match=r"\[row\] body p1: mass = 1e-100 kg: .*give a mass of at least 1.27e-65 kg"):
        vi.Model.from_toml(ROW.replace("mass = 0.227 ", "mass = 1e-100 "), "row.toml")
    with pytest.raises(ValueError, match=r"mass = 1e307 with natural_frequency = 7.41"):
        vi.Model.from_toml(ROW.replace("mass = 0.227 ", "mass = 1e307 "), "row.toml")


def test_tolerances_outside_their_range_are_refused_by_name():
    m = vi.Model.load(EXAMPLES / "fujita-row-n2.toml")
    rng = r"give a tolerance in \(1e-15, 0.1\)"
    with pytest.raises(ValueError, match=r"rtol = 1 is invalid: must lie in \(1e-15, 0.1\)"):
        vi.impact([0.1], method="integrate", rtol=1.0)
    with pytest.raises(ValueError, match=rf"tol = 1: {rng}"):
        vi.periodic(m, tol=1.0)
    with pytest.raises(ValueError, match=rf"rtol = 1e-20: {rng}"):
        vi.simulate(m, periods=1, rtol=1e-20)
    with pytest.raises(ValueError, match=rf"rtol = 0.5: {rng}"):
        vi.sweep(m, "frequency", values=[5.0, 6.0], rtol=0.5)


def test_one_recorded_period_is_refused():
    m = vi.Model.load(EXAMPLES / "fujita-row-n2.toml")
    with pytest.raises(ValueError, match="record = 1: record at least two periods"):
        vi.sweep(m, "frequency", values=[5.0, 6.0], transient=1, record=1)


def test_repeated_measurements_give_no_standard_error():
    # Three identical points gave a/b ± 1e-15 ("0.00 %").
    with pytest.raises(ValueError, match="hold 1 distinct .* give 2 distinct points at least"):
        vi.identify(restitution=([0.1, 0.1, 0.1], [0.5, 0.5, 0.5]))


def test_the_orientation_of_measurements_is_explicit():
    # The same four numbers fitted a/b 1.020 as rows and 0.552 as columns.
    with pytest.raises(ValueError, match=r"restitution: a 2 x 2 array is ambiguous"):
        vi.identify(restitution=[[0.1, 0.2], [0.9, 0.8]])
    u, e = [0.05, 0.1, 0.2, 0.4], [0.8, 0.7, 0.62, 0.55]
    by_columns = vi.identify(restitution=(u, e)).a_over_b.value
    by_dict = vi.identify(restitution={"impact_velocity": u, "restitution": e}).a_over_b.value
    by_rows = vi.identify(restitution=np.c_[u, e]).a_over_b.value
    assert by_columns == by_dict == by_rows
    with pytest.raises(ValueError, match="exactly the keys 'impact_velocity' and 'restitution'"):
        vi.identify(restitution={"velocity": u, "restitution": e})


def test_a_key_path_ends_at_its_commented_header():
    # ``key `row]   # N identical bodies between two walls.mas` ``.
    with pytest.raises(ValueError, match=r"row.toml:10: key `row.mas`: unknown field `mas`"):
        vi.Model.from_toml(ROW.replace("mass = 0.227 ", "mas = 0.227 "), "row.toml")


def test_plots_check_what_they_are_given():
    # vp.frequency_response(impact_result) raised KeyError: 'points', and
    # vp.restitution(None) an AttributeError.
    import vibroimpact.plot as vp

    hit = vi.impact([0.1])
    with pytest.raises(TypeError, match=r"branch: give the result of vibroimpact.continue_, got a result with .*without points"):
        vp.frequency_response(hit)
    with pytest.raises(TypeError, match="impact: give the result of vibroimpact.impact, got NoneType"):
        vp.restitution(None)
    for f in (vp.time_history, vp.poincare, vp.fragility):
        with pytest.raises(TypeError, match="give the result of"):
            f(hit)


def _interrupted(call, after=1.0):
    """The KeyboardInterrupt of ``call()`` under a SIGINT ``after`` s."""
    import os
    import signal
    import threading

    timer = threading.Timer(after, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            call()
    finally:
        timer.cancel()
    return info.value


def test_ctrl_c_keeps_the_branch_so_far():
    # KeyboardInterrupt came promptly but lost the branch, which the CLI
    # writes with stop "Interrupted": it is on the exception as .result.
    m = vi.Model.load(EXAMPLES / "fujita-row.toml")
    branch = _interrupted(lambda: vi.continue_(m, "frequency", 11.1, 3.7, ds_max=0.001)).result
    assert branch.stop == "Interrupted"
    assert len(branch.points) >= 2
    assert branch.column("parameter")[0] == pytest.approx(11.1)


def test_long_charts_and_basins_warn_before_any_work():
    # As the CLI's note: a 40 x 40 basins grid (about 3 min on one core)
    # warns up front; as an error the warning stops the call first.
    import warnings

    m = vi.Model.load(EXAMPLES / "fujita-row-n2.toml")
    grid = np.linspace(-0.9e-3, 0.9e-3, 40), np.linspace(-0.06, 0.06, 40)
    with warnings.catch_warnings():
        warnings.simplefilter("error", vi.LongRunWarning)
        with pytest.raises(vi.LongRunWarning, match="a long run: about .* on one core"):
            vi.basins(m, "u1", grid[0], "v1", grid[1], transient=400, record=30)
        with pytest.raises(vi.LongRunWarning, match="a long run"):
            vi.chart(m, "frequency", np.linspace(3.7, 11.1, 200), "amplitude", np.linspace(0.01, 0.1, 200))
        # periodic on a long row said nothing first.
        row = vi.Model.from_toml(ROW.replace("count = 3\n", "count = 100000\n"), "row.toml")
        with pytest.raises(vi.LongRunWarning, match="a long run: about .* on one core"):
            vi.periodic(row)


def test_ctrl_c_keeps_the_history_and_the_sweep_so_far():
    # The CLI keeps a simulation's history and a sweep's values up to
    # Ctrl-C; Python attaches them to the KeyboardInterrupt as .result.
    m = vi.Model.load(EXAMPLES / "fujita-row.toml")
    run = _interrupted(lambda: vi.simulate(m, periods=2e4, output_step=0.01)).result
    assert run.completed is False and 0.0 < run.final_time
    assert len(run.t) > 10 and run.t[-1] <= run.final_time
    sweep = _interrupted(lambda: vi.sweep(m, "frequency", values=np.linspace(5, 9, 400), threads=1)).result
    done = [p for p in sweep.points if p.completed]
    assert 0 < len(done) < 400


def test_plot_axes_carry_units():
    # Axes read "frequency" with no units, and x_scale labelled
    # "frequency × 0.135" instead of Ω/ω0.
    import matplotlib

    matplotlib.use("Agg")
    import vibroimpact.plot as vp

    m = vi.Model.load(EXAMPLES / "fujita-row-n2.toml")
    sweep = vi.sweep(m, "frequency", values=[7.0, 7.2], transient=5, record=4)
    assert vp.poincare(sweep).get_xlabel() == "forcing frequency Ω (rad/s)"
    assert vp.poincare(sweep, x_scale=1 / 7.41).get_xlabel() == "Ω/ω0 (ω0 = 7.41 rad/s)"
    clearance = vi.sweep(m, "row.clearance", values=[1e-3, 1.1e-3], transient=5, record=4)
    assert vp.poincare(clearance).get_xlabel() == "row.clearance (m)"


def test_a_simulation_says_how_it_was_made(cli):
    # The summary said nothing of its settings or model: it carries the
    # version, method, tolerances, integrator and the model's digest, the
    # command line's for the same file.
    path = EXAMPLES / "fujita-row-n2.toml"
    r = vi.simulate(vi.Model.load(path), periods=1, rtol=1e-7)
    p = r.provenance
    assert (p.method, p.integrator, p.rtol, p.atol) == ("dop853", "auto", 1e-7, 1e-11)
    assert len(p.model_sha256) == 64
    assert dict(p) == cli("simulate", path, "--periods", 1, "--rtol", 1e-7)["provenance"]
    other = vi.Model.from_toml(path.read_text().replace("amplitude = 0.05", "amplitude = 0.06"), "m.toml")
    assert vi.simulate(other, periods=1, rtol=1e-7).provenance.model_sha256 != p.model_sha256


def test_special_points_sit_on_their_drawn_curve():
    # BP1 was drawn at the nearest branch point's amplitude, off its curve:
    # each special point now has its own orbit's amplitude, the curve passes
    # through it, and its label sits there.
    import matplotlib

    matplotlib.use("Agg")
    import vibroimpact.plot as vp

    b = vi.continue_(EXAMPLES / "fujita-row-n2.toml", "frequency", 3.705, 11.115)
    ax = vp.frequency_response(b)
    labels = {t.get_text(): t.xy for t in ax.texts}
    curve = np.vstack([line.get_xydata() for line in ax.lines if line.get_linestyle() in ("-", "--")])
    for sp in b.special_points:
        x, y = labels[sp.label]
        assert (x, y) == (sp.parameter, 1e3 * sp.max_displacement[0])
        # A vertex of the drawn curve, exactly.
        assert np.any((curve[:, 0] == x) & (curve[:, 1] == y)), sp.label
