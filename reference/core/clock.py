"""Time as a double-double t_hi + t_lo (Knuth's two-sum), so that intervals near the
singularity keep their digits however large t is."""

from numba import njit


@njit(cache=True)
def two_sum_add(hi, lo, s):
    """(hi + lo) + s as a new double-double."""
    h = hi + s
    bb = h - hi
    err = (hi - (h - bb)) + (s - bb)
    lo2 = lo + err
    hi2 = h + lo2
    return hi2, lo2 - (hi2 - h)


@njit(cache=True)
def time_until(hi, lo, t):
    """t − (hi + lo) as a float, exact to the last bit of the difference."""
    return (t - hi) - lo
