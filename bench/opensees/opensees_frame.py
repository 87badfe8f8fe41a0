"""A fixed-base shear building with P-Δ (a row file of one building,
``vibroimpact pounding``; docs/earthquakes.md "P-Δ", "Storeys that
yield") built in OpenSees (openseespy), for the peer comparison of issue
37 ("collapse an engineer would sign").

The model is the same equations as vibroimpact's ``Building::place`` of a
fixed building (crates/vibroimpact/src/seismic/pounding/building.rs,
frame.rs), built the way bench/opensees/opensees_pair.py and
opensees_isolated.py build theirs:

* one-degree-of-freedom nodes (``model basic -ndm 1 -ndf 1``): the ground
  (fixed) and the floors (``masses``);
* storey i a ``zeroLength`` element from the floor below (the ground for
  storey 1) to floor i (opensees_pair.add_storey): ``Elastic(k_i, beta
  k_i)`` when elastic, else its law (``Steel01`` for ``bilinear``,
  ``IMKBilin`` for ``imk``: opensees_pair.storey_material) with a
  ``zeroLength`` dashpot ``beta k_i`` beside it;
* P-Δ (``p_delta = true``): storey i carries P_i = sum_{j >= i} (m_j g +
  L_j), g = 9.80665 m/s^2, L_j the ``leaning_loads``, through its drift d
  as the shear -(P_i/h_i) d (docs/theory.md §11). ``p_delta="spring"``
  (default): a ``zeroLength`` ``Elastic(-P_i/h_i)`` beside the storey, the
  linearised geometric stiffness. ``p_delta="leaning-column"``: the model
  in 2-D (``-ndm 2 -ndf 3``; the floors' y and rotation fixed) with a true
  leaning column: ``elasticBeamColumn`` segments (stiff axially, both ends
  released in bending, ``geomTransf PDelta``) from a pinned base up
  through a node at each floor level, each floor node tied to it in x by
  ``equalDOF`` (``constraints Transformation``); the gravity loads m_j g +
  L_j at its nodes applied first in a static step, then ``loadConst``.
  Its segment i carries N = -P_i, and PDelta's lateral geometric
  stiffness N/h_i is exactly the spring above;
* Rayleigh damping as vibroimpact's ``ShearFrame::rayleigh``: alpha, beta
  with zeta in modes 1 and 2 of the frame WITH P-Δ (stiffnesses k_i -
  P_i/h_i); the dampers act on the initial stiffnesses WITHOUT it: ``beta
  k_i`` beside storey i, ``alpha m_i`` from floor i to the ground;
* the record as a ``Path`` series (linear between samples) in a
  ``UniformExcitation`` pattern; for a building with a storey that yields,
  the free-vibration tail of 5 T (``TAIL_PERIODS``), T the fundamental
  period WITH P-Δ (vibroimpact's ``Building::period`` of a fixed
  building: ``ShearFrame::period``, k_i - P_i/h_i), the record's last
  sample ramped to zero over one record step (a 0 appended to the Path);
  an elastic building runs the record alone (vibroimpact's row has no tail
  then);
* Newmark's average acceleration with Newton iterations (or an explicit
  rule, ``CentralDifference`` or ``ExplicitDifference``), a constant step ``dt``: one ``analyze`` call up
  to one step before the residual window, one through it.

Outputs, as vibroimpact's ``runs[0].pounding`` of the building: the peak
storey drifts (an ``EnvelopeElement`` recorder of the storeys'
deformations) and drift ratios (over the heights); the residual drifts
(and ratios): the time mean of each drift over the building's last period
[t_end - T, t_end] (vibroimpact's: the mean on its dense output,
crates/vibroimpact/src/simulate/gauges.rs), here of the drift linear
between OpenSees' steps, from an ``Element`` recorder (``-time``) added
for the window (the run goes on to the first step at or past t_end).
"""

from __future__ import annotations

import os
import tempfile
import time
from typing import Any, Dict, List, Union

import numpy as np

from opensees_pair import (
    one_building,
    TAIL_PERIODS,
    add_storey,
    import_opensees,
    transient,
)
from opensees_pair import period as frame_period
from opensees_pair import rayleigh as frame_rayleigh

GRAVITY = 9.80665
"""Standard gravity (m/s^2), vibroimpact's ``STANDARD_GRAVITY``."""

P_DELTA = ("spring", "leaning-column")

# The leaning column's segments: axially stiff (EA/h ~ 5e13 N/m: its
# shortening under the gravity loads is ~1e-6 m), in bending released at
# both ends; it stands LEAN_X from the floors' nodes (any distance).
LEAN_E, LEAN_A, LEAN_I, LEAN_X = 2.0e11, 1.0e3, 1.0, 10.0


def load(row: Union[str, os.PathLike, Dict[str, Any]]) -> Dict[str, Any]:
    """The one fixed-base building of a row file (a path, TOML text, the
    parsed document or the building's own table), checked to be what this
    module builds."""
    b = one_building(row, "building")
    if b.get("isolation") is not None:
        raise ValueError(f"building {b.get('name')!r} is isolated: bench/opensees/opensees_isolated.py builds it")
    n = len(b["masses"])
    if b.get("p_delta", False) and len(b.get("heights", [])) != n:
        raise ValueError("p_delta needs one height per storey")
    if len(b.get("heights", [])) not in (0, n):
        raise ValueError("give one height per storey")
    if b.get("leaning_loads") and not b.get("p_delta", False):
        raise ValueError("leaning_loads without p_delta = true")
    return b


def laws(building: Dict[str, Any]) -> List[Dict[str, Any]]:
    """The storeys' laws (all elastic without ``storeys``)."""
    return building.get("storeys") or [{"law": "elastic"}] * len(building["masses"])


def inelastic(building: Dict[str, Any]) -> bool:
    """Whether a storey yields (the run then has the free-vibration tail)."""
    return any(s.get("law", "elastic") != "elastic" for s in laws(building))


def gravity_loads(building: Dict[str, Any]) -> List[float]:
    """P_i (N): the weights of the floors at and above storey i and their
    leaning loads; zeros without P-Δ (vibroimpact's
    ``ShearFrame::gravity_loads``)."""
    m = building["masses"]
    if not building.get("p_delta", False):
        return [0.0] * len(m)
    lean = building.get("leaning_loads") or [0.0] * len(m)
    p, above = [0.0] * len(m), 0.0
    for i in reversed(range(len(m))):
        above += m[i] * GRAVITY + lean[i]
        p[i] = above
    return p


def geometric_stiffnesses(building: Dict[str, Any]) -> List[float]:
    """P_i/h_i (N/m), the P-Δ stiffness of each storey; zeros without P-Δ."""
    return [p / h if p else 0.0 for p, h in zip(gravity_loads(building), building.get("heights") or [1.0] * len(building["masses"]))]


def with_p_delta(building: Dict[str, Any]) -> Dict[str, Any]:
    """The frame of the modes: stiffnesses k_i - P_i/h_i (vibroimpact's
    ``ShearFrame::stiffness_matrix``)."""
    return {
        "masses": building["masses"],
        "stiffnesses": [k - g for k, g in zip(building["stiffnesses"], geometric_stiffnesses(building))],
        "damping_ratio": building["damping_ratio"],
    }


def rayleigh(building: Dict[str, Any]):
    """(alpha, beta): zeta in modes 1 and 2 of the frame with P-Δ."""
    return frame_rayleigh(with_p_delta(building))


def period(building: Dict[str, Any]) -> float:
    """The fundamental period (s) with P-Δ, vibroimpact's ``Building::
    period`` of a fixed building (the tail's and the residual window's)."""
    return frame_period(with_p_delta(building))


def yield_drifts(building: Dict[str, Any]):
    """The storeys' yield drifts (None for an elastic storey)."""
    return [s.get("yield_drift") if s.get("law", "elastic") != "elastic" else None for s in laws(building)]


def window_mean(rows: np.ndarray, a: float, b: float) -> np.ndarray:
    """The time mean over [a, b] of each column of ``rows`` (time, then
    values), linear between the rows."""
    t = rows[:, 0]
    inside = t[(t > a) & (t < b)]
    grid = np.concatenate(([a], inside, [b]))
    out = []
    for j in range(1, rows.shape[1]):
        x = np.interp(grid, t, rows[:, j])
        out.append(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(grid)) / (b - a))
    return np.array(out)


def _build_spring(ops, building, new, alpha, beta):
    """The 1-D model, P-Δ as springs; returns the storey elements."""
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ground = new("node")
    ops.node(ground, 0.0)
    ops.fix(ground, 1)
    storeys = []
    below = ground
    for m, k, law, kg in zip(building["masses"], building["stiffnesses"], laws(building),
                             geometric_stiffnesses(building)):
        nd = new("node")
        ops.node(nd, 0.0, "-mass", m)
        storeys.append(add_storey(ops, new, below, nd, k, law, beta))
        if kg:
            mat = new("mat")
            ops.uniaxialMaterial("Elastic", mat, -kg)
            ops.element("zeroLength", new("ele"), below, nd, "-mat", mat, "-dir", 1)
        if alpha > 0.0:
            mat = new("mat")
            ops.uniaxialMaterial("Elastic", mat, 0.0, alpha * m)
            ops.element("zeroLength", new("ele"), ground, nd, "-mat", mat, "-dir", 1)
        below = nd
    return storeys


def _build_leaning(ops, building, new, alpha, beta):
    """The 2-D model with a leaning column carrying the gravity loads
    (applied here in a static step, then held); returns the storey
    elements."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ground = new("node")
    ops.node(ground, 0.0, 0.0)
    ops.fix(ground, 1, 1, 1)
    storeys, floors = [], []
    below = ground
    for m, k, law in zip(building["masses"], building["stiffnesses"], laws(building)):
        nd = new("node")
        ops.node(nd, 0.0, 0.0, "-mass", m, 0.0, 0.0)
        ops.fix(nd, 0, 1, 1)
        storeys.append(add_storey(ops, new, below, nd, k, law, beta))
        if alpha > 0.0:
            mat = new("mat")
            ops.uniaxialMaterial("Elastic", mat, 0.0, alpha * m)
            ops.element("zeroLength", new("ele"), ground, nd, "-mat", mat, "-dir", 1)
        floors.append(nd)
        below = nd
    if not building.get("p_delta", False):
        return storeys
    ops.geomTransf("PDelta", 1)
    base = new("node")
    ops.node(base, LEAN_X, 0.0)
    ops.fix(base, 1, 1, 1)  # pinned: the segment is released in bending
    lean = building.get("leaning_loads") or [0.0] * len(floors)
    y, below = 0.0, base
    column = []
    for nd, h in zip(floors, building["heights"]):
        y += h
        top = new("node")
        ops.node(top, LEAN_X, y)
        ops.fix(top, 0, 0, 1)  # its rotation carries nothing (released)
        ops.element("elasticBeamColumn", new("ele"), below, top, LEAN_A, LEAN_E, LEAN_I, 1, "-release", 3)
        ops.equalDOF(nd, top, 1)
        column.append(top)
        below = top
    ops.timeSeries("Linear", 2)
    ops.pattern("Plain", 2, 2)
    for top, m, l in zip(column, building["masses"], lean):
        ops.load(top, 0.0, -(m * GRAVITY + l), 0.0)
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 20)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        raise RuntimeError("OpenSees: the leaning column's gravity step failed")
    ops.loadConst("-time", 0.0)
    ops.wipeAnalysis()
    return storeys


def run(
    row: Union[str, os.PathLike, Dict[str, Any]],
    times: np.ndarray,
    acceleration: np.ndarray,
    scale: float,
    dt: float,
    system: str = "BandGeneral",
    algorithm: str = "Newton",
    tol: float = 1e-10,
    integrator: str = "Newmark",
    p_delta: str = "spring",
) -> Dict[str, Any]:
    """One OpenSees run of the fixed-base building of ``row`` under the
    record (``times``, ``acceleration`` in m/s^2, uniform from t = 0) times
    ``scale``, constant step ``dt``, through the free-vibration tail if a
    storey yields; the equation solver, Newton variant, displacement-
    increment tolerance (m) and integrator (``Newmark``: average
    acceleration; ``CentralDifference`` or ``ExplicitDifference``:
    explicit, ``algorithm Linear``, with ``-factorOnce`` where given;
    ``opensees_pair.transient``) as given; P-Δ as ``p_delta`` (``spring`` or ``leaning-column``). Returns
    the peak drifts and drift ratios, the residual drifts and ratios, the
    period, Rayleigh coefficients, duration, and the wall time of building
    and running the model."""
    if p_delta not in P_DELTA:
        raise ValueError(f"p_delta {p_delta!r}: one of {P_DELTA}")
    building = load(row)
    ops = import_opensees()
    rec_dt = float(times[1] - times[0])
    if not np.allclose(np.diff(times), rec_dt, rtol=1e-9, atol=1e-12) or abs(times[0]) > 1e-12:
        raise ValueError("the OpenSees Path series here needs a uniform record from t = 0")
    T = period(building)
    alpha, beta = rayleigh(building)
    values = acceleration.tolist()
    if inelastic(building):
        duration = float(times[-1]) + TAIL_PERIODS * T
        values.append(0.0)  # the last sample ramps to rest over one record step
    else:
        duration = float(times[-1])
    # The steps k dt up to the first at or past t_end; the window's first
    # step one before t_end - T.
    steps = int(np.ceil(duration / dt * (1 - 1e-12)))
    first = max(int(np.floor((duration - T) / dt * (1 + 1e-12))) - 1, 0)
    heights = building.get("heights") or []
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ops.wipe()
        ops.logFile(os.path.join(tmp, "opensees.log"), "-noEcho")
        tag = {"node": 0, "mat": 0, "ele": 0}

        def new(kind):
            tag[kind] += 1
            return tag[kind]

        if p_delta == "spring":
            storeys = _build_spring(ops, building, new, alpha, beta)
        else:
            storeys = _build_leaning(ops, building, new, alpha, beta)
        ops.timeSeries("Path", 1, "-dt", rec_dt, "-values", *values, "-factor", scale)
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        files = {k: os.path.join(tmp, f"{k}.out") for k in ("peak", "window")}
        ops.recorder("EnvelopeElement", "-file", files["peak"], "-precision", 14, "-ele", *storeys, "deformation")
        transient(ops, system, algorithm, tol, integrator,
                  constraints="Transformation" if p_delta == "leaning-column" else "Plain")
        status = ops.analyze(first, dt) if first > 0 else 0
        if status == 0:
            ops.recorder("Element", "-file", files["window"], "-time", "-precision", 14, "-ele", *storeys,
                         "deformation")
            status = ops.analyze(steps - first, dt)
        ops.wipe()  # flushes the recorders
        if status != 0:
            raise RuntimeError(f"OpenSees analyze failed (status {status}) at dt = {dt}")
        peak = np.abs(np.loadtxt(files["peak"], ndmin=2)[2])
        rows = np.loadtxt(files["window"], ndmin=2)  # time, the storeys' drifts
        seconds = time.perf_counter() - t0
    # The window: the record series starts at 0 after loadConst("-time", 0).
    residual = window_mean(rows, duration - T, duration)
    if not (np.all(np.isfinite(peak)) and np.all(np.isfinite(residual))):
        raise RuntimeError(f"OpenSees: non-finite results at dt = {dt}")
    out = {
        "dt": dt,
        "steps": steps,
        "seconds": seconds,
        "duration": duration,
        "period": T,
        "rayleigh": {"alpha": alpha, "beta": beta},
        "peak_drift": peak.tolist(),
        "residual_drift": residual.tolist(),
    }
    if heights:
        out["peak_drift_ratio"] = [d / h for d, h in zip(out["peak_drift"], heights)]
        out["residual_drift_ratio"] = [d / h for d, h in zip(out["residual_drift"], heights)]
    return out
