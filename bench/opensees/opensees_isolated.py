"""An isolated building in its moat (a row file of one isolated building,
``vibroimpact pounding``; docs/earthquakes.md, "Isolated buildings") built
in OpenSees (openseespy), for the peer comparison of issue 27.

The model is the same equations as vibroimpact's ``Building::place``
(crates/vibroimpact/src/pounding_building.rs), built the way
bench/opensees/opensees_pair.py builds the pounding pair:

* one-degree-of-freedom nodes (``model basic -ndm 1 -ndf 1``): the ground
  (fixed), the base slab (``isolation.mass``), the floors (``masses``);
* the bearings a ``zeroLength`` element from the ground to the slab:
  ``bilinear`` is ``Steel01(Fy = k u_y, E0 = k, b)`` without isotropic
  hardening (a1 = a3 = 0, a2 = a4 = 1), ``bouc-wen`` is ``BoucWen``
  (opensees_pair.storey_material; first order in the step there); the
  layer's viscous damper (``isolation.damping``, N s/m) a ``zeroLength``
  dashpot beside them (``Elastic`` with E = 0);
* storey i a ``zeroLength`` element from the floor below (the slab for
  storey 1) to floor i: ``Elastic(k_i, beta k_i)`` when elastic, else its
  law (``Steel01`` for ``bilinear``) with a ``zeroLength`` dashpot
  ``beta k_i`` beside it (the Rayleigh damper stays linear on the initial
  stiffness, as in vibroimpact);
* the superstructure's Rayleigh damping on its FIXED-BASE modes
  (opensees_pair.rayleigh of the frame: alpha, beta with zeta in modes 1
  and 2; one storey alpha = 2 zeta omega, beta = 0): ``beta k_i`` beside
  each storey as above, and a dashpot ``alpha m_i`` from each floor TO THE
  SLAB (not to the ground: the superstructure's damping leaves the
  isolation mode alone);
* the moat wall a contact on each side of the slab at the clear distance
  ``moat.gap``: a rigid wall is a fixed node, a flexible one (``wall =
  {mass, stiffness, damping}``) a node of that mass on an ``Elastic
  (stiffness, damping)`` element to the ground. The contact is a
  ``zeroLength`` element with the contact material of opensees_pair.
  contact_material (``ElasticPPGap(k, -1e30, -gap)`` = ``kelvin-voigt``
  with damping 0; ``Hertzdamp(k, 3 (1 - e^2)/4, -gap, n)`` =
  ``lankarani-nikravesh``), which closes when the element's deformation
  u_j - u_i falls below -gap. The left wall's element runs from the wall
  to the slab (deformation u_slab - u_wall, closing as the slab goes left
  past -gap), the right wall's from the slab to the wall (deformation
  u_wall - u_slab, closing as the slab goes right past +gap):
  ``test_a_slab_pushed_right_hits_only_the_right_wall`` checks it;
* the record as a ``Path`` series (linear between samples) in a
  ``UniformExcitation`` pattern, then the free-vibration tail of
  vibroimpact: 5 T (``TAIL_PERIODS``) with T the isolated building's period
  (:func:`period`: the slab and floors on the bearings' post-yield
  stiffness, vibroimpact's ``Building::period``), the record's last sample
  ramped to zero over one record step (a 0 appended to the ``Path``);
* Newmark's average acceleration with Newton iterations (or an explicit
  rule, ``CentralDifference`` or ``ExplicitDifference``), a constant step ``dt``, one ``analyze`` call up
  to one step before the residual window and one through it.

Outputs, as vibroimpact's ``runs[0].pounding`` of the building: the peak
storey drifts (storey 1 = floor 1 - slab) and the slab's peak displacement
from an ``EnvelopeElement`` recorder of the storey and bearing elements'
deformations; the peak moat force from one of the gap elements' forces;
the residual drifts (and the slab's residual displacement) as the mean at
the steps k dt in the building's last period [t_end - T, t_end]
(vibroimpact's definition at its samples), from an ``Element`` recorder
(``-time``) added for the window. ``impacts=True`` adds an ``Element``
recorder of the gap elements' deformations over the whole run and counts
the contacts (a step in contact after one out of it): the moat impacts.
"""

from __future__ import annotations

import os
import tempfile
import time
from typing import Any, Dict, Union

import numpy as np

from opensees_pair import (
    one_building,
    TAIL_PERIODS,
    _omegas,
    add_storey,
    contact_material,
    import_opensees,
    rayleigh,
    storey_material,
    transient,
)


def load(row: Union[str, os.PathLike, Dict[str, Any]]) -> Dict[str, Any]:
    """The one isolated building of a row file (a path, TOML text, the
    parsed document or the building's own table), checked to be what this
    module builds."""
    b = one_building(row, "isolated building")
    iso = b.get("isolation")
    if iso is None:
        raise ValueError(f"building {b.get('name')!r} is not isolated")
    if iso["bearing"]["law"] not in ("bilinear", "bouc-wen"):
        raise ValueError(f"bearing law {iso['bearing']['law']!r}: OpenSees has no equal material here")
    return b


def period(building: Dict[str, Any]) -> float:
    """The isolated building's period (s): the slab and floors on the
    bearings at their post-yield stiffness (elastic if there is none), the
    storeys elastic (vibroimpact's ``Building::period``)."""
    iso = building["isolation"]
    bearing = iso["bearing"]
    b = bearing.get("post_yield_ratio", 0.0)
    kb = bearing["stiffness"] * (b if b > 0 else 1.0)
    whole = {
        "masses": [iso["mass"], *building["masses"]],
        "stiffnesses": [kb, *building["stiffnesses"]],
    }
    return 2 * np.pi / _omegas(whole)[0]


def yield_drifts(building: Dict[str, Any]):
    """The storeys' yield drifts (None for an elastic storey)."""
    laws = building.get("storeys") or [{"law": "elastic"}] * len(building["masses"])
    return [s.get("yield_drift") if s.get("law", "elastic") != "elastic" else None for s in laws]


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
    impacts: bool = False,
) -> Dict[str, Any]:
    """One OpenSees run of the isolated building of ``row`` under the record
    (``times``, ``acceleration`` in m/s^2, uniform from t = 0) times
    ``scale``, constant step ``dt``, through the free-vibration tail; the
    equation solver, Newton variant, displacement-increment tolerance (m)
    and integrator (``Newmark``: average acceleration; ``CentralDifference``
    or ``ExplicitDifference``: explicit, ``algorithm Linear``, with
    ``-factorOnce`` where given; ``opensees_pair.transient``) as given. Returns the peak drifts, the
    slab's peak displacement, the peak moat force (and per wall, ``left``
    and ``right``), the residual drifts and slab displacement, the wall time
    of building and running the model and, with ``impacts``, the moat
    impacts (and per wall)."""
    building = load(row)
    ops = import_opensees()
    rec_dt = float(times[1] - times[0])
    if not np.allclose(np.diff(times), rec_dt, rtol=1e-9, atol=1e-12) or abs(times[0]) > 1e-12:
        raise ValueError("the OpenSees Path series here needs a uniform record from t = 0")
    iso = building["isolation"]
    moat = iso.get("moat")
    T = period(building)
    duration = float(times[-1]) + TAIL_PERIODS * T
    values = acceleration.tolist() + [0.0]  # the last sample ramps to rest over one record step
    steps = int(np.floor(duration / dt * (1 + 1e-12)))  # the steps k dt <= t_end
    first = max(int(np.ceil((duration - T) / dt * (1 - 1e-12))) - 1, 0)  # one step before the window
    alpha, beta = rayleigh(building)
    laws = building.get("storeys") or [{"law": "elastic"}] * len(building["masses"])
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ops.wipe()
        ops.logFile(os.path.join(tmp, "opensees.log"), "-noEcho")
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        tag = {"node": 0, "mat": 0, "ele": 0}

        def new(kind):
            tag[kind] += 1
            return tag[kind]

        def dashpot(i, j, eta):
            mat = new("mat")
            ops.uniaxialMaterial("Elastic", mat, 0.0, eta)
            ops.element("zeroLength", new("ele"), i, j, "-mat", mat, "-dir", 1)

        ground = new("node")
        ops.node(ground, 0.0)
        ops.fix(ground, 1)
        slab = new("node")
        ops.node(slab, 0.0, "-mass", iso["mass"])
        bearing = iso["bearing"]
        name, args = storey_material(bearing, bearing["stiffness"])
        mat = new("mat")
        ops.uniaxialMaterial(name, mat, *args)
        bearing_ele = new("ele")
        ops.element("zeroLength", bearing_ele, ground, slab, "-mat", mat, "-dir", 1)
        if iso.get("damping", 0.0) > 0.0:
            dashpot(ground, slab, iso["damping"])
        storeys = []
        below = slab
        for m, k, law in zip(building["masses"], building["stiffnesses"], laws):
            nd = new("node")
            ops.node(nd, 0.0, "-mass", m)
            storeys.append(add_storey(ops, new, below, nd, k, law, beta))
            if alpha > 0.0:
                dashpot(slab, nd, alpha * m)  # to the slab, not the ground
            below = nd
        gaps = []
        if moat is not None:
            wall = moat.get("wall")
            name, args = contact_material(moat["law"], moat["gap"])
            for side in ("left", "right"):
                w = new("node")
                if wall is None:
                    ops.node(w, 0.0)
                    ops.fix(w, 1)
                else:
                    ops.node(w, 0.0, "-mass", wall["mass"])
                    wm = new("mat")
                    ops.uniaxialMaterial("Elastic", wm, wall["stiffness"], wall.get("damping", 0.0))
                    ops.element("zeroLength", new("ele"), ground, w, "-mat", wm, "-dir", 1)
                mat = new("mat")
                ops.uniaxialMaterial(name, mat, *args)
                ele = new("ele")
                i, j = (w, slab) if side == "left" else (slab, w)
                ops.element("zeroLength", ele, i, j, "-mat", mat, "-dir", 1)
                gaps.append(ele)
        ops.timeSeries("Path", 1, "-dt", rec_dt, "-values", *values, "-factor", scale)
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        files = {k: os.path.join(tmp, f"{k}.out") for k in ("peak", "force", "window", "gaps")}
        watched = [*storeys, bearing_ele]
        ops.recorder("EnvelopeElement", "-file", files["peak"], "-precision", 12, "-ele", *watched, "deformation")
        if gaps:
            ops.recorder("EnvelopeElement", "-file", files["force"], "-precision", 12, "-ele", *gaps, "force")
            if impacts:
                ops.recorder("Element", "-file", files["gaps"], "-precision", 12, "-ele", *gaps, "deformation")
        transient(ops, system, algorithm, tol, integrator)
        status = ops.analyze(first, dt)
        if status == 0:
            ops.recorder("Element", "-file", files["window"], "-time", "-precision", 12, "-ele", *watched, "deformation")
            status = ops.analyze(steps - first, dt)
        ops.wipe()  # flushes the recorders
        if status != 0:
            raise RuntimeError(f"OpenSees analyze failed (status {status}) at dt = {dt}")
        peak = np.loadtxt(files["peak"], ndmin=2)[2]
        force = np.loadtxt(files["force"], ndmin=2)[2] if gaps else np.zeros(4)
        rows = np.loadtxt(files["window"], ndmin=2)  # time, the storeys' drifts, the slab
        history = np.loadtxt(files["gaps"], ndmin=2) if gaps and impacts else None
        seconds = time.perf_counter() - t0
    # A zeroLength element's force: (node i, node j); the wall's force is
    # the largest magnitude of either.
    walls = np.abs(force).reshape(-1, 2).max(axis=1)
    late = rows[:, 0] >= duration - T - 1e-9 * dt
    residual = rows[late, 1:].mean(axis=0)
    n = len(storeys)
    out = {
        "dt": dt,
        "steps": steps,
        "seconds": seconds,
        "duration": duration,
        "period": T,
        "peak_drift": peak[:n].tolist(),
        "peak_displacement": float(abs(peak[n])),
        "moat_peak_force": float(walls.max()),
        "moat_peak_force_sides": {"left": float(walls[0]), "right": float(walls[1])} if gaps else None,
        "residual_drift": residual[:n].tolist(),
        "residual_displacement": float(residual[n]),
    }
    if history is not None:
        gap = moat["gap"]
        closed = history < -gap  # per wall, per step: in contact
        onsets = closed[1:] & ~closed[:-1]
        out["moat_impacts"] = int(onsets.sum() + closed[0].sum())
        out["moat_impacts_sides"] = {"left": int(onsets[:, 0].sum()), "right": int(onsets[:, 1].sum())}
    values_ = [*out["peak_drift"], out["peak_displacement"], out["moat_peak_force"], *out["residual_drift"]]
    if not np.all(np.isfinite(values_)):
        raise RuntimeError(f"OpenSees: non-finite results at dt = {dt}")
    return out
