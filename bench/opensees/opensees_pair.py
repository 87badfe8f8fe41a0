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


def rayleigh(frame: Dict[str, Any]):
    """(alpha, beta) giving the frame's damping ratio in its first two modes
    (one mode: mass-proportional only), as vibroimpact's ``ShearFrame``."""
    m = np.asarray(frame["masses"], dtype=float)
    k = np.asarray(frame["stiffnesses"], dtype=float)
    n = len(m)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    w = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(np.diag(m), K)).real))
    z = frame["damping_ratio"]
    if n == 1:
        return 2 * z * w[0], 0.0
    return 2 * z * w[0] * w[1] / (w[0] + w[1]), 2 * z / (w[0] + w[1])


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
    average acceleration rule; ``CentralDifference``: explicit, with
    ``algorithm="Linear"``); returns the peaks and the wall time of
    building and running the model."""
    ops = import_opensees()
    rec_dt = float(times[1] - times[0])
    if not np.allclose(np.diff(times), rec_dt, rtol=1e-9, atol=1e-12) or abs(times[0]) > 1e-12:
        raise ValueError("the OpenSees Path series here needs a uniform record from t = 0")
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
        for frame in (pair["left"], pair["right"]):
            alpha, beta = rayleigh(frame)
            ground = new("node")
            ops.node(ground, 0.0)
            ops.fix(ground, 1)
            nodes = []
            below = ground
            for m, k in zip(frame["masses"], frame["stiffnesses"]):
                nd = new("node")
                ops.node(nd, 0.0, "-mass", m)
                mat = new("mat")
                ops.uniaxialMaterial("Elastic", mat, k, beta * k)
                ele = new("ele")
                ops.element("zeroLength", ele, below, nd, "-mat", mat, "-dir", 1)
                storeys.append(ele)
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
        ops.timeSeries("Path", 1, "-dt", rec_dt, "-values", *acceleration.tolist(), "-factor", scale)
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        drift_file = os.path.join(tmp, "drift.out")
        force_file = os.path.join(tmp, "force.out")
        ops.recorder("EnvelopeElement", "-file", drift_file, "-ele", *storeys, "deformation")
        ops.recorder("EnvelopeElement", "-file", force_file, "-ele", *gaps, "force")
        ops.constraints("Plain")
        ops.numberer("Plain")
        ops.system(system)
        if integrator == "CentralDifference":
            ops.algorithm("Linear")
            ops.integrator("CentralDifference")
        else:
            ops.test("NormDispIncr", tol, 50)
            ops.algorithm(algorithm)
            ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        status = ops.analyze(steps, dt)
        ops.wipe()  # flushes the envelope recorders
        seconds = time.perf_counter() - t0
        if status != 0:
            raise RuntimeError(f"OpenSees analyze failed (status {status}) at dt = {dt}")
        drift = np.loadtxt(drift_file, ndmin=2)[2]
        force = np.loadtxt(force_file, ndmin=2)[2]
    if not (np.all(np.isfinite(drift)) and np.all(np.isfinite(force))):
        raise RuntimeError(f"OpenSees: non-finite peaks at dt = {dt}")
    nl = len(pair["left"]["masses"])
    return {
        "dt": dt,
        "steps": steps,
        "seconds": seconds,
        "peak_drift": [drift[:nl].tolist(), drift[nl:].tolist()],
        "peak_impact_force": float(np.max(np.abs(force))),
    }
