"""Conservative advancement: the first positive root of a lower bound of a gap.

From a gap's value g, rate g′ and acceleration g″ now, and bounds K ≥ |g″|, B ≥ |g‴|
over the step, two polynomials bound it from below:

    P2(δ) = g + g′δ − K δ²/2,     P3(δ) = g + g′δ + g″δ²/2 − B δ³/6.

The gap stays positive until the first positive root of max(P2, P3) (`safe_step`), so
advancing by it never steps over a contact.  Near a transversal root the step tends to
g/|g′| (Newton from the safe side: quadratic convergence); near a grazing minimum P3
lets the search pass it in a few steps."""

import math

from .jit import hot
from .tolerances import ROOT_REL_TOL


@hot
def _cubic_value(c0, c1, c2, c3, x):
    return c0 + x * (c1 + x * (c2 + x * c3))


@hot
def _critical_points(c1, c2, c3):
    """The critical points of the cubic (roots of 3c3 x² + 2c2 x + c1),
    sorted: (count, first, second)."""
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    if a == 0.0:
        if b != 0.0:
            return 1, -c / b, 0.0
        return 0, 0.0, 0.0
    disc = b * b - 4 * a * c
    if disc < 0:
        return 0, 0.0, 0.0
    qq = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    if qq == 0:
        return 0, 0.0, 0.0
    r0, r1 = qq / a, c / qq
    return 2, min(r0, r1), max(r0, r1)


@hot
def _cubic_slopes(c1, c2, c3, x):
    """The cubic's first and second derivatives at x."""
    return c1 + x * (2.0 * c2 + 3.0 * c3 * x), 2.0 * c2 + 6.0 * c3 * x


@hot
def _past_root_bound(flo, d2lo, c3):
    """A step h past the first root from a point where the cubic (c3 < 0) is flo > 0
    and not rising, with second derivative d2lo there: the cubic is at most
    flo + d2lo h²/2 + c3 h³ ≤ 0 once |c3| h³ ≥ 2 flo and |c3| h ≥ d2lo."""
    return max((2.0 * flo / -c3) ** (1.0 / 3.0), d2lo / -c3)


@hot
def _monotone_root(c0, c1, c2, c3, lo, flo, hi, fhi):
    """A point below the root of the cubic on [lo, hi] (decreasing there, flo = f(lo)
    > 0, fhi = f(hi) ≤ 0; hi = inf: decreasing for ever, c3 < 0), within ROOT_REL_TOL
    of it.

    With c3 ≤ 0 the Taylor quadratic of the cubic at a point x is above the cubic to the
    right of x and below it to the left (the remainder is c3 h³): its root from lo is
    past the root (a new hi), its root from hi back toward lo short of it (a new lo).
    Each estimate is taken from the end that moved last, so it lands on the other side,
    third-order close; pushed a quarter of the tolerance further, so that the bracket
    closes rather than one end creeping up on the root.  The midpoint when an estimate
    falls outside the bracket (a Taylor quadratic without a root, roundoff)."""
    from_lo = True
    for _ in range(100):
        if hi < math.inf and hi - lo <= ROOT_REL_TOL * hi:
            break
        if from_lo:
            d1, d2 = _cubic_slopes(c1, c2, c3, lo)
            x = lo + quadratic_taylor_root(flo, d1, d2)
            x += 0.25 * ROOT_REL_TOL * x
            if not x < math.inf and hi == math.inf:
                x = lo + _past_root_bound(flo, d2, c3)
        else:
            d1, d2 = _cubic_slopes(c1, c2, c3, hi)
            x = hi - quadratic_taylor_root(-fhi, d1, -d2) - 0.25 * ROOT_REL_TOL * hi
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        f = _cubic_value(c0, c1, c2, c3, x)
        from_lo = f > 0.0
        if from_lo:
            lo, flo = x, f
        else:
            hi, fhi = x, f
    return lo


@hot
def cubic_first_root(c0, c1, c2, c3, start=0.0):
    """First positive root of c0 + c1 x + c2 x² + c3 x³ (c3 ≤ 0, positive on [0,
    start]), from below within ROOT_REL_TOL; inf if there is none.  The critical points
    split (start, ∞) into monotone pieces; the first whose end value is ≤ 0 holds the
    root (`_monotone_root`), the last one when the cubic falls for ever after it."""
    m, cr0, cr1 = _critical_points(c1, c2, c3)
    lo = start
    flo = _cubic_value(c0, c1, c2, c3, lo)
    for i in range(m):
        hi = cr0 if i == 0 else cr1
        if hi <= lo:
            continue
        fhi = _cubic_value(c0, c1, c2, c3, hi)
        if fhi <= 0.0:
            return _monotone_root(c0, c1, c2, c3, lo, flo, hi, fhi)
        lo, flo = hi, fhi
    if c3 < 0.0 or (c3 == 0.0 and (c2 < 0.0 or (c2 == 0.0 and c1 < 0.0))):
        return _monotone_root(c0, c1, c2, c3, lo, flo, math.inf, -math.inf)
    return math.inf


@hot
def cubic_positive_on(c0, c1, c2, c3, T):
    """Whether the cubic (c0 > 0, c3 ≤ 0) stays positive on [0, T]: positive at T and at
    its local minimum (where the derivative turns from negative to positive) if that
    lies inside."""
    if _cubic_value(c0, c1, c2, c3, T) <= 0.0:
        return False
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    if a == 0.0:
        if b <= 0.0:
            return True  # concave or linear: the ends decide
        dm = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc <= 0.0:
            return True  # the derivative is never positive: decreasing, the ends decide
        sq = math.sqrt(disc)
        dm = min((-b + sq) / (2.0 * a), (-b - sq) / (2.0 * a))
    if 0.0 < dm < T:
        return _cubic_value(c0, c1, c2, c3, dm) > 0.0
    return True


@hot
def p2_positive_at(g, g1, K, x):
    """Whether P2 = g + g1 δ − K δ²/2 (concave, g > 0) is still positive at δ = x: then
    its first root is past x (no square root needed to tell)."""
    return g + x * (g1 - 0.5 * K * x) > 0.0


@hot
def quadratic_first_root(g, g1, K):
    """First positive root of P2 = g + g1 δ − K δ²/2 (g > 0), in the cancellation-free
    form for g1's sign; inf if there is none."""
    if K > 0.0:
        sq = math.sqrt(g1 * g1 + 2.0 * K * g)
        return (g1 + sq) / K if g1 >= 0.0 else 2.0 * g / (sq - g1)
    if g1 < 0.0:
        return g / -g1
    return math.inf


@hot
def quadratic_taylor_root(g, g1, g2):
    """First positive root of g + g1 δ + g2 δ²/2 (g > 0), cancellation-free; inf if
    none (B = 0 makes P3 this Taylor quadratic, in closed form)."""
    if g2 == 0.0:
        return g / -g1 if g1 < 0.0 else math.inf
    disc = g1 * g1 - 2.0 * g2 * g
    if disc < 0.0:
        return math.inf
    sq = math.sqrt(disc)
    if g2 < 0.0:  # concave: one positive root
        return (g1 + sq) / -g2 if g1 >= 0.0 else 2.0 * g / (sq - g1)
    return 2.0 * g / (sq - g1) if g1 < 0.0 else math.inf  # convex: the smaller root


@hot
def safe_step(g, g1, g2, K, B, cap=math.inf):
    """First positive root of max(P2, P3): no contact before it; 0 if g < 0, or g = 0
    and the gap not rising (g′ ≤ 0).  A gap exactly zero and rising (a contact leaving
    the ground from a state where its gap and its roundoff are both exactly zero: a
    body lying exactly flat at z = 0 with one vertex leaving beside two held ones, after
    a simultaneous impact) is positive until P2's second root 2g′/K (P2 = δ(g′ − Kδ/2)):
    returning 0 there stalled the contact phase.

    When P2's root is already ≥ `cap` (the smallest step found so far among other
    contacts), or P3 stays positive up to `cap`, this contact does not bind the step and
    P3 is not solved: a value ≥ cap is returned."""
    if g < 0.0 or (g == 0.0 and not g1 > 0.0):
        return 0.0
    if cap < math.inf and p2_positive_at(g, g1, K, cap):
        return cap  # P2's root is past cap
    d2 = quadratic_first_root(g, g1, K)
    if d2 >= cap:
        return d2
    if B == 0.0:
        return max(d2, quadratic_taylor_root(g, g1, g2))
    c2, c3 = 0.5 * g2, -B / 6.0
    if not cubic_positive_on(g, g1, c2, c3, d2):
        return d2  # P3's first root comes before P2's: P2 binds
    if cap < math.inf and cubic_positive_on(g, g1, c2, c3, cap):
        return cap
    return cubic_first_root(g, g1, c2, c3, d2)


@hot
def _rising_cubic_root(c0, c1, c2, c3):
    """First positive root of c0 + c1 x + c2 x² + c3 x³ with c0 > 0, c1 < 0, c3 ≥ 0, as a
    point at or just past it (where the cubic is ≤ 0), within ROOT_REL_TOL; inf if the
    cubic stays positive (its one local minimum on x > 0 is above zero)."""
    if c3 == 0.0:
        if c2 <= 0.0:
            return -c0 / c1 if c2 == 0.0 else quadratic_first_root(c0, c1, -2.0 * c2)
        xm = -c1 / (2.0 * c2)
    else:
        xm = (-c2 + math.sqrt(c2 * c2 - 3.0 * c3 * c1)) / (3.0 * c3)
    if _cubic_value(c0, c1, c2, c3, xm) > 0.0:
        return math.inf
    lo, hi = 0.0, xm  # decreasing on [0, xm]: bisection with Newton steps
    for _ in range(200):
        if hi - lo <= ROOT_REL_TOL * hi:
            break
        x = 0.5 * (lo + hi)
        f = _cubic_value(c0, c1, c2, c3, x)
        d = c1 + x * (2.0 * c2 + 3.0 * x * c3)
        nxt = x - f / d if d < 0.0 else x
        if f > 0.0:
            lo = x
        else:
            hi = x
        if lo < nxt < hi:
            if _cubic_value(c0, c1, c2, c3, nxt) > 0.0:
                lo = nxt
            else:
                hi = nxt
    return hi


@hot
def zero_bracket_end(g, g1, g2, K, B):
    """An end of a bracket [safe step, end] that holds the gap's first zero and no other,
    for a gap g > 0 approaching (g1 < 0): the first zero of an upper bound of the gap
    (U2 = g + g1 δ + K δ²/2, else U3 = g + g1 δ + g2 δ²/2 + B δ³/6), provided the gap is
    still decreasing there (`_decreasing_until`).  inf when there is no such end."""
    if g1 >= 0.0 or g <= 0.0:
        return math.inf
    disc = g1 * g1 - 2.0 * K * g
    if disc >= 0.0:  # U2's zero, in closed form, is enough when the rate stays negative
        end = 2.0 * g / (-g1 + math.sqrt(disc))
        if _decreasing_until(g1, g2, K, B, end):
            return end
    end = _rising_cubic_root(g, g1, 0.5 * g2, B / 6.0)
    if end < math.inf and _decreasing_until(g1, g2, K, B, end):
        return end
    return math.inf


@hot
def _decreasing_until(g1, g2, K, B, end):
    """Whether a gap with rate g1 < 0, acceleration g2 and |g″| ≤ K, |g‴| ≤ B at the
    start is still decreasing at every time up to `end`: its rate is at most g1 + Kδ and
    g1 + g2 δ + B δ²/2 (convex in δ), so it suffices that either is negative at end."""
    return g1 + K * end < 0.0 or g1 + end * (g2 + 0.5 * B * end) < 0.0
