"""Earthquakes: :func:`read_record` (a ground-motion record file),
:func:`response_spectrum` (``vibroimpact spectrum``), :func:`pounding`
(``vibroimpact pounding``, two shear frames under recorded ground motions)
and :func:`pounding_history`, with the checks of pair files, records and
pounding settings that :mod:`vibroimpact.distributed` shares. Records that
ship with other Python packages are in :mod:`vibroimpact.records`.
"""

from __future__ import annotations

import math
import os
import stat
from collections.abc import Iterable, Mapping
from typing import Any, Optional, Union

import numpy as np

from . import _core
from ._checks import ArrayLike, _floats, _method
from ._results import Result

# The numbers a setting takes: Python's and numpy's.
_NUMBER = (int, float, np.integer, np.floating)


def read_record(path: Union[str, "os.PathLike[str]"], *, units: Optional[str] = None) -> Result:
    """A ground-motion record: a PEER NGA ``.AT2`` file, two columns (time s,
    acceleration; header lines skipped) or CSV. ``units`` (``"g"``,
    ``"m/s2"``, ``"gal"``) is needed when the header does not state them.

    Returns ``source``, ``header`` (the header lines), ``units`` (of the
    file), ``dt`` (None if not uniform), ``times`` (s), ``acceleration``
    (m/s², converted), ``pga`` (m/s²)."""
    try:
        path = os.fspath(path)
    except TypeError:
        raise TypeError(f"path: expected a file name, got {type(path).__name__}") from None
    if not isinstance(path, str):
        raise TypeError("path: expected a file name")
    if units is not None and not isinstance(units, str):
        raise TypeError("units: expected 'g', 'm/s2' or 'gal'")
    try:
        st = os.stat(path)
    except OSError as e:
        raise OSError(f"{path}: cannot read: {e.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(
            f"path: {path} is not a regular file (a directory, FIFO or device "
            "cannot be read as a record)"
        )
    size = st.st_size
    if size > 1 << 30:
        raise ValueError(f"path: {path} has {size} bytes, more than the input limit of 1 GiB")
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    return Result(_core.parse_record(text, path, units))


def response_spectrum(
    record: Any,
    periods: Optional[ArrayLike] = None,
    *,
    damping: float = 0.05,
    scale: float = 1.0,
    acceleration: Optional[ArrayLike] = None,
    units: Optional[str] = None,
) -> Result:
    """Elastic response spectra of a record, exact for its piecewise-linear
    ground acceleration (Nigam–Jennings; ``vibroimpact spectrum``).
    ``record``: a result of :func:`read_record`, a file name (read with
    ``units`` when its header does not state them), or the sample times (s)
    with ``acceleration`` (m/s²). ``periods`` (s): default 100
    log-spaced from 0.05 to 5. Peaks over the record's time steps.

    Returns the ``vibroimpact spectrum`` document: ``record`` (source,
    header, units, dt, pga, scale, …), ``damping``, ``peaks``, ``units``, and
    its rows as the arrays ``period``, ``pseudo_acceleration`` (m/s²),
    ``pseudo_velocity`` (m/s), ``displacement`` (m)."""
    if isinstance(record, (str, os.PathLike)):
        record = read_record(record, units=units)
    meta = {}
    if acceleration is None:
        try:
            times, acc = record["times"], record["acceleration"]
        except (KeyError, TypeError, IndexError):
            raise TypeError(
                "record: expected a read_record result, a file name, or times with acceleration="
            ) from None
        if isinstance(record, Mapping) and "source" in record:
            meta = {
                "source": str(record["source"]),
                "header": [str(h) for h in record.get("header", [])],
                "units": str(record.get("units", "m/s2")),
            }
    else:
        times, acc = record, acceleration
    if periods is None:
        periods = np.geomspace(0.05, 5.0, 100)
    for name, v in (("damping", damping), ("scale", scale)):
        if isinstance(v, bool) or not isinstance(v, _NUMBER) or not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    return Result(
        _core.response_spectrum(
            _floats(times, "times", allow_scalar=False),
            _floats(acc, "acceleration", allow_scalar=False),
            _floats(periods, "periods"),
            float(damping),
            float(scale),
            **meta,
        )
    )


def _pair_text(pair: Any):
    """(source, TOML text) of a pounding pair given as a file name or text
    (text holds a line break or an `=`; anything else is a file name)."""
    if isinstance(pair, str) and ("\n" in pair or "=" in pair):
        return "<pair>", pair
    if isinstance(pair, (str, os.PathLike)):
        source = os.fspath(pair)
        try:
            with open(source, encoding="utf-8") as f:
                return source, f.read()
        except OSError as e:
            raise OSError(f"pair: {source}: cannot read: {e.strerror}") from None
    raise TypeError("pair: expected a pair file name or its TOML text")


def _record_arrays(record: Any):
    if isinstance(record, (str, os.PathLike)):
        record = read_record(record)
    try:
        return record["times"], record["acceleration"]
    except (KeyError, TypeError, IndexError):
        raise TypeError("record: expected a read_record result or a file name") from None


def _record_inputs(records: Any, units: Optional[str]) -> list:
    """The binding's records: (source, header, units, times, acceleration)
    of one record or a list of them (file names or :func:`read_record`
    results)."""
    one = isinstance(records, (str, os.PathLike, Mapping))
    if not one and not isinstance(records, Iterable):
        raise TypeError(
            "records: expected a file name, a read_record result or a list of them, "
            f"got {type(records).__name__}"
        )
    out = []
    for k, r in enumerate([records] if one else list(records)):
        if isinstance(r, (str, os.PathLike)):
            r = read_record(r, units=units)
        try:
            times, acc = r["times"], r["acceleration"]
        except (KeyError, TypeError, IndexError):
            raise TypeError(
                f"records[{k}]: expected a read_record result or a file name"
            ) from None
        out.append(
            (
                str(r.get("source", f"record {k}")),
                [str(h) for h in r.get("header", [])],
                str(r.get("units", "m/s2")),
                _floats(times, "times", allow_scalar=False),
                _floats(acc, "acceleration", allow_scalar=False),
            )
        )
    if not out:
        raise ValueError("records: give at least one record")
    return out


def _value_range(values: Any, name: str) -> Optional[np.ndarray]:
    """`FROM:TO:N` (the CLI's form) or a list of values."""
    if values is None:
        return None
    if isinstance(values, str):
        return _core.value_range(name, values)
    return _floats(values, name, allow_scalar=False)


def _pounding_settings(scale: Any, sample: Any, rtol: Any, method: Any, integrator: Any) -> None:
    """Checks the settings of a pounding run (the binding checks their
    ranges)."""
    for name, v in (("scale", scale), ("sample", sample), ("rtol", rtol)):
        if isinstance(v, bool) or not isinstance(v, _NUMBER) or not math.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    _method(method, ("dop853", "dopri5", "rodas", "auto"))
    _method(integrator, ("auto", "global", "local"), "integrator")


def _pounding_args(
    pair: Any, record: Any, scale: Any, sample: Any, rtol: Any, method: Any, integrator: Any
) -> tuple:
    """The binding's leading arguments of a pounding run, checked."""
    source, text = _pair_text(pair)
    _pounding_settings(scale, sample, rtol, method, integrator)
    times, acc = _record_arrays(record)
    return (
        text,
        source,
        _floats(times, "times", allow_scalar=False),
        _floats(acc, "acceleration", allow_scalar=False),
        float(scale),
        float(sample),
        float(rtol),
        method,
        integrator,
    )


def pounding(
    pair: Union[str, "os.PathLike[str]"],
    records: Any,
    *,
    units: Optional[str] = None,
    scale: float = 1.0,
    sample: float = 0.0025,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
    free: bool = True,
    gaps: Any = None,
    ratios: Any = None,
    moat_gaps: Any = None,
) -> Result:
    """Pounding of a row of buildings under recorded ground motions
    (``vibroimpact pounding``): ``pair`` is a row file (``[[building]]``
    entries) or a pair file (``[left]``, ``[right]``), TOML
    (docs/earthquakes.md), or its text; ``records`` one record or a list,
    each a :func:`read_record` result or a file name (read with ``units``
    when its header does not state them), scaled by ``scale``. ``sample``
    (s): the sampling of the hysteresis loops; peaks and residual drifts are
    exact on the dense output whatever it is. ``method``:
    "dop853", or "dopri5", the faster at ``rtol`` 1e-3 to 1e-5 (the
    record's samples limit the step; peaks within 1 % there,
    docs/earthquakes.md). ``integrator="local"``: each frame moves exactly
    between poundings and away from yield, per record sample ("auto": the
    global integrator, the faster under a record). ``free=False`` runs the row with
    its contacts only (half the work; no ``free``, ``amplification`` or
    ``joints``). ``gaps`` and ``ratios`` (``"FROM:TO:N"`` or lists of
    values): the pounding spectrum of a pair over gaps (m) × period ratios
    T_left/T_right instead of the runs; ``moat_gaps`` (the same forms): the
    moat-gap study of isolated buildings instead (every moat at each gap,
    and once without contacts).

    Returns the CLI's document: ``row`` (``buildings``: ``name``,
    ``period``, ``floors``, ``isolated``, ``rayleigh``; ``joints``:
    ``between``, ``gap``, ``floors``) and ``runs``, one per record, each with ``record``,
    ``pounding`` and ``free`` (per building name: ``peak_drift``,
    ``residual_drift``, ``ductility``, ``hysteretic_energy``,
    ``peak_floor_acceleration``, ``peak_displacement``; ``isolators`` per
    isolated building; ``peak_impact_force``, ``impacts``, ``closing`` per
    joint), ``amplification`` and ``joints`` (``required_gap`` and
    ``code_gaps``: ``absolute_sum``, ``srss``, ``double_difference``,
    ``correlation``); with ``gaps`` and ``ratios``, ``row``, ``records``
    and ``cells`` (per gap and ratio the median, 16 and 84 % quantiles over
    the records); with ``moat_gaps``, ``row``, ``records`` and
    ``moat_cells`` (per gap, null first for no contacts: ``peak_drift``,
    ``peak_floor_acceleration``, ``isolator_displacement``,
    ``moat_peak_force``, ``moat_impacts`` as median, 16/84 % and values;
    ``beyond_capacity``, the records that passed an isolator's capacity)."""
    source, text = _pair_text(pair)
    _pounding_settings(scale, sample, rtol, method, integrator)
    if not isinstance(free, bool):
        raise TypeError(f"free: expected True or False, got {free!r}")
    if (gaps is None) != (ratios is None):
        raise ValueError("gaps, ratios: give both (the pounding spectrum) or neither")
    if gaps is not None and moat_gaps is not None:
        raise ValueError("moat_gaps: give it or gaps and ratios, not both")
    return Result(
        _core.pounding(
            text,
            source,
            _record_inputs(records, units),
            float(scale),
            float(sample),
            float(rtol),
            method,
            integrator,
            free,
            _value_range(gaps, "gaps"),
            _value_range(ratios, "ratios"),
            _value_range(moat_gaps, "moat_gaps"),
        )
    )


def pushover(
    pair: Any,
    building: Any = None,
    *,
    drift_ratio_limit: float = 0.10,
    points: int = 400,
    code_period: Any = None,
) -> Result:
    """The static pushover of one building (``vibroimpact pushover``,
    docs/earthquakes.md): ``pair`` a row or pair file (name or TOML text),
    ``building`` its name (default: the first; it needs ``heights``). The
    loads follow the first mode times the floor masses and grow until the
    critical storey collapses or reaches ``drift_ratio_limit`` (``points``
    along its drift); ``code_period`` is FEMA P695's T = C_u T_a for
    δ_y,eff (default: T1 with P-Δ).

    Returns the CLI's document: ``roof_displacement``, ``roof_drift_ratio``,
    ``base_shear``, ``drifts`` per point, ``pattern``, ``critical_storey``,
    ``collapsed``, ``max_base_shear``, ``weight``, ``period``, ``c0``,
    ``yield_displacement``, ``ultimate_displacement``, ``strength_loss``,
    ``ductility`` (μ_T) and ``units``."""
    from . import _core
    from ._checks import _real

    source, text = _pair_text(pair)
    if building is not None and not isinstance(building, str):
        raise TypeError(f"building: expected a building's name, got {building!r}")
    limit = _real(drift_ratio_limit, "drift_ratio_limit", positive=True)
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 2:
        raise ValueError(f"points: expected an integer >= 2, got {points!r}")
    period = _real(code_period, "code_period", positive=True, optional=True)
    return Result(_core.pushover(text, source, building, limit, int(points), period))


def pounding_history(
    pair: Union[str, "os.PathLike[str]"],
    record: Any,
    *,
    scale: float = 1.0,
    sample: float = 0.01,
    rtol: float = 1e-8,
    method: str = "dop853",
    integrator: str = "auto",
) -> Result:
    """The time history of a row (or pair) with its contacts under one
    record (as :func:`pounding` takes them), sampled every ``sample``
    seconds: ``t`` (s); ``floors``, per building name its floor
    displacements relative to the ground (floors × samples, m); ``slab``,
    per isolated building its base slab's displacement (m); ``loops``, per
    hysteretic storey (or bearing layer) its ``building``, ``storey``
    (1-based; None for the bearings), ``drift`` (m) and ``force`` (N) at the
    samples (its hysteresis loop); and the impact log ``impact_time`` (s), ``impact_at`` (``"A–B floor F"`` between
    buildings, ``"A moat"`` on a moat wall), ``impact_floor`` (1-based, 0
    for a slab), ``impact_peak_force`` (N)."""
    d = _core.pounding_history(*_pounding_args(pair, record, scale, sample, rtol, method, integrator))
    d["floors"] = {name: np.asarray(v) for name, v in d["floors"].items()}
    d["impact_floor"] = np.asarray(d["impact_floor"], dtype=np.int64)
    return Result(d)
