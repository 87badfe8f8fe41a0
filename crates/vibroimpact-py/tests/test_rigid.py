"""Rigid impacts from Python (docs/theory.md §12): the same run as the
command line's, the impact log's rigid columns, and refusals that name
the argument."""

import numpy as np
import pytest

import vibroimpact as vi
from conftest import EXAMPLES

OSCILLATOR = EXAMPLES / "impact-oscillator.toml"


def test_the_impact_oscillator_settles_on_its_closed_form_orbit():
    r = vi.simulate(vi.Model.load(str(OSCILLATOR)), periods=40, output_step=0)
    log = r.impacts
    assert len(log.impact_velocity) == 40 and set(log.impacts) == {"rigid"}
    # U of Shaw and Holmes' period-1 orbit (the Rust tests: to 1e-10).
    assert log.impact_velocity[-1] == pytest.approx(2.503614666, rel=1e-6)
    np.testing.assert_allclose(log.restitution, 0.8, rtol=1e-15)
    np.testing.assert_allclose(log.impulse, 1.8 * log.impact_velocity, rtol=1e-14)
    u = log.impact_velocity
    np.testing.assert_allclose(log.energy_lost, 0.5 * u * u * 0.36, rtol=1e-12)
    assert "rigid impacts with e = 0.8" in r.contact_laws[0]


def test_soft_and_rigid_from_the_same_file():
    m = vi.Model.load(str(OSCILLATOR))
    soft = vi.simulate(m, periods=4, impacts="soft", output_step=0)
    assert soft.contact_evaluations > 0 and set(soft.impacts.impacts) == {"soft"}
    assert np.isnan(soft.impacts.impulse).all()
    # The Hertz law's own e(U) is 1: elastic impacts.
    law = vi.simulate(m, periods=4, impacts="rigid", output_step=0)
    np.testing.assert_allclose(law.impacts.restitution, 1.0, rtol=1e-14)
    half = vi.simulate(m, periods=4, restitution=0.5, output_step=0)
    np.testing.assert_allclose(half.impacts.restitution, 0.5, rtol=1e-14)


def test_python_equals_the_command_line(cli):
    d = vi.simulate(vi.Model.load(str(OSCILLATOR)), periods=10, output_step=0)
    cli = cli("simulate", str(OSCILLATOR), "--periods", "10")
    assert cli["final_displacement"] == list(d.final_displacement)
    assert cli["impact_count"] == d.impact_count == 10


def test_the_local_integrator_takes_the_jumps():
    # Exact motion between the jumps: the same orbit as the global run's.
    m = vi.Model.load(str(OSCILLATOR))
    glob = vi.simulate(m, periods=40, integrator="global", output_step=0)
    loc = vi.simulate(m, periods=40, integrator="local", output_step=0)
    assert loc.impact_count == glob.impact_count == 40
    np.testing.assert_allclose(loc.final_displacement, glob.final_displacement, atol=1e-8)
    np.testing.assert_allclose(loc.impacts.impact_velocity, glob.impacts.impact_velocity, rtol=1e-8)


@pytest.mark.parametrize(
    "kw, needle",
    [
        ({"impacts": "hard"}, "impacts = 'hard': give one of 'soft', 'rigid'"),
        ({"impacts": "soft", "restitution": 0.5}, "restitution = 0.5: a coefficient of restitution is for rigid impacts"),
        ({"restitution": 1.5}, "restitution: contact m|wall: rigid impacts: restitution = 1.5 is invalid"),
        ({"restitution": "x"}, "restitution"),
    ],
)
def test_bad_impacts_name_the_argument(kw, needle):
    with pytest.raises((ValueError, TypeError)) as e:
        vi.simulate(vi.Model.load(str(OSCILLATOR)), periods=2, output_step=0, **kw)
    assert needle in str(e.value)


def test_periodic_orbits_through_rigid_impacts(cli):
    # The bouncing ball (gravity, rigid impacts with e = 0.5): the orbit's
    # multipliers are the closed form's, equal to the command line's, and
    # its branch doubles its period at Gamma_PD g = 14.97814050 m/s^2.
    ball = EXAMPLES / "bouncing-ball.toml"
    r = vi.periodic(ball)
    doc = cli("periodic", str(ball))
    np.testing.assert_allclose(r.floquet_multipliers, doc["floquet_multipliers"], rtol=1e-12)
    np.testing.assert_allclose(r.initial_state, doc["initial_state"], rtol=1e-12)
    assert np.abs(np.array(r.floquet_multipliers)[:, 1]).max() == pytest.approx(0.4377558, abs=1e-6)
    b = vi.continue_(ball, "amplitude", 12.753, 16.0)
    (pd,) = b.special_points
    assert pd["kind"] == "period-doubling"
    assert pd["parameter"] == pytest.approx(14.97814050, abs=1e-6)


def test_impacts_reach_every_study(cli):
    # As --impacts/--restitution: periodic with e = 0.6 equals the command
    # line's, its multipliers' product is e^2 exp(-2 zeta T) (the
    # saltation's determinant); sweep, chart, basins and continue_ take
    # the same arguments and refuse a bad one by name.
    m = vi.Model.load(str(OSCILLATOR))
    r = vi.periodic(m, restitution=0.6)
    doc = cli("periodic", str(OSCILLATOR), "--restitution", "0.6")
    np.testing.assert_allclose(r.floquet_multipliers, doc["floquet_multipliers"], rtol=1e-12)
    mu = np.array(r.floquet_multipliers)
    det = 0.36 * np.exp(-0.1 * 2 * np.pi / 1.5)
    assert np.prod(np.hypot(mu[:, 0], mu[:, 1])) == pytest.approx(det, rel=1e-6)
    assert m.with_impacts(restitution=0.6).to_toml().count("restitution = 0.6") == 1
    s = vi.sweep(m, "force.1.frequency", from_=1.4, to=1.6, points=2, transient=5, record=2, impacts="soft")
    assert s.column("parameter").size == 2
    for call in (
        lambda: vi.sweep(m, "force.1.frequency", from_=1.4, to=1.6, points=2, restitution=1.5),
        lambda: vi.continue_(m, "force.1.frequency", 1.4, 1.6, restitution=1.5),
        lambda: vi.chart(m, "force.1.frequency", [1.4, 1.6], "force.1.amplitude", [0.9, 1.0], restitution=1.5),
        lambda: vi.basins(m, "u1", [-1, 1], "v1", [-1, 1], restitution=1.5),
    ):
        with pytest.raises(ValueError) as e:
            call()
        assert "restitution = 1.5 is invalid" in str(e.value)
    with pytest.raises(ValueError) as e:
        vi.periodic(m, impacts="hard")
    assert "impacts = 'hard'" in str(e.value)


def test_soft_episodes_are_listed_as_on_the_command_line(cli):
    # The seed's row with rigid impacts: chains overlap, and those
    # impacts are taken by the law in soft episodes, each with its
    # contact, times and reason, the same from Python as from the CLI.
    row = EXAMPLES / "fujita-row.toml"
    r = vi.simulate(row, periods=5, impacts="rigid", output_step=0)
    doc = cli("simulate", str(row), "--periods", "5", "--impacts", "rigid")
    assert r.soft_episodes == doc["soft_episodes"] and len(r.soft_episodes) >= 1
    assert all("shared body" in e["reason"] for e in r.soft_episodes)
