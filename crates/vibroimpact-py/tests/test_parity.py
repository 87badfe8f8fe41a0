"""Parity of the command line and the Python API: every subcommand has its
function, every option its keyword with the same default, except the
differences listed in docs/parity.md (and each listed one still exists)."""

import inspect
import json
import subprocess

import vibroimpact as vi
from conftest import ROOT

FUNCTIONS = {
    "impact": vi.impact,
    "identify": vi.identify,
    "simulate": vi.simulate,
    "periodic": vi.periodic,
    "continue": vi.continue_,
    "sweep": vi.sweep,
    "chart": vi.chart,
    "basins": vi.basins,
    "spectrum": vi.response_spectrum,
    "pounding": vi.pounding,
    "pushover": vi.pushover,
    "hysteresis": vi.hysteresis,
    "collapse": vi.collapse_study,
}
# Subcommands without a function: the default study's report.
NO_FUNCTION = {"report"}
PYTHON_KEYWORDS = {"from": "from_"}


def table():
    """The rows of docs/parity.md: (command, option, face, kind)."""
    rows = []
    for line in (ROOT / "docs" / "parity.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 5 or cells[0] in ("command", "---") or set(cells[0]) <= {"-"}:
            continue
        for option in cells[1].split(","):
            rows.append((cells[0], option.strip(), cells[2], cells[3]))
    return rows


def cli_options(cli_exe):
    out = subprocess.run([cli_exe, "options"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def same_default(cli, py):
    if py is inspect.Parameter.empty:
        return True
    value = cli["default"]
    if cli["flag"]:
        return py is False and value in (None, "false")
    if value is None:
        return py is None
    if isinstance(py, (list, tuple)):
        return [str(x) for x in py] == value.split(",")
    if isinstance(py, bool):
        return str(py).lower() == value
    if isinstance(py, (int, float)):
        try:
            return float(value) == float(py)
        except ValueError:
            return False
    return str(py) == value


def differences(options):
    """Every difference: (command, option, face) with face CLI, Python or
    default."""
    found = set()
    for command, spec in options.items():
        if command in NO_FUNCTION:
            continue
        assert command in FUNCTIONS, f"`vibroimpact {command}` has no Python function"
        params = inspect.signature(FUNCTIONS[command]).parameters
        positional = set(spec["positional"])
        cli = {}
        for o in spec["options"]:
            name = o["name"].replace("-", "_")
            cli[PYTHON_KEYWORDS.get(name, name)] = o
        for name, o in cli.items():
            if name not in params:
                found.add((command, name, "CLI"))
            elif not same_default(o, params[name].default):
                found.add((command, name, "default"))
        for name in params:
            if name not in cli and name not in positional:
                found.add((command, name, "Python"))
    return found


def test_every_option_has_its_keyword(cli_exe):
    found = differences(cli_options(cli_exe))
    listed = table()
    covered = set()
    unlisted = []
    for command, option, face in sorted(found):
        rows = [
            r for r in listed if r[0] in (command, "*") and r[1] == option and r[2] == face
        ]
        if rows:
            covered.update(rows)
        else:
            unlisted.append(f"{command}: {option} ({face} only)" if face != "default"
                            else f"{command}: {option} (a different default)")
    assert not unlisted, "differences not in docs/parity.md:\n" + "\n".join(unlisted)
    stale = [
        r for r in listed
        if r[0] != "*" and r not in covered
    ]
    assert not stale, f"rows of docs/parity.md that match no difference: {stale}"


def test_a_difference_is_found(cli_exe):
    # The check itself: an option the CLI would gain, a default it would
    # change, are differences.
    options = cli_options(cli_exe)
    options["simulate"]["options"].append({"name": "new-option", "default": None, "flag": False})
    points = next(o for o in options["sweep"]["options"] if o["name"] == "points")
    points["default"] = "7"
    found = differences(options)
    assert ("simulate", "new_option", "CLI") in found
    assert ("sweep", "points", "default") in found
