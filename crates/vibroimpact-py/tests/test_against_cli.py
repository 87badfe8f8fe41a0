"""The Python API against the CLI on the same inputs: same numbers to 1e-12
(both are the same library; the tolerance only allows for the JSON text)."""

import json

import numpy as np
import pytest

import vibroimpact as vi
from conftest import EXAMPLES, ROOT

REL = 1e-12


def close(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    assert a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=REL, atol=1e-300)


def read_measured(path):
    """Two numeric columns after the header row, `#` comments skipped."""
    rows = [l for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    return np.array([[float(x) for x in l.split(",")] for l in rows[1:]])


@pytest.mark.parametrize("method", ["closed-form", "integrate"])
def test_impact(cli, method):
    v = np.logspace(-3, 1, 25)
    doc = cli(
        "impact", "--velocity", ",".join(repr(float(x)) for x in v), "--method", method
    )
    r = vi.impact(v, method=method)
    assert r.method == doc["method"] == method
    assert r.contact_law.to_dict() == doc["contact_law"]
    for key in doc["rows"][0]:
        want = [np.nan if row[key] is None else row[key] for row in doc["rows"]]
        close(r[key], want)


def test_impact_other_law_and_wall(cli):
    v = [0.05, 0.2, 0.7]
    doc = cli(
        "impact", "--law", "hunt-crossley", "--stiffness", "2e9", "--chi", "0.4",
        "--mass2", "wall", "--velocity", "0.05,0.2,0.7",
    )
    r = vi.impact(v, law="hunt-crossley", stiffness=2e9, chi=0.4, mass2="wall")
    assert r.mass2 == "wall" and r.method == "integrate"
    for key in ("restitution", "peak_force", "contact_duration", "max_penetration"):
        close(r[key], [row[key] for row in doc["rows"]])


def test_identify(cli):
    rest = read_measured(EXAMPLES / "seed-impacts/restitution.csv")
    acc = read_measured(EXAMPLES / "seed-impacts/acceleration.csv")
    for joint in (False, True):
        args = [
            "identify", "--restitution", EXAMPLES / "seed-impacts/restitution.csv",
            "--acceleration", EXAMPLES / "seed-impacts/acceleration.csv",
        ] + (["--joint"] if joint else [])
        doc = cli(*args)
        r = vi.identify(restitution=rest, acceleration=(acc[:, 0], acc[:, 1]), joint=joint)
        assert r.method == doc["method"]
        for key in ("a_over_b", "alpha"):
            close(r[key].value, doc[key]["value"])
            close(r[key].std_error, doc[key]["std_error"])
        close(r.acceleration_fit.alpha.value, doc["acceleration_fit"]["alpha"]["value"])
        # The CLI's files as they are.
        f = vi.identify(
            restitution=EXAMPLES / "seed-impacts/restitution.csv",
            acceleration=str(EXAMPLES / "seed-impacts/acceleration.csv"),
            joint=joint,
        )
        assert f.a_over_b.value == r.a_over_b.value and f.alpha.value == r.alpha.value
    with pytest.raises(ValueError, match=r"acceleration.csv:\d+: wrong header: expected a column named `restitution`"):
        vi.identify(restitution=EXAMPLES / "seed-impacts/acceleration.csv")
    with pytest.raises(OSError, match="restitution: no-such.csv: cannot read"):
        vi.identify(restitution="no-such.csv")
    with pytest.raises(ValueError, match="restitution = 1.5: must be above 0 and below 1.5"):
        vi.identify(restitution=([0.1, 0.2], [0.9, 1.5]))


def test_simulate(cli):
    doc = cli("simulate", EXAMPLES / "fujita-row.toml", "--periods", "5")
    # Without a history, as the CLI without --out (dense output costs
    # evaluations, so the counters would differ).
    r = vi.simulate(EXAMPLES / "fujita-row.toml", periods=5, output_step=0)
    for key in ("final_time", "final_displacement", "final_velocity"):
        close(r[key], doc[key])
    for key in ("impact_count", "rhs_evaluations", "steps", "rejected_steps", "completed"):
        assert r[key] == doc[key], key
    assert [c.impacts for c in r.impacts_per_contact] == [c["impacts"] for c in doc["impacts_per_contact"]]
    assert r.impacts["restitution"].size == doc["impact_count"]
    # With a history the trajectory is the same to the tolerance, and the
    # history ends at the final state.
    h = vi.simulate(EXAMPLES / "fujita-row.toml", periods=5)
    assert h.t[-1] == pytest.approx(doc["final_time"], rel=1e-12)
    np.testing.assert_allclose(h.displacement[-1], doc["final_displacement"], atol=1e-9)
    close(h.displacement[-1], h.final_displacement)


def test_simulate_local(cli):
    # The local integrator (exact motion between contacts) from both faces:
    # the same numbers and the same work counters; sampling a history does
    # not move the trajectory.
    doc = cli("simulate", EXAMPLES / "fujita-row.toml", "--periods", "5", "--integrator", "local")
    r = vi.simulate(EXAMPLES / "fujita-row.toml", periods=5, output_step=0, integrator="local")
    assert doc["integrator"] == r.integrator == "local"
    for key in ("final_time", "final_displacement", "final_velocity"):
        close(r[key], doc[key])
    for key in ("impact_count", "rhs_evaluations", "steps", "completed"):
        assert r[key] == doc[key], key
    assert r.local.to_dict() == doc["local"]
    assert doc["local"]["bodies_integrated"] == 3
    h = vi.simulate(EXAMPLES / "fujita-row.toml", periods=5, integrator="local")
    close(h.final_displacement, doc["final_displacement"])
    close(h.displacement[-1], h.final_displacement)
    g = vi.simulate(EXAMPLES / "fujita-row.toml", periods=5, output_step=0)
    assert g.integrator == "global" and g.impact_count == r.impact_count
    with pytest.raises(ValueError, match="integrator"):
        vi.simulate(EXAMPLES / "fujita-row.toml", periods=1, integrator="fast")


def test_periodic_local(cli):
    # The dense period map by the local integrator, from both faces; the
    # orbit of the global integrator's to the tolerance.
    doc = cli("periodic", EXAMPLES / "fujita-row.toml", "--symmetric", "--integrator", "local")
    r = vi.periodic(EXAMPLES / "fujita-row.toml", symmetric=True, integrator="local")
    for key in ("period", "initial_state", "floquet_multipliers", "spectral_radius"):
        close(r[key], doc[key])
    g = vi.periodic(EXAMPLES / "fujita-row.toml", symmetric=True)
    np.testing.assert_allclose(r.initial_state, g.initial_state, rtol=0, atol=1e-10)
    np.testing.assert_allclose(r.floquet_multipliers, g.floquet_multipliers, rtol=0, atol=1e-6)
    # Newton-Krylov on the local integrator's tape: the same orbit.
    doc = cli("periodic", EXAMPLES / "fujita-row.toml", "--symmetric", "--krylov", "--integrator", "local")
    k = vi.periodic(EXAMPLES / "fujita-row.toml", symmetric=True, krylov=True, integrator="local")
    close(k.initial_state, doc["initial_state"])
    np.testing.assert_allclose(k.initial_state, g.initial_state, rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match="integrator"):
        vi.periodic(EXAMPLES / "fujita-row.toml", integrator="fast")


def test_continue_local(cli):
    # A branch by the local integrator, from both faces; its special points
    # are the global integrator's to 1e-6 of the parameter.
    m = EXAMPLES / "fujita-row-n2.toml"
    args = ("--parameter", "frequency", "--from", "11.115", "--to", "3.705")
    doc = cli("continue", m, *args, "--integrator", "local")
    r = vi.continue_(m, "frequency", 11.115, 3.705, integrator="local")
    g = vi.continue_(m, "frequency", 11.115, 3.705)
    assert r.stop == doc["stop"] == "ReachedEnd"
    close(r.column("parameter"), [p["parameter"] for p in doc["points"]])
    assert [s.label for s in r.special_points] == [s.label for s in g.special_points]
    np.testing.assert_allclose(
        r.column("parameter", "special_points"), g.column("parameter", "special_points"), rtol=1e-6
    )


def test_continue_falls_back_to_the_homotopy(cli):
    # At 0.95 w0 the row's simulated guess does not converge: both faces
    # start from the homotopy in the amplitude (the library's study) and
    # give the same branch; `start` and the linear algebra are keywords.
    m = EXAMPLES / "fujita-row.toml"
    doc = cli("continue", m, "--parameter", "frequency", "--from", "7.0395", "--to", "7.5")
    r = vi.continue_(m, "frequency", 7.0395, 7.5)
    assert r.stop == doc["stop"] == "ReachedEnd"
    close(r.column("parameter"), [p["parameter"] for p in doc["points"]])
    close(r.points[-1].max_displacement, doc["points"][-1]["max_displacement"])
    h = vi.continue_(m, "frequency", 7.0395, 7.5, start="homotopy", dense=True)
    close(h.column("parameter"), r.column("parameter"))
    with pytest.raises(vi.VibroimpactError, match="start"):
        vi.continue_(m, "frequency", 7.0395, 7.5, start="simulate")
    with pytest.raises(ValueError, match="start"):
        vi.continue_(m, "frequency", 7.0395, 7.5, start="guess")
    with pytest.raises(ValueError, match="krylov = True, dense = True"):
        vi.continue_(m, "frequency", 7.0395, 7.5, krylov=True, dense=True)
    with pytest.raises(ValueError, match="from_ = 7.5, to = 7.5: the range is empty"):
        vi.continue_(m, "frequency", 7.5, 7.5)


def test_continue_with_curves(cli, tmp_path):
    # R2 N = 1: the fold curves in (frequency, amplitude) through the
    # branch's folds, the same from both faces (the library's curve driver).
    text = (EXAMPLES / "fujita-row-n2.toml").read_text().replace("count = 2", "count = 1")
    m = tmp_path / "n1.toml"
    m.write_text(text)
    args = ("--parameter", "frequency", "--from", "3.705", "--to", "11.115")
    doc = cli("continue", m, *args, "--parameter2", "amplitude", "--from2", "0.001",
              "--to2", "0.1", "--curves", "fold")
    r = vi.continue_(m, "frequency", 3.705, 11.115, parameter2="amplitude", from2=0.001,
                     to2=0.1, curves=["fold"])
    assert [c["kind"] for c in r.curves] == [c["kind"] for c in doc["curves"]] == ["fold"] * 4
    for a, b in zip(r.curves, doc["curves"]):
        assert a["stop"] == b["stop"]
        close([p["amplitude"] for p in a["points"]], [p["amplitude"] for p in b["points"]])
    assert len(r.curves_skipped) == len(doc["curves_skipped"]) == 0
    # The same curves from the branch's special points, without the branch
    # (the CLI's --special-points).
    again = vi.continue_(m, "frequency", 3.705, 11.115, parameter2="amplitude", from2=0.001,
                         to2=0.1, curves=["fold"], special_points=r)
    assert [c["kind"] for c in again.curves] == ["fold"] * 4
    close(again.curves[0]["points"][-1]["amplitude"], r.curves[0]["points"][-1]["amplitude"])
    with pytest.raises(ValueError, match="curves = torus: give any of fold, bp"):
        vi.continue_(m, "frequency", 3.705, 11.115, parameter2="amplitude", curves=["torus"])
    with pytest.raises(ValueError, match='parameter2 = "frequency": the same key'):
        vi.continue_(m, "frequency", 3.705, 11.115, parameter2="frequency")


def _same_document(a, b, path="doc"):
    """The same fields and nesting, numbers within REL."""
    if isinstance(b, dict):
        assert sorted(a) == sorted(b), f"{path}: {sorted(a)} against {sorted(b)}"
        for k in b:
            _same_document(a[k], b[k], f"{path}.{k}")
    elif isinstance(b, list) and b and not all(isinstance(x, (int, float)) for x in b):
        assert len(a) == len(b), path
        for k, (x, y) in enumerate(zip(a, b)):
            _same_document(x, y, f"{path}[{k}]")
    elif isinstance(b, list) or isinstance(b, float):
        close(a, b)
    elif b is None and isinstance(a, float):
        # JSON null in a list of numbers (an elastic storey's ductility)
        # is NaN in the array Python returns.
        assert np.isnan(a), f"{path}: {a!r} against null"
    else:
        assert a == b, f"{path}: {a!r} against {b!r}"


def test_pounding_documents_have_one_shape(cli):
    # Several records, units, the free response, the pounding spectrum
    # over gaps x ratios: Python returns the CLI's document.
    pair = EXAMPLES / "pounding-frames.toml"
    quake = EXAMPLES / "synthetic-quake.csv"
    doc = cli("pounding", pair, quake, quake, "--units", "m/s2", "--scale", "0.8")
    r = vi.pounding(pair, [quake, quake], units="m/s2", scale=0.8)
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    assert doc["runs"][0]["pounding"]["peak_drift"]["left"]
    spectrum = ("--gaps", "0.01:0.03:2", "--ratios", "1:1.5:2")
    doc = cli("pounding", pair, quake, "--units", "m/s2", *spectrum)
    r = vi.pounding(pair, quake, units="m/s2", gaps="0.01:0.03:2", ratios=[1.0, 1.5])
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    alone = cli("pounding", pair, quake, "--units", "m/s2", "--free", "false")
    assert sorted(alone["runs"][0]) == ["pounding", "record"]
    with pytest.raises(OSError, match="pair: no-such-pair.toml: cannot read"):
        vi.pounding("no-such-pair.toml", quake, units="m/s2")
    with pytest.raises(ValueError, match="gaps = 0.01:0.03: give FROM:TO:N"):
        vi.pounding(pair, quake, units="m/s2", gaps="0.01:0.03", ratios="1:2:2")


def test_isolated_building_documents_have_one_shape(cli):
    # An isolated building with yielding storeys against its moat wall:
    # the runs (isolators, ductility, hysteretic energy) and the moat-gap
    # study are the CLI's documents.
    building = EXAMPLES / "isolated-building.toml"
    quake = EXAMPLES / "synthetic-quake.csv"
    doc = cli("pounding", building, quake, "--units", "m/s2", "--scale", "2")
    r = vi.pounding(building, quake, units="m/s2", scale=2)
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    iso = doc["runs"][0]["pounding"]["isolators"]["isolated"]
    assert iso["moat_impacts"] > 0 and iso["capacity"] == 0.45
    doc = cli("pounding", building, quake, "--units", "m/s2", "--scale", "2", "--moat-gaps", "0.1:0.3:2")
    r = vi.pounding(building, quake, units="m/s2", scale=2, moat_gaps=[0.1, 0.3])
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    h = vi.pounding_history(building, vi.read_record(quake, units="m/s2"), scale=2, sample=0.0025)
    assert [(x["building"], x["storey"]) for x in h["loops"]] == [("isolated", None)] + [
        ("isolated", k) for k in (1, 2, 3, 4)]
    bearings = h["loops"][0]
    assert bearings["drift"].shape == bearings["force"].shape == h["t"].shape
    # The loop's samples stay below the exact peak (on the dense output),
    # within 1e-3 of it at 2.5 ms.
    sampled, exact = np.max(np.abs(bearings["drift"])), iso["peak_displacement"]
    assert exact * (1 - 1e-3) <= sampled <= exact * (1 + 1e-12)
    assert "isolated moat" in h["impact_at"] and h["slab"]["isolated"].shape == h["t"].shape
    with pytest.raises(ValueError, match="moat_gaps: give it or gaps and ratios"):
        vi.pounding(building, quake, units="m/s2", gaps="0.1:0.2:2", ratios="1:2:2", moat_gaps="0.1:0.2:2")


def test_local_integrator_with_yielding_storeys(cli):
    # The isolated building (yielding storeys, lead-rubber bearings, moat
    # struck) by the local integrator: Python returns the CLI's document,
    # and every peak is the global run's to 1e-5.
    building = EXAMPLES / "isolated-building.toml"
    quake = EXAMPLES / "synthetic-quake.csv"
    args = ("pounding", building, quake, "--units", "m/s2", "--scale", "2", "--free", "false")
    doc = cli(*args, "--integrator", "local")
    r = vi.pounding(building, quake, units="m/s2", scale=2, free=False, integrator="local")
    _same_document(json.loads(json.dumps(r.to_dict())), doc)
    local, glob = doc["runs"][0]["pounding"], cli(*args, "--integrator", "global")["runs"][0]["pounding"]
    for key in ("peak_drift", "peak_floor_acceleration", "hysteretic_energy"):
        np.testing.assert_allclose(local[key]["isolated"], glob[key]["isolated"], rtol=1e-5, err_msg=key)
    a, b = local["isolators"]["isolated"], glob["isolators"]["isolated"]
    assert a["moat_impacts"] == b["moat_impacts"] > 0
    for key in ("peak_displacement", "moat_peak_force", "hysteretic_energy"):
        assert a[key] == pytest.approx(b[key], rel=1e-5), key


def test_periodic(cli):
    # The three-pendulum row's unstable symmetric orbit from the simulated
    # guess (the two-pendulum row's motion at 0.95 omega0 is irregular too:
    # where its 200 simulated periods end is a matter of the last bits).
    doc = cli("periodic", EXAMPLES / "fujita-row.toml", "--symmetric")
    r = vi.periodic(EXAMPLES / "fujita-row.toml", symmetric=True)
    for key in ("period", "initial_state", "floquet_multipliers", "max_displacement", "max_velocity", "spectral_radius"):
        close(r[key], doc[key])
    assert r.stable == doc["stable"] and r.symmetric_orbit == doc["symmetric_orbit"]
    assert r.orbit_displacement.shape == (r.orbit_t.size, 3)


def test_periodic_guesses(cli, tmp_path):
    # The homotopy and a guess file, as the CLI takes them.
    m = EXAMPLES / "fujita-row-n2.toml"
    doc = cli("periodic", m, "--guess", "homotopy")
    h = vi.periodic(m, guess="homotopy")
    assert list(h.initial_state) == doc["initial_state"]
    saved = tmp_path / "summary.json"
    saved.write_text(json.dumps(doc))
    again = cli("periodic", m, "--guess", saved)
    f = vi.periodic(m, guess=saved)
    close(f.initial_state, again["initial_state"])
    with pytest.raises(OSError, match="cannot read it"):
        vi.periodic(m, guess="no-such.json")
    # Forced through a body, not the base: no amplitude for the homotopy,
    # refused by the guess's own name in both faces.
    forced = tmp_path / "forced.toml"
    forced.write_text(
        "[row]\ncount = 1\nmass = 1\nnatural_frequency = 5\ndamping_ratio = 0.02\n"
        "clearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n"
        "[[force]]\nbody = \"p1\"\namplitude = 1\nfrequency = 4\n"
    )
    with pytest.raises(ValueError, match="guess = 'homotopy': the homotopy needs a forcing amplitude"):
        vi.periodic(forced, guess="homotopy")


@pytest.mark.parametrize("parameter,from_,to", [
    ("frequency", 11.115, 3.705),
    # From the rest state at zero forcing (the amplitude homotopy).
    ("amplitude", 0.0, 0.05),
])
def test_continue(cli, parameter, from_, to):
    m = EXAMPLES / "fujita-row-n2.toml"
    doc = cli("continue", m, "--parameter", parameter, "--from", repr(from_), "--to", repr(to))
    r = vi.continue_(m, parameter, from_, to)
    assert r.stop == doc["stop"] == "ReachedEnd"
    assert len(r.points) == len(doc["points"])
    close(r.column("parameter"), [p["parameter"] for p in doc["points"]])
    close(r.column("max_displacement"), [p["max_displacement"] for p in doc["points"]])
    assert [s.label for s in r.special_points] == [s["label"] for s in doc["special_points"]]
    close(r.column("parameter", "special_points"), [s["parameter"] for s in doc["special_points"]])
    if parameter == "amplitude":
        # From rest; well below the first contact the row is linear, its
        # response in proportion to the forcing (the exponential law's
        # force is exp(-65) of its scale at half the grazing amplitude).
        a, u = r.column("parameter"), r.column("max_displacement")
        assert a[0] == 0.0 and np.all(u[0] == 0.0)
        graze = min(s.parameter for s in r.special_points if s.kind == "grazing")
        free = (a > 0) & (a < 0.5 * graze)
        assert free.sum() >= 5
        ratio = u[free, 0] / a[free]
        np.testing.assert_allclose(ratio, ratio[0], rtol=1e-8)


@pytest.mark.parametrize("integrator", ["global", "local"])
def test_sweep(cli, integrator):
    m = EXAMPLES / "fujita-row.toml"
    doc = cli(
        "sweep", m, "--parameter", "frequency", "--from", "5.9", "--to", "8.9",
        "--points", "5", "--transient", "20", "--record", "5", "--up-down",
        "--integrator", integrator,
    )
    r = vi.sweep(m, "frequency", from_=5.9, to=8.9, points=5, transient=20, record=5, up_down=True,
                 integrator=integrator)
    assert len(r.points) == len(doc["points"]) == 10
    for p, q in zip(r.points, doc["points"]):
        assert (p.direction, p.distinct_section_points, p.completed) == (q["direction"], q["distinct_section_points"], q["completed"])
        close(p.parameter, q["parameter"])
        close(p.max_displacement, q["max_displacement"])
        close(p.section_spread, q["section_spread"])
        assert p.sections.shape == (5, 6)


def test_sweep_lyapunov_matches_the_cli(cli):
    m = EXAMPLES / "fujita-row-n2.toml"
    doc = cli("sweep", m, "--parameter", "frequency", "--from", "7.0", "--to", "8.0",
              "--points", "2", "--record", "30", "--lyapunov", "3")
    r = vi.sweep(m, "frequency", from_=7.0, to=8.0, points=2, record=30, lyapunov=3)
    for p, q in zip(r.points, doc["points"]):
        assert len(p.lyapunov) == 3
        close(p.lyapunov, q["lyapunov"])
        close(p.lyapunov_uncertainty, q["lyapunov_uncertainty"])
    with pytest.raises(ValueError, match="lyapunov"):
        vi.sweep(m, "frequency", from_=7.0, to=8.0, points=2, lyapunov=0)
    with pytest.raises(ValueError, match="lyapunov = 5"):
        vi.sweep(m, "frequency", from_=7.0, to=8.0, points=2, lyapunov=5)


def test_chart_matches_the_cli(cli):
    m = EXAMPLES / "fujita-row-n2.toml"
    doc = cli("chart", m, "--x", "frequency", "--x-from", "6.5", "--x-to", "8.5", "--x-points", "3",
              "--y", "row.clearance", "--y-from", "1e-3", "--y-to", "2e-3", "--y-points", "2",
              "--transient", "20", "--record", "6", "--starts", "2", "--lyapunov")
    r = vi.chart(m, "frequency", vi.parameter_values(6.5, 8.5, 3), "row.clearance",
                 vi.parameter_values(1e-3, 2e-3, 2), transient=20, record=6, starts=2, lyapunov=True)
    with pytest.raises(ValueError, match="integrator"):
        vi.chart(m, "frequency", [7.0], "amplitude", [0.05], integrator="exact")
    assert len(r.cells) == len(doc["cells"]) == 6
    for c, d in zip(r.cells, doc["cells"]):
        assert (c.x, c.y, c.attractors) == (d["x"], d["y"], d["attractors"])
        for a, b in zip(c.runs, d["runs"]):
            assert (a.period, a.error) == (b["period"], b["error"])
            close(a.max_displacement, b["max_displacement"])
            close(a.lyapunov, b["lyapunov"])
    with pytest.raises(ValueError, match="the same key"):
        vi.chart(m, "frequency", [7.0], "excitation.frequency", [7.0])
    with pytest.raises(ValueError, match="starts = 0"):
        vi.chart(m, "frequency", [7.0], "amplitude", [0.05], starts=0)
    with pytest.raises(TypeError, match="x: expected a parameter name"):
        vi.chart(m, 3, [7.0], "amplitude", [0.05])


def test_basins_match_the_cli(cli):
    m = EXAMPLES / "fujita-row-n2.toml"
    doc = cli("basins", m, "--x", "u1", "--x-from=-1.2e-3", "--x-to", "0.8e-3", "--x-points", "3",
              "--y", "v1", "--y-from=-0.02", "--y-to", "0.02", "--y-points", "2",
              "--transient", "20", "--record", "6")
    r = vi.basins(m, "u1", vi.parameter_values(-1.2e-3, 0.8e-3, 3), "v1",
                  vi.parameter_values(-0.02, 0.02, 2), transient=20, record=6)
    # (None where no attractor: NaN in the result's array)
    expected = [np.nan if c is None else c for c in doc["cells"]]
    np.testing.assert_array_equal(np.asarray(r.cells, dtype=float), expected)
    assert r.inadmissible == doc["inadmissible"] == 2
    assert len(r.attractors) == len(doc["attractors"])
    for a, b in zip(r.attractors, doc["attractors"]):
        assert (a.period, a.cells) == (b["period"], b["cells"])
    with pytest.raises(ValueError, match="x: component `w1`"):
        vi.basins(m, "w1", [0.0, 1e-4], "v1", [0.0, 0.01])
    with pytest.raises(ValueError, match="base: needs 4 values"):
        vi.basins(m, "u1", [0.0, 1e-4], "v1", [0.0, 0.01], base=[0.0, 0.0, 0.0])


def test_parameter_values_match_the_cli(cli):
    # (to - from) i / (k - 1) rounds differently from (to - from)(i / (k - 1))
    # at some i: the values must be the CLI's to the bit.
    m = ROOT / "examples" / "fujita-row.toml"
    doc = cli("sweep", m, "--parameter", "row.clearance", "--from", "1e-3", "--to", "2.3e-3",
              "--points", "13", "--transient", "0", "--record", "2")
    v = vi.parameter_values(1e-3, 2.3e-3, 13)
    assert v.tolist() == [p["parameter"] for p in doc["points"]]


def test_spectrum_document_has_the_cli_shape(cli):
    # The CLI's spectrum JSON is the schema: Python returns its fields (the
    # record as read, damping, peaks, units) with the rows as columns.
    quake = EXAMPLES / "synthetic-quake.csv"
    doc = cli("spectrum", quake, "--units", "m/s2", "--scale", "0.8", "--damping", "0.03")
    r = vi.response_spectrum(quake, units="m/s2", scale=0.8, damping=0.03)
    rows = doc.pop("rows")
    for key in ("period", "pseudo_acceleration", "pseudo_velocity", "displacement"):
        close(r[key], [row[key] for row in rows])
    got = {k: v for k, v in r.to_dict().items() if k in doc}
    assert set(got) == set(doc)
    _same_document(got, doc, "spectrum")


def test_pushover(cli):
    # The archetype's pushover: the same curve and FEMA P695 quantities;
    # options and a missing building refused by name.
    path = EXAMPLES / "moment-frame-4.toml"
    doc = cli("pushover", str(path), "--points", "200")
    r = vi.pushover(path, points=200)
    for key in ("roof_displacement", "base_shear", "drifts", "pattern"):
        close(r[key], doc[key])
    for key in ("max_base_shear", "yield_displacement", "ultimate_displacement", "ductility", "c0"):
        close(r[key], doc[key])
    # The code-designed SMF: storey 1 critical, its strength lost (to
    # 0.8 V_max) within the push without a collapse; mu_T 2.68.
    assert r["critical_storey"] == doc["critical_storey"] == 1
    assert r["strength_loss"] and doc["strength_loss"] and not r["collapsed"] and not doc["collapsed"]
    assert 2.4 < r["ductility"] < 3.0
    with pytest.raises(ValueError, match="drift_ratio_limit"):
        vi.pushover(path, drift_ratio_limit=-1.0)
    with pytest.raises(ValueError, match="points"):
        vi.pushover(path, points=1)
    with pytest.raises(ValueError, match="building"):
        vi.pushover(path, "nope")
    with pytest.raises(ValueError, match="heights"):
        vi.pushover(EXAMPLES / "pounding-frames.toml")
