"""The plots on real results, and the example notebook executed end to end."""

import sys

import numpy as np
import pytest

import vibroimpact as vi
from conftest import EXAMPLES

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def test_import_does_not_load_matplotlib():
    import subprocess

    code = "import sys, vibroimpact, vibroimpact.plot; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_plots_draw_the_results():
    import matplotlib.pyplot as plt
    import vibroimpact.plot as vp

    b = vi.continue_(EXAMPLES / "fujita-row-n2.toml", "frequency", 11.115, 3.705)
    ax = vp.frequency_response(b, x_scale=1 / 7.41)
    drawn = np.concatenate([l.get_xdata() for l in ax.get_lines()])
    assert drawn.min() == pytest.approx(3.705 / 7.41) and drawn.max() == pytest.approx(1.5)
    h = vi.simulate(EXAMPLES / "fujita-row.toml", periods=2)
    assert vp.time_history(h).get_lines()
    s = vi.sweep(EXAMPLES / "fujita-row.toml", "frequency", values=[6.0, 7.0], transient=5, record=3)
    assert vp.poincare(s).collections
    assert vp.restitution(vi.impact(np.logspace(-3, 0, 20))).get_xscale() == "log"
    plt.close("all")


@pytest.mark.parametrize("name", ["seed-study.ipynb", "pounding-records.ipynb", "isolation-collapse.ipynb",
                                  "moment-frame-collapse.ipynb"])
def test_example_notebook_runs(name):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(EXAMPLES / name, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}
    )
    client.execute()
    errors = [
        o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors
