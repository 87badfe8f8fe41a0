"""Sweeps and ensembles on a Dask LocalCluster of two worker processes: bit
for bit the local results; the command-line entry; a missing scheduler."""

import json
import subprocess
import sys

import numpy as np
import pytest

import vibroimpact as vi
from conftest import EXAMPLES, ROOT
from vibroimpact.distributed import ensemble

distributed = pytest.importorskip("dask.distributed")

ROW = EXAMPLES / "fujita-row.toml"


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def same(a, b):
    """Bit-for-bit equality of two results (NaN equal to NaN)."""
    da, db = a.to_dict(), b.to_dict()
    return json.dumps(da, sort_keys=True) == json.dumps(db, sort_keys=True)


def test_sweep_is_bit_identical_to_the_local_run(client):
    kw = dict(from_=5.9, to=8.9, points=13, transient=15, record=4)
    local = vi.sweep(ROW, "frequency", **kw)
    for tasks in (None, 3, 13):
        remote = vi.sweep(ROW, "frequency", client=client, tasks=tasks, **kw)
        assert same(local, remote), tasks
        for p, q in zip(local.points, remote.points):
            assert np.array_equal(p.sections, q.sections)
    one_thread = vi.sweep(ROW, "frequency", threads=1, **kw)
    assert same(local, one_thread)


def test_chart_is_bit_identical_to_the_local_run(client):
    kw = dict(transient=10, record=4, starts=2)
    xs, ys = [6.0, 7.0, 8.0], [0.03, 0.05, 0.07, 0.09]
    local = vi.chart(ROW, "frequency", xs, "amplitude", ys, **kw)
    for tasks in (None, 3):
        remote = vi.chart(ROW, "frequency", xs, "amplitude", ys, client=client, tasks=tasks, **kw)
        assert same(local, remote), tasks
    assert same(local, vi.chart(ROW, "frequency", xs, "amplitude", ys, threads=1, **kw))


def test_basins_are_bit_identical_to_the_local_run(client):
    # vi.basins had no client=: the rows run on the workers, the attractors
    # are identified here over all of them (the row of two at 7.45 rad/s:
    # period 3, period 1 and irregular motion side by side).
    row = vi.Model.load(EXAMPLES / "fujita-row-n2.toml").with_(frequency=7.45)
    xs, ys = np.linspace(-0.9e-3, 0.9e-3, 5), np.linspace(-0.06, 0.06, 4)
    kw = dict(transient=100, record=10)
    local = vi.basins(row, "u1", xs, "v1", ys, **kw)
    assert sorted(a.period or 0 for a in local.attractors) == [0, 1, 3]
    for tasks in (None, 3):
        remote = vi.basins(row, "u1", xs, "v1", ys, client=client, tasks=tasks, **kw)
        assert same(local, remote), tasks
    with pytest.raises(ValueError, match="tasks: applies with a Dask client only"):
        vi.basins(row, "u1", xs, "v1", ys, tasks=2, **kw)


def test_up_down_sweep_on_the_cluster(client):
    kw = dict(values=[6.0, 7.0, 8.0], transient=10, record=3, up_down=True)
    assert same(vi.sweep(ROW, "frequency", **kw), vi.sweep(ROW, "frequency", client=client, **kw))


def test_ensemble_of_models(client):
    base = vi.Model.load(ROW)
    models = [base.with_(amplitude=a) for a in (0.02, 0.05, 0.08)]
    here = ensemble(models, "simulate", periods=3, output_step=0)
    there = ensemble(models, "simulate", client=client, periods=3, output_step=0)
    assert len(there) == 3
    for a, b in zip(here, there):
        assert np.array_equal(a.final_displacement, b.final_displacement)
    assert here[0].impact_count < here[2].impact_count
    # A numerical failure is one entry's error, not the ensemble's.
    out = ensemble([base, base], "periodic", client=client, guess_periods=1)
    assert all("Newton did not converge" in r.error for r in out)


def test_command_line_entry_matches_the_cli(cli):
    args = ["--parameter", "frequency", "--from", "6", "--to", "8", "--points", "4",
            "--transient", "10", "--record", "3"]
    out = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "sweep", str(ROW), *args],
        capture_output=True, text=True, cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    mine = json.loads(out.stdout)
    theirs = cli("sweep", ROW, *args)
    assert mine == theirs


def test_missing_scheduler_is_a_clear_error():
    out = subprocess.run(
        [sys.executable, "-m", "vibroimpact", "sweep", str(ROW), "--parameter", "frequency",
         "--from", "6", "--to", "8", "--points", "3", "--scheduler", "tcp://127.0.0.1:9",
         "--timeout", "2"],
        capture_output=True, text=True, cwd=ROOT,
    )
    assert out.returncode == 2
    assert "--scheduler tcp://127.0.0.1:9: cannot connect" in out.stderr
    with pytest.raises(TypeError, match="client"):
        vi.sweep(ROW, "frequency", values=[6.0, 7.0], client=object())


def test_ida_of_a_pounding_pair_is_the_same_on_the_cluster(client):
    """Incremental dynamic analysis (one task per record, its scales in it): the
    cluster's numbers are the local ones bit for bit; the peak impact force
    grows with the scale; 'impact force above 1 MN' separates the runs by
    their intensity (every exceedance above every non-exceedance), so its
    fragility is refused as not determined (it was given with beta at the
    search grid's edge)."""
    from vibroimpact import distributed as dist
    from vibroimpact import records

    pair = EXAMPLES / "pounding-frames.toml"
    recs = [records.gmspy_record(n) for n in ("Kobe", "Northridge")]
    scales = [0.25, 0.5, 1.0, 2.0]
    local = dist.ida(pair, recs, scales)
    remote = dist.ida(pair, recs, scales, client=client)
    for key in ("sa", "peak_impact_force", "impacts", "max_drift", "required_gap"):
        np.testing.assert_array_equal(local[key], remote[key])
    assert local["sa"].size == 8 and local["period"] > 0
    f = local["peak_impact_force"].reshape(2, 4)
    assert np.all(np.diff(f, axis=1) >= 0), f
    with pytest.raises(ValueError, match="dispersion is not determined"):
        dist.fragility(local["sa"], local["peak_impact_force"] > 1e6)


def test_fragility_recovers_a_lognormal():
    from vibroimpact import distributed as dist

    x = np.geomspace(0.5, 20.0, 30)
    theta, beta = 3.0, 0.45
    p = dist._normal_cdf(np.log(x / theta) / beta)
    fit = dist.fragility(x, p)
    assert fit["theta"] == pytest.approx(theta, rel=1e-3)
    assert fit["beta"] == pytest.approx(beta, rel=1e-3)
    with pytest.raises(ValueError, match="intensity"):
        dist.fragility([0.0, 1.0], [0, 1])


def test_collapse_study_is_bit_identical_on_the_cluster(client):
    # One Dask task per record (each record's IDA inside it): the document
    # is the local one bit for bit.
    epp = ('[[building]]\nname = "epp"\nmasses = [1e5]\nstiffnesses = [4e6]\ndamping_ratio = 0.0\n'
           'storeys = [{ law = "bilinear", yield_drift = 0.05, post_yield_ratio = 0.0 }]\n')
    recs = [{"source": f"step {a}", "times": np.array([0.0, 40.0]), "acceleration": np.array([a, a])}
            for a in (0.8, 1.0, 1.3, 2.1, 0.05)]
    kw = dict(drift_limit=0.5, first=0.5, max_scale=8.0, sample=0.004, rtol=1e-8, period=1.0)
    local = vi.collapse_study(epp, recs, **kw)
    seen = []
    remote = vi.collapse_study(epp, recs, client=client, progress=lambda d, t: seen.append((d, t)), **kw)
    assert same(local, remote)
    assert seen[-1] == (5, 5)
