"""The two-frame pounding problem of ``vibroimpact pounding`` built in
OpenSees (openseespy), for the peer comparison of docs/earthquakes.md.

The model is the same equations as vibroimpact's ``PoundingPair::model``:

* every floor a node with one degree of freedom (``model basic -ndm 1
  -ndf 1``) carrying the floor mass; every storey a ``zeroLength`` element
  with an ``Elastic`` material ``E = k``, ``eta = beta k`` (the stiffness-
  proportional half of the frame's Rayleigh damping, on the storey), and
  every floor a ``zeroLength`` dashpot to the ground, ``Elastic`` with
  ``E = 0``, ``eta = alpha m`` (the mass-proportional half). This is the
  Rayleigh damping matrix of each frame exactly, each frame with its own
  coefficients (one global ``rayleigh`` command cannot give two frames
  their own);
* every pounding floor a ``zeroLength`` element from the left frame's floor
  to the right frame's, its deformation ``u_R - u_L`` (closing is
  ``-deformation``), with the contact as a uniaxial material:
  ``ElasticPPGap(k, -1e30, -gap)`` for vibroimpact's linear law
  (``kelvin-voigt`` with damping 0: a yield force that is never reached
  makes it elastic) or ``Hertzdamp(k, xiNorm, -gap, n)`` for
  ``lankarani-nikravesh`` with ``xiNorm = 3 (1 - e^2) / 4`` (OpenSees'
  Hertzdamp is ``F = k d^n (1 + xiNorm ddot / v0)`` with ``v0`` the
  approach rate at the first step in contact, the same law);
* the record as a ``Path`` time series (linear between samples, the same
  piecewise-linear input) in a ``UniformExcitation`` pattern (relative
  coordinates, load ``-M 1 a_g`` as in vibroimpact);
* Newmark's average acceleration (the unconditionally stable trapezoidal
  rule, OpenSees' usual choice for pounding), full Newton on each step with
  a displacement-increment test, a constant step ``dt``.

Peaks come from envelope recorders of the storey deformations (drifts) and
of the gap elements' force, the whole history run by one ``analyze`` call
(faster than stepping from Python: bench/opensees/README.md); a step that
fails to converge, or a non-finite peak, is an error.

Storeys that yield (a frame's ``storeys``, docs/earthquakes.md "Storeys
that yield"; docs/theory.md §11):

* ``bilinear`` is ``Steel01(Fy = k u_y, E0 = k, b)`` without isotropic
  hardening (a1 = a3 = 0, a2 = a4 = 1), ``bouc-wen`` is ``BoucWen(alpha =
  b, ko = k, n, gamma / u_y^n, beta / u_y^n, A0 = 1, delta_A, delta_nu,
  delta_eta)`` (its z is our z, its energy our e, so the degradation
  coefficients carry over); such a storey's Rayleigh damper ``beta k`` is
  a ``zeroLength`` dashpot of its own beside it (``Elastic`` with E = 0),
  the damping staying linear on the initial stiffness as in vibroimpact;
  ``imk`` is ``IMKBilin`` (Nov22) with the same values on both sides
  (:func:`imk_args`; an absent lambda is :data:`NO_DETERIORATION`);
* the record is followed by the same free-vibration tail as ours: 5 T1 of
  the longer-period frame (``TAIL_PERIODS``) at zero ground acceleration,
  the record's last sample ramped to zero over one record step (a 0
  appended to the ``Path``, which is 0 after its end);
* the residual drift of a storey is the mean of its drift at the analysis
  steps k dt in its frame's last fundamental period, [t_end - T1_frame,
  t_end], t_end = record end + tail (our definition, at our samples k
  sample). The run is split in two ``analyze`` calls: up to one step before
  the longer window, then the window with an ``Element`` recorder of the
  storey deformations added (``-time``), read back once. Stepping
  ``analyze(1, dt)`` from Python through the window reading
  ``eleResponse`` costs the same within noise (bench/opensees/inelastic-
  pair.toml, median of 9: 42.50 against 42.55 ms at dt_rec, 303.5 against
  304.4 ms at dt_rec/8); the recorder, a shade cheaper, is kept.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
import tempfile
import time
from typing import Any, Dict, List

import numpy as np


def import_opensees():
    """``openseespy.opensees``; on openseespylinux 3.7.x the bundled LAPACK
    needs its bundled BLAS loaded first (the wheel's RUNPATH reaches only
    its own direct dependencies)."""
    spec = importlib.util.find_spec("openseespylinux")
    if spec is not None and spec.origin:
        blas = os.path.join(os.path.dirname(spec.origin), "lib", "libblas.so.3")
        if os.path.exists(blas):
            ctypes.CDLL(blas, mode=ctypes.RTLD_GLOBAL)
    import openseespy.opensees as ops

    return ops


def one_building(row, what: str) -> Dict[str, Any]:
    """The one building of a row file (a path, TOML text, the parsed
    document or the building's own table); ``what`` names the kind asked
    for in the error ("isolated building", "building")."""
    import tomllib
    from pathlib import Path

    if isinstance(row, dict):
        doc = row if "building" in row else {"building": [row]}
    elif isinstance(row, Path) or (isinstance(row, str) and "\n" not in row and row.endswith(".toml")):
        doc = tomllib.loads(Path(row).read_text())
    else:
        doc = tomllib.loads(row)
    buildings = doc.get("building", [])
    if len(buildings) != 1:
        raise ValueError(f"a row of one {what} is needed, got {len(buildings)} buildings")
    return buildings[0]


def rayleigh(frame: Dict[str, Any]):
    """(alpha, beta) giving the frame's damping ratio in its first two modes
    (one mode: mass-proportional only), as vibroimpact's ``ShearFrame``."""
    w = _omegas(frame)
    z = frame["damping_ratio"]
    if len(w) == 1:
        return 2 * z * w[0], 0.0
    return 2 * z * w[0] * w[1] / (w[0] + w[1]), 2 * z / (w[0] + w[1])


TAIL_PERIODS = 5.0
"""The free-vibration tail after the record for a pair with yielding
storeys, in fundamental periods of the longer-period frame (vibroimpact's
``pounding::TAIL_PERIODS``)."""


def period(frame: Dict[str, Any]) -> float:
    """The frame's fundamental period (s) on its initial stiffnesses."""
    return 2 * np.pi / _omegas(frame)[0]


def _omegas(frame: Dict[str, Any]) -> np.ndarray:
    m = np.asarray(frame["masses"], dtype=float)
    k = np.asarray(frame["stiffnesses"], dtype=float)
    n = len(m)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    return np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(np.diag(m), K)).real))


def inelastic(frame: Dict[str, Any]) -> bool:
    """Whether a frame of a pair file has a storey that may yield."""
    return any(s.get("law", "elastic") != "elastic" for s in frame.get("storeys", []))


def storey_material(spec: Dict[str, Any], k: float):
    """The OpenSees uniaxial material (name, args) of a yielding storey of
    elastic stiffness ``k`` (a pair file's ``storeys`` entry)."""
    law, uy, b = spec["law"], spec.get("yield_drift"), spec.get("post_yield_ratio")
    if law == "bilinear":
        return "Steel01", (k * uy, k, b, 0.0, 1.0, 0.0, 1.0)
    if law == "bouc-wen":
        n = spec.get("exponent", 2.0)
        return "BoucWen", (
            b, k, n, spec.get("gamma", 0.5) / uy**n, spec.get("beta", 0.5) / uy**n, 1.0,
            spec.get("degradation_a", 0.0), spec.get("degradation_nu", 0.0), spec.get("degradation_eta", 0.0),
        )
    if law == "imk":
        return "IMKBilin", imk_args(spec, k)
    raise ValueError(f"storey law {law!r}: OpenSees has no equal material here (bilinear, bouc-wen or imk)")


NO_DETERIORATION = 1e30
"""IMKBilin's lambda (m) for a lambda vibroimpact does not have (infinite:
no deterioration of that kind): beta = (E_i/(lambda F_y - E))^c rounds to
0 against 1, for any c (lambda = 0 is off only with c = 1: with c != 1
OpenSees' pow of a negative base is NaN; the peer notes)."""


def imk_args(spec: Dict[str, Any], k: float):
    """OpenSees' ``IMKBilin`` (Nov22) arguments after the tag for an IMK
    storey of elastic stiffness ``k`` (vibroimpact's symmetric ``imk`` law,
    crates/vibroimpact/src/model/hysteresis/imk.rs): Ke = k; both sides
    dp = plastic_drift (the cap at u_y + dp), dpc = post_capping_drift (cap
    to zero force), du = ultimate_drift (total), Fy = k yield_drift,
    FmaxFy = cap_ratio, FresFy = residual_ratio; lambda_s, lambda_c,
    lambda_k (m, the reference energy lambda F_y; absent:
    :data:`NO_DETERIORATION`), c_s, c_c, c_k (default 1); D = 1 both sides
    (bench/opensees/imk_reference.py; the arguments' meanings in
    docs/theory.md §11, "IMK")."""
    fy = k * spec["yield_drift"]
    side = (spec["plastic_drift"], spec["post_capping_drift"], spec["ultimate_drift"], fy,
            spec["cap_ratio"], spec["residual_ratio"])
    lam = [spec.get(key) for key in ("lambda_s", "lambda_c", "lambda_k")]
    lam = [NO_DETERIORATION if v is None else v for v in lam]
    c = [spec.get(key, 1.0) for key in ("c_s", "c_c", "c_k")]
    return (k, *side, *side, *lam, *c, 1.0, 1.0)


def add_storey(ops, new, below: int, node: int, k: float, law: Dict[str, Any], beta: float) -> int:
    """A storey from node ``below`` to ``node``: ``zeroLength`` with an
    ``Elastic`` material (E = k, eta = beta k) for an elastic law, else its
    law's material (:func:`storey_material`) with a ``beta k`` dashpot
    beside it (the damping stays linear on the initial stiffness). ``new``
    hands out tags by kind. Returns the storey element's tag."""
    mat, ele = new("mat"), new("ele")
    if law.get("law", "elastic") == "elastic":
        ops.uniaxialMaterial("Elastic", mat, k, beta * k)
        ops.element("zeroLength", ele, below, node, "-mat", mat, "-dir", 1)
        return ele
    name, args = storey_material(law, k)
    ops.uniaxialMaterial(name, mat, *args)
    ops.element("zeroLength", ele, below, node, "-mat", mat, "-dir", 1)
    if beta > 0.0:
        damper = new("mat")
        ops.uniaxialMaterial("Elastic", damper, 0.0, beta * k)
        ops.element("zeroLength", new("ele"), below, node, "-mat", damper, "-dir", 1)
    return ele


def transient(ops, system: str, algorithm: str, tol: float, integrator: str, constraints: str = "Plain") -> None:
    """The transient analysis of a model: the equation ``system``; Newmark's
    average acceleration with a Newton ``algorithm`` (its flags after a
    space: ``"ModifiedNewton -factoronce"``) and a displacement test at
    ``tol``, or an explicit rule (``CentralDifference``,
    ``ExplicitDifference``) with the linear algorithm (``"Linear
    -factorOnce"`` where given so, else ``Linear``); ``constraints`` the
    constraint handler (``Transformation`` for a model with ``equalDOF``)."""
    ops.constraints(constraints)
    ops.numberer("Plain")
    ops.system(system)
    if integrator in ("CentralDifference", "ExplicitDifference"):
        ops.algorithm(*(algorithm.split() if algorithm.startswith("Linear") else ["Linear"]))
        ops.integrator(integrator)
    else:
        ops.test("NormDispIncr", tol, 50)
        ops.algorithm(*algorithm.split())
        ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def contact_material(law: Dict[str, Any], gap: float):
    """The OpenSees uniaxial material (name, args) equal to a vibroimpact
    law; only the two laws OpenSees has exactly."""
    name = law["law"]
    if name == "kelvin-voigt" and law.get("damping", 0.0) == 0.0:
        return "ElasticPPGap", (law["stiffness"], -1e30, -gap)
    if name == "lankarani-nikravesh":
        e = law["restitution"]
        return "Hertzdamp", (law["stiffness"], 0.75 * (1 - e * e), -gap, law.get("exponent", 1.5))
    raise ValueError(f"law {name!r}: OpenSees has no equal material (use kelvin-voigt with damping 0 or lankarani-nikravesh)")


def run(
    pair: Dict[str, Any],
    times: np.ndarray,
    acceleration: np.ndarray,
    scale: float,
    dt: float,
    system: str = "BandGeneral",
    algorithm: str = "Newton",
    tol: float = 1e-10,
    integrator: str = "Newmark",
) -> Dict[str, Any]:
    """One OpenSees run of the pair (a parsed pair TOML) under the record,
    constant step ``dt``, with the given equation solver, Newton variant,
    displacement-increment tolerance (m) and integrator (``Newmark``: the
    average acceleration rule; ``CentralDifference`` or
    ``ExplicitDifference``: explicit, with ``algorithm="Linear"`` or
    ``"Linear -factorOnce"``; :func:`transient`); returns the peaks and the wall time of
    building and running the model. A pair with yielding storeys runs
    through the free-vibration tail and returns ``residual_drift`` too."""
    ops = import_opensees()
    rec_dt = float(times[1] - times[0])
    if not np.allclose(np.diff(times), rec_dt, rtol=1e-9, atol=1e-12) or abs(times[0]) > 1e-12:
        raise ValueError("the OpenSees Path series here needs a uniform record from t = 0")
    frames = (pair["left"], pair["right"])
    yielding = any(inelastic(f) for f in frames)
    values = acceleration.tolist()
    if yielding:
        periods = [period(f) for f in frames]
        duration = float(times[-1]) + TAIL_PERIODS * max(periods)
        values.append(0.0)  # the last sample ramps to rest over one record step
        steps = int(np.floor(duration / dt * (1 + 1e-12)))  # samples k dt <= t_end
        # The window's first step: one before the longer frame's window.
        first = max(int(np.ceil((duration - max(periods)) / dt * (1 - 1e-12))) - 1, 0)
    else:
        duration = float(times[-1])
        steps = int(round(duration / dt))
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ops.wipe()
        ops.logFile(os.path.join(tmp, "opensees.log"), "-noEcho")
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        tag = {"node": 0, "mat": 0, "ele": 0}

        def new(kind):
            tag[kind] += 1
            return tag[kind]

        floors: List[List[int]] = []
        storeys: List[int] = []
        for frame in frames:
            alpha, beta = rayleigh(frame)
            laws = frame.get("storeys") or [{"law": "elastic"}] * len(frame["masses"])
            ground = new("node")
            ops.node(ground, 0.0)
            ops.fix(ground, 1)
            nodes = []
            below = ground
            for m, k, law in zip(frame["masses"], frame["stiffnesses"], laws):
                nd = new("node")
                ops.node(nd, 0.0, "-mass", m)
                storeys.append(add_storey(ops, new, below, nd, k, law, beta))
                dash = new("mat")
                ops.uniaxialMaterial("Elastic", dash, 0.0, alpha * m)
                ops.element("zeroLength", new("ele"), ground, nd, "-mat", dash, "-dir", 1)
                nodes.append(nd)
                below = nd
            floors.append(nodes)
        gaps = []
        name, args = contact_material(pair["law"], pair["gap"])
        for f in pair["floors"]:
            mat = new("mat")
            ops.uniaxialMaterial(name, mat, *args)
            ele = new("ele")
            ops.element("zeroLength", ele, floors[0][f - 1], floors[1][f - 1], "-mat", mat, "-dir", 1)
            gaps.append(ele)
        ops.timeSeries("Path", 1, "-dt", rec_dt, "-values", *values, "-factor", scale)
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        drift_file = os.path.join(tmp, "drift.out")
        force_file = os.path.join(tmp, "force.out")
        window_file = os.path.join(tmp, "window.out")
        ops.recorder("EnvelopeElement", "-file", drift_file, "-ele", *storeys, "deformation")
        ops.recorder("EnvelopeElement", "-file", force_file, "-ele", *gaps, "force")
        transient(ops, system, algorithm, tol, integrator)
        if not yielding:
            status = ops.analyze(steps, dt)
        else:
            status = ops.analyze(first, dt)
            if status == 0:
                ops.recorder("Element", "-file", window_file, "-time", "-ele", *storeys, "deformation")
                status = ops.analyze(steps - first, dt)
        ops.wipe()  # flushes the recorders
        if status != 0:
            raise RuntimeError(f"OpenSees analyze failed (status {status}) at dt = {dt}")
        drift = np.loadtxt(drift_file, ndmin=2)[2]
        force = np.loadtxt(force_file, ndmin=2)[2]
        if yielding:
            rows = np.loadtxt(window_file, ndmin=2)  # time, then the storeys' drifts
        seconds = time.perf_counter() - t0
    if not (np.all(np.isfinite(drift)) and np.all(np.isfinite(force))):
        raise RuntimeError(f"OpenSees: non-finite peaks at dt = {dt}")
    nl = len(pair["left"]["masses"])
    out = {
        "dt": dt,
        "steps": steps,
        "seconds": seconds,
        "peak_drift": [drift[:nl].tolist(), drift[nl:].tolist()],
        "peak_impact_force": float(np.max(np.abs(force))),
    }
    if yielding:
        # The mean drift at the steps in each frame's last period.
        residual = []
        for side, cols in enumerate((slice(1, nl + 1), slice(nl + 1, None))):
            late = rows[:, 0] >= duration - periods[side] - 1e-9 * dt
            residual.append(rows[late, cols].mean(axis=0).tolist())
        if not np.all(np.isfinite(np.concatenate(residual))):
            raise RuntimeError(f"OpenSees: non-finite residual drifts at dt = {dt}")
        out.update(residual_drift=residual, duration=duration)
    return out
