"""The safe-step roots (reference.core.roots) against roots found independently: the
first sign change of the polynomial (or of the bounds P2, P3 written out here) on a
fine logarithmic grid, closed by scipy's brentq."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from reference.core.roots import cubic_first_root, safe_step
from reference.core.tolerances import ROOT_REL_TOL

# the grid both root finders below look for the first sign change on: 400 points a
# decade over 1e-20 … 1e6
GRID = np.logspace(-20, 6, 26 * 400 + 1)
GRID.flags.writeable = False


def _first_positive_root(coeffs):
    """The first x > 0 where the polynomial c0 + c1 x + … (ascending, c0 > 0) changes
    sign: the first sign change on GRID, closed by brentq; inf if there is none."""
    f = np.polynomial.Polynomial(coeffs)
    xs = GRID
    below = np.nonzero(f(xs) <= 0.0)[0]
    if below.size == 0:
        return math.inf
    i = below[0]
    if i == 0:
        return xs[0]
    return brentq(f, xs[i - 1], xs[i], xtol=1e-300, rtol=4 * np.finfo(float).eps)


def _random_cubic(rng):
    """c0 > 0 and c3 ≤ 0 (the P3 of a gap), over many scales; one in twenty quadratic."""
    c0 = 10.0 ** rng.uniform(-12, 0)
    c1 = rng.normal() * 10.0 ** rng.uniform(-4, 1)
    c2 = rng.normal() * 10.0 ** rng.uniform(-4, 1)
    c3 = 0.0 if rng.random() < 0.05 else -(10.0 ** rng.uniform(-4, 3))
    return c0, c1, c2, c3


@pytest.mark.parametrize("seed", range(3))
def test_cubic_first_root_is_below_the_first_root_within_its_tolerance(seed):
    """cubic_first_root returns the first positive root from below within
    ROOT_REL_TOL, or inf exactly when there is none: 3,000 random cubics whose roots
    span twelve decades, roots found by numpy and brentq."""
    rng = np.random.default_rng(seed)
    found = 0
    for _ in range(3000):
        c = _random_cubic(rng)
        got = cubic_first_root(*c)
        want = _first_positive_root(c)
        if not math.isfinite(want):
            assert got == math.inf, c
            continue
        found += 1
        assert want * (1 - ROOT_REL_TOL) <= got <= want * (1 + 8 * np.finfo(float).eps), c
    assert found > 1500


def _bounds_first_root(g, g1, g2, K, B):
    """The first positive root of max(P2, P3), P2 = g + g1 δ − K δ²/2 and P3 = g + g1 δ
    + g2 δ²/2 − B δ³/6: where both are ≤ 0 for the first time (same grid and brentq)."""

    def m(x):
        return np.maximum(g + x * (g1 - 0.5 * K * x), g + x * (g1 + x * (0.5 * g2 - x * B / 6.0)))

    xs = GRID
    below = np.nonzero(m(xs) <= 0.0)[0]
    if below.size == 0:
        return math.inf
    i = below[0]
    return brentq(m, xs[i - 1], xs[i], xtol=1e-300, rtol=4 * np.finfo(float).eps)


@pytest.mark.parametrize("seed", range(2))
def test_safe_step_is_the_first_root_of_the_larger_bound_from_below(seed):
    """safe_step is the first root of max(P2, P3) from below within ROOT_REL_TOL
    (gaps approaching, leaving, grazing; K ≥ |g″|), and with a cap it returns a value
    ≥ the cap exactly when that root is past the cap, else the same step."""
    rng = np.random.default_rng(seed)
    for _ in range(1500):
        g = 10.0 ** rng.uniform(-10, -1)
        g1 = rng.normal() * 10.0 ** rng.uniform(-4, 0)
        g2 = rng.normal() * 10.0 ** rng.uniform(-2, 1)
        K = abs(g2) * (1.0 + 10.0 ** rng.uniform(-3, 1))
        B = 10.0 ** rng.uniform(-1, 3)
        want = _bounds_first_root(g, g1, g2, K, B)
        got = safe_step(g, g1, g2, K, B)
        if not math.isfinite(want):
            assert got == math.inf
            continue
        assert want * (1 - ROOT_REL_TOL) <= got <= want * (1 + 1e-12), (g, g1, g2, K, B)
        cap = want * 10.0 ** rng.uniform(-1, 1)
        capped = safe_step(g, g1, g2, K, B, cap)
        if want >= cap * (1 + 2 * ROOT_REL_TOL):
            assert capped >= cap
        elif want <= cap * (1 - 2 * ROOT_REL_TOL):
            assert want * (1 - ROOT_REL_TOL) <= capped <= want * (1 + 1e-12)


@pytest.mark.parametrize("seed", range(2))
def test_a_gap_exactly_zero_and_rising_is_safe_until_its_bounds_come_back(seed):
    """A gap exactly 0 leaving the ground (g′ > 0: a vertex leaving a body that lies
    exactly flat at z = 0, its roundoff 0 too) is positive until the later of the
    bounds' second roots: P2 = δ(g′ − Kδ/2) at 2g′/K and P3 = δ(g′ + g″δ/2 − Bδ²/6) at
    the positive root of its quadratic factor (B = 0: the Taylor quadratic's).  A gap
    exactly 0 and not rising, or below 0, gives 0."""
    rng = np.random.default_rng(seed)
    for _ in range(500):
        g1 = 10.0 ** rng.uniform(-6, 1)
        g2 = rng.normal() * 10.0 ** rng.uniform(-2, 1)
        K = abs(g2) * (1.0 + 10.0 ** rng.uniform(-3, 1))
        B = 0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-1, 3)
        p3_roots = np.roots([-B / 6.0, 0.5 * g2, g1]) if B > 0 else np.roots([0.5 * g2, g1])
        p3 = min((r.real for r in p3_roots if abs(r.imag) == 0 and r.real > 0), default=math.inf)
        want = max(2.0 * g1 / K, p3)
        got = safe_step(0.0, g1, g2, K, B)
        if not math.isfinite(want):
            assert got == math.inf
            continue
        assert want * (1 - 2 * ROOT_REL_TOL) <= got <= want * (1 + 1e-12), (g1, g2, K, B)
        assert safe_step(0.0, -g1, g2, K, B) == 0.0
        assert safe_step(0.0, 0.0, g2, K, B) == 0.0
        assert safe_step(-1e-300, g1, g2, K, B) == 0.0
