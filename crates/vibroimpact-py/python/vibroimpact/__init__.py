"""vibroimpact: vibrating systems whose bodies collide, after T. Fujita (1977).

The library's computations from Python, named after the command line
(subcommand -> function, ``--option-name`` -> ``option_name=``, same
defaults). Results are :class:`Result` objects whose fields carry the names
of the CLI's JSON output, with numpy arrays for numeric lists.

>>> import vibroimpact as vi
>>> r = vi.impact([0.01, 0.1, 1.0])              # the seed's law and balls
>>> r.restitution                                 # doctest: +SKIP
>>> m = vi.Model.load("examples/fujita-row.toml")
>>> h = vi.simulate(m, periods=5)                 # h.t, h.displacement, h.impacts
>>> s = vi.sweep(m, parameter="frequency", from_=5.9, to=8.9, points=41)

Long calls release the GIL, stop on Ctrl-C (KeyboardInterrupt) and report
progress to ``progress(done, total)`` if given. Bad input raises
``ValueError`` naming the argument or model key; a numerical failure raises
:class:`VibroimpactError`. A legal run that will take long (``simulate`` of
1e7 periods, a forcing far faster than the bodies) still runs, but first
warns with :class:`LongRunWarning`: its estimated steps and time.
"""

from __future__ import annotations

# The façade: the public names live in topic modules, by subject.
from . import _checks
from ._core import LongRunWarning, Model, VibroimpactError
from .collapse import collapse_study
from ._earthquakes import pounding, pounding_history, pushover, read_record, response_spectrum
from ._impacts import contact_force, identify, impact
from ._maps import basins, chart, parameter_values, sweep
from ._motion import simulate
from ._orbits import continue_, periodic
from ._storeys import hysteresis
from ._results import Result

# The type aliases of the public signatures (not in __all__).
ArrayLike, ModelLike, Progress = _checks.ArrayLike, _checks.ModelLike, _checks.Progress

__all__ = [
    "Model",
    "Result",
    "VibroimpactError",
    "LongRunWarning",
    "basins",
    "chart",
    "collapse_study",
    "contact_force",
    "continue_",
    "hysteresis",
    "identify",
    "impact",
    "parameter_values",
    "periodic",
    "pounding",
    "pounding_history",
    "pushover",
    "read_record",
    "response_spectrum",
    "simulate",
    "sweep",
]

try:  # pragma: no cover - metadata exists once installed
    from importlib.metadata import version as _version

    __version__ = _version("vibroimpact")
except Exception:  # pragma: no cover
    __version__ = "0+unknown"
