"""Type stubs of the compiled extension ``vibroimpact._core``. Users call the
package's functions (``vibroimpact.simulate`` ...), which check and default
their arguments and wrap these results in ``Result`` objects."""

from os import PathLike
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

Progress = Optional[Callable[[int, int], Any]]
F64 = npt.NDArray[np.float64]

class VibroimpactError(Exception):
    """A numerical failure (an integration that cannot go on, a Newton
    iteration that does not converge)."""

class LongRunWarning(UserWarning):
    """A run that will take long: its estimated steps and time, said
    before it starts (it still runs)."""

def parameter_values(from_: float, to: float, k: int) -> F64: ...

class Model:
    """A model of bodies, springs, contacts and excitation (the model-file
    schema of docs/model.md). Immutable and picklable."""

    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> Model: ...
    @staticmethod
    def from_toml(text: str, source: str = "<string>") -> Model: ...
    @staticmethod
    def from_dict(document: dict[str, Any], source: str = "<dict>") -> Model: ...
    def to_dict(self) -> dict[str, Any]: ...
    def to_toml(self) -> str: ...
    def with_(self, values: Optional[dict[str, float]] = None, **kwargs: float) -> Model: ...
    def with_impacts(self, impacts: Optional[str] = None, restitution: Optional[float] = None) -> Model: ...
    def get(self, name: str) -> float: ...
    @property
    def bodies(self) -> list[str]: ...
    @property
    def contacts(self) -> list[str]: ...
    @property
    def forcing_frequency(self) -> Optional[float]: ...
    @property
    def mirror_symmetric(self) -> bool: ...
    @property
    def source(self) -> str: ...
    def __len__(self) -> int: ...

def impact(
    velocity: F64, law_spec: str, mass1: float, mass2: float, method: str,
    rtol: float, duration_level: Optional[float], progress: Progress = None,
) -> dict[str, Any]: ...
def parse_measured(text: str, source: str, wanted: list[str]) -> list[F64]: ...
def contact_force(law_spec: str, s: F64, sdot: F64, impact_velocity: F64) -> dict[str, F64]: ...
def identify(
    restitution_velocity: F64, restitution: F64, acceleration_velocity: F64,
    peak_acceleration: F64, mass1: float, mass2: float, a_over_b: Optional[float], joint: bool,
) -> dict[str, Any]: ...
def simulate(
    model: Model, duration: float, rtol: Optional[float], atol: Optional[float],
    method_name: str, output_step: Optional[float], energy: bool,
    impact_force_threshold: Optional[float], integrator: str, impacts: Optional[str],
    restitution: Optional[float], progress: Progress = None,
) -> dict[str, Any]: ...
def periodic(
    model: Model, subharmonic: int, guess: Optional[F64], guess_periods: float, rtol: float,
    tol: float, krylov: bool, arnoldi: int, symmetric: bool, progress: Progress = None,
    integrator: str = "auto", dense: bool = False, homotopy: bool = False,
) -> dict[str, Any]: ...
def continue_branch(
    model: Model, parameter: str, from_: float, to: float, subharmonic: int,
    switch_at: Optional[str], max_points: int, ds_max: float, guess_periods: float,
    progress: Progress = None, integrator: str = "auto", start: str = "auto",
    krylov: bool = False, dense: bool = False, arnoldi: int = 20,
    second: tuple[
        Optional[str], Optional[float], Optional[float], list[str], float, Optional[str]
    ] = ...,
) -> dict[str, Any]: ...
def sweep(
    model: Model, parameter: str, values: F64, transient: int, record: int, up_down: bool,
    rtol: Optional[float], atol: Optional[float], method_name: str,
    cluster_tolerance: Optional[float], threads: Optional[int], only: Optional[str] = None,
    progress: Progress = None, lyapunov: Optional[int] = None, integrator: str = "auto",
    settle: Optional[int] = None,
) -> dict[str, Any]: ...

def chart(
    model: Model, x: str, x_values: F64, y: str, y_values: F64, transient: int, record: int,
    starts: int, lyapunov: bool, rtol: Optional[float], atol: Optional[float], method_name: str,
    cluster_tolerance: Optional[float], threads: Optional[int], progress: Progress = None,
    integrator: str = "auto", settle: Optional[int] = None,
) -> dict[str, Any]: ...

def basins(
    model: Model, x: str, x_values: F64, y: str, y_values: F64, base: Optional[F64],
    transient: int, record: int, rtol: Optional[float], atol: Optional[float], method_name: str,
    cluster_tolerance: Optional[float], threads: Optional[int], progress: Progress = None,
    integrator: str = "auto", settle: Optional[int] = None,
) -> dict[str, Any]: ...

def basin_runs(
    model: Model, x: str, x_values: F64, y: str, y_values: F64, base: Optional[F64],
    options: dict[str, Any],
) -> str: ...

def basins_merge(
    model: Model, x: str, x_values: F64, y: str, y_values: F64, base: Optional[F64],
    options: dict[str, Any], parts: list[str],
) -> dict[str, Any]: ...

def parse_record(text: str, source: str, units: Optional[str] = None) -> dict[str, Any]: ...
def response_spectrum(
    times: F64, acceleration: F64, periods: F64, damping: float, scale: float,
    source: str = "record", header: list[str] = ..., units: str = "m/s2",
) -> dict[str, Any]: ...
def pounding(
    pair_text: str, source: str, records: list[tuple[str, list[str], str, F64, F64]],
    scale: float, sample: float, rtol: float, method: str, integrator: str, free: bool,
    gaps: Optional[F64] = None, ratios: Optional[F64] = None,
) -> dict[str, Any]: ...
def value_range(field: str, text: str) -> F64: ...
def parse_drifts(text: str, source: str) -> F64: ...
def hysteresis(
    law: tuple[str, float, Optional[float], float, float, float, float, float, float, float],
    amplitudes: list[float], cycles: int, points: int, drift: Optional[F64], rtol: float,
    imk: Optional[tuple[list[Optional[float]], list[Optional[float]], list[float]]] = ...,
) -> dict[str, Any]: ...
def pushover(
    pair_text: str, source: str, building: Optional[str], drift_ratio_limit: float, points: int,
    code_period: Optional[float],
) -> dict[str, Any]: ...
def pounding_history(
    pair_text: str, source: str, times: F64, acceleration: F64, scale: float, sample: float,
    rtol: float, method: str, integrator: str,
) -> dict[str, Any]: ...
