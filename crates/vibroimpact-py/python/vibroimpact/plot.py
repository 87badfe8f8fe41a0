"""Matplotlib helpers for notebooks: one figure type per computation.

Every function takes a result, draws on ``ax`` (a new figure's Axes if
None) and returns the Axes. Matplotlib is imported only when a function is
called, so ``import vibroimpact`` does not need it.

>>> import vibroimpact as vi, vibroimpact.plot as vp
>>> b = vi.continue_("examples/fujita-row-n2.toml", "frequency", 11.115, 3.705)
>>> ax = vp.frequency_response(b, x_scale=1 / 7.41)   # doctest: +SKIP
"""

from __future__ import annotations

import numpy as np

__all__ = ["fragility", "frequency_response", "poincare", "restitution", "time_history"]

# Marker per special-point kind (the ``kind`` strings of ``continue_``).
_MARKERS = {
    "fold": "o",
    "branch-point": "s",
    "period-doubling": "D",
    "neimark-sacker": "^",
    "torus": "^",
    "grazing": "X",
}
# Colour per sweep direction.
_DIRECTIONS = {"none": "0.2", "up": "tab:red", "down": "tab:green"}


def _need(result, argument, keys, source):
    """Refuses, naming the argument, what is not the result ``source``
    returns: a plot of the wrong result raised ``KeyError: 'points'``, of
    None an ``AttributeError`` (issue 38)."""
    try:
        missing = [k for k in keys if k not in result]
    except TypeError:
        missing = list(keys)
    if missing:
        got = (f"a result with {', '.join(sorted(result.keys())[:6])}, without {', '.join(missing)}"
               if hasattr(result, "keys") else type(result).__name__)
        raise TypeError(f"{argument}: give the result of {source}, got {got}")


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def _labels(ax, x, y):
    """Axis labels, unless an earlier plot on these axes set them."""
    if not ax.get_xlabel():
        ax.set_xlabel(x)
    if not ax.get_ylabel():
        ax.set_ylabel(y)


def _parameter_axis(name, x_scale):
    """The parameter's axis label, with its units; a scaled frequency as
    Omega/omega0 (issue 38: it read "frequency × 0.135")."""
    if name in ("frequency", "excitation.frequency"):
        if x_scale == 1.0:
            return "forcing frequency Ω (rad/s)"
        return f"Ω/ω0 (ω0 = {1.0 / x_scale:.4g} rad/s)"
    last = name.rsplit(".", 1)[-1]
    units = {"mass": "kg", "stiffness": "N/m", "damping": "N s/m", "clearance": "m",
             "natural_frequency": "rad/s", "phase": "rad", "alpha": "1/m",
             "amplitude": "N" if name.startswith("force") else "m/s²"}.get(last)
    label = name if units is None else f"{name} ({units})"
    return label if x_scale == 1.0 else f"{label} × {x_scale:.4g}"


def _special_amplitude(sp, body, branch, p, u):
    """max |u| (mm) of a special point: its own orbit's; from a document
    without it, the nearest branch point's in parameter and state."""
    own = sp["max_displacement"] if "max_displacement" in sp else None
    if own is not None and len(own) > body:
        return 1e3 * abs(own[body])
    states = np.array([pt.initial_state for pt in branch.points])
    scale = np.ptp(p) or 1.0, np.abs(states).max() or 1.0
    d = np.hypot((p - sp.parameter) / scale[0],
                 np.linalg.norm(states - sp.initial_state, axis=1) / scale[1])
    return u[np.argmin(d)]


def _branch(ax, branch, body, x_scale, label, color, seen):
    p = branch.column("parameter")
    u = 1e3 * np.abs(np.array([pt.max_displacement[body] for pt in branch.points]))
    stable = [bool(pt.stable) for pt in branch.points]
    # The vertices: the points, and after each the special points located
    # after it that carry their own orbit (the curve passes through them,
    # as the CLI's figure draws it).
    after = {}
    for sp in branch.special_points:
        if "after_point" in sp and "max_displacement" in sp and len(sp.max_displacement) > body:
            after.setdefault(int(sp.after_point), []).append(sp)
    xs, ys, st = [], [], []
    for i in range(len(p)):
        xs.append(p[i]), ys.append(u[i]), st.append(stable[i])
        for sp in sorted(after.get(i, []), key=lambda s: abs(s.parameter - p[i])):
            xs.append(sp.parameter), ys.append(1e3 * abs(sp.max_displacement[body])), st.append(None)
    xs, ys = np.array(xs) * x_scale, np.array(ys)
    # A segment is drawn as its first vertex's stability, or from a special
    # point as the next point's.
    style = [next((s for s in st[k:] if s is not None), True) for k in range(len(st))]
    start, labelled = 0, False
    while start + 1 < len(xs):
        end = start + 1
        while end + 1 < len(xs) and style[end] == style[start]:
            end += 1
        ax.plot(xs[start:end + 1], ys[start:end + 1], color=color,
                ls="-" if style[start] else "--", label=None if labelled else label)
        labelled, start = True, end
    for sp in branch.special_points:
        y = _special_amplitude(sp, body, branch, p, u)
        ax.plot(sp.parameter * x_scale, y, ls="none", marker=_MARKERS.get(sp.kind, "*"),
                mfc=color, mec="k", ms=7, zorder=3,
                label=None if sp.kind in seen else sp.kind)
        seen.add(sp.kind)
        ax.annotate(sp.label, (sp.parameter * x_scale, y), xytext=(4, 4),
                    textcoords="offset points", fontsize="x-small")


def frequency_response(branch, ax=None, body=0, x_scale=1.0, label="branch", switched=True):
    """The branch of a :func:`vibroimpact.continue_` result: max |u| of body
    ``body`` (mm) against its parameter times ``x_scale`` (e.g. ``1/omega0``
    for Omega/omega0); stable stretches solid, unstable dashed, special
    points marked by kind and labelled (BP1, PD1, ...). With ``switched``,
    the ``switched_branch`` (if any) is drawn too, in another colour."""
    _need(branch, 'branch', ('points', 'special_points', 'parameter_name'), 'vibroimpact.continue_')
    ax = _axes(ax)
    seen: set = set()
    _branch(ax, branch, body, x_scale, label, "tab:blue", seen)
    if switched and "switched_branch" in branch:
        _branch(ax, branch.switched_branch, body, x_scale, f"{label} (switched)",
                "tab:orange", seen)
    _labels(ax, _parameter_axis(branch.parameter_name, x_scale), f"max |u{body + 1}| (mm)")
    ax.legend(fontsize="small")
    return ax


def time_history(history, ax=None, bodies=None):
    """The displacements (mm) against time (s) of a
    :func:`vibroimpact.simulate` result, for the body indices ``bodies``
    (default: all, at most 8), with each impact's start time ticked along
    the bottom of the axes in its contact's colour."""
    _need(history, 'history', ('t', 'displacement', 'impacts', 'impacts_per_contact'), 'vibroimpact.simulate')
    if len(history.t) == 0:
        raise ValueError("history: no samples to draw (simulated with output_step=0)")
    ax = _axes(ax)
    u = np.asarray(history.displacement)
    for i in range(min(u.shape[1], 8)) if bodies is None else bodies:
        ax.plot(history.t, 1e3 * u[:, i], lw=1, label=f"body {i + 1}")
    contact = np.asarray(history.impacts.contact, dtype=int)
    start = np.asarray(history.impacts.start_time, dtype=float)
    trans = ax.get_xaxis_transform()  # x in data, y in axes fraction
    for k, c in enumerate(history.impacts_per_contact):
        t = start[contact == k]
        if t.size:
            ax.vlines(t, 0.0, 0.05, transform=trans, colors=f"C{(k + 3) % 10}",
                      lw=1.2, label=f"impact {c.contact}")
    _labels(ax, "t (s)", "u (mm)")
    ax.legend(fontsize="small", ncol=2)
    return ax


def poincare(sweep, ax=None, body=0, x_scale=1.0):
    """The brute-force bifurcation diagram of a :func:`vibroimpact.sweep`
    result: every point's Poincaré samples of body ``body``'s displacement
    (mm) against the parameter times ``x_scale``; an up-down sweep's two
    directions in two colours, with a legend."""
    _need(sweep, 'sweep', ('points', 'bodies', 'parameter_name', 'up_down'), 'vibroimpact.sweep')
    ax = _axes(ax)
    n = 2 * len(sweep.bodies)
    xs: dict = {}
    for pt in sweep.points:
        sec = np.asarray(pt.sections, dtype=float).reshape(-1, n)[:, body]
        x, y = xs.setdefault(pt.direction, ([], []))
        x.extend([pt.parameter * x_scale] * len(sec))
        y.extend(1e3 * sec)
    for direction, (x, y) in xs.items():
        name = "sweep" if direction == "none" else f"sweep {direction}"
        ax.scatter(x, y, s=6, color=_DIRECTIONS.get(direction, "k"), label=name, zorder=2)
    _labels(ax, _parameter_axis(sweep.parameter_name, x_scale), f"u{body + 1} at the Poincaré section (mm)")
    if sweep.up_down or ax.get_legend() is not None:
        ax.legend(fontsize="small")
    return ax


def restitution(impact, ax=None, label=None):
    """Coefficient of restitution against impact velocity (m/s, log axis)
    of a :func:`vibroimpact.impact` result; ``label`` defaults to its
    method ("closed-form" or "integrate")."""
    _need(impact, 'impact', ('impact_velocity', 'restitution', 'method'), 'vibroimpact.impact')
    ax = _axes(ax)
    ax.semilogx(impact.impact_velocity, impact.restitution, label=label or impact.method)
    _labels(ax, "impact velocity V (m/s)", "coefficient of restitution e")
    ax.legend(fontsize="small")
    return ax


def fragility(study, ax=None):
    """The collapse fragility of a :func:`vibroimpact.collapse_study`
    result, as ``vibroimpact collapse --out`` draws it: the summary's
    lognormal fit (maximum likelihood, censored records entering with their
    survival) against the empirical collapse fractions (the i-th smallest
    collapse intensity at i / N, N every record), in S_T (g: the set's
    Sa(T) times the collapse scale, as Ŝ_CT) where the study has a period,
    else the scale. Raises ValueError, with the
    summary's reason, where no fit is determined."""
    _need(study, 'study', ('summary', 'records', 'period'), 'vibroimpact.collapse_study')
    from math import erfc, log, sqrt

    summary = study["summary"]
    fit = summary.get("fragility")
    if fit is None:
        raise ValueError(f"study: {summary.get('fragility_note') or 'no fragility fitted'}")
    theta, beta = fit["median"], fit["dispersion"]
    in_g = study["period"] is not None
    per = summary["s_t"] if in_g else 1.0
    records = study["records"]
    fell = np.sort([r["collapse"] * per for r in records if r["collapse"] is not None])
    top = 1.2 * max(fell.max() if fell.size else theta, theta * np.exp(2 * beta))
    s = np.linspace(0.0, top, 201)
    p = [0.0 if x <= 0 else 0.5 * erfc(-log(x / theta) / beta / sqrt(2)) for x in s]
    ax = _axes(ax)
    ax.plot(s, p, color="C0", label=f"lognormal fit: θ = {theta:.4f}, β = {beta:.3f}")
    ax.plot(fell, np.arange(1, fell.size + 1) / len(records), "o", color="C3",
            label="collapsed records (fraction)")
    ax.plot([theta, theta], [0.0, 0.5], "--", color="C1", label="median θ")
    ax.set_ylim(0.0, 1.0)
    x = f"S_T = the set's Sa(T = {study['period']:.4g} s) at collapse (g)" if in_g else "scale"
    _labels(ax, x, "probability of collapse")
    ax.legend(fontsize="small", loc="lower right")
    return ax
