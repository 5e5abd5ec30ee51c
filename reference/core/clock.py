"""Time as a double-double t_hi + t_lo (Knuth's two-sum), so that intervals near the
singularity keep their digits however large t is."""

from .jit import hot


@hot
def two_sum_add(hi, lo, s):
    """(hi + lo) + s as a new double-double."""
    h = hi + s
    bb = h - hi
    err = (hi - (h - bb)) + (s - bb)
    lo2 = lo + err
    hi2 = h + lo2
    return hi2, lo2 - (hi2 - h)


@hot
def time_until(hi, lo, t):
    """t − (hi + lo) as a float, exact to the last bit of the difference."""
    return (t - hi) - lo


@hot
def grid_time(k, dt, hi, lo):
    """Local time from the clock hi + lo of the k-th point k·dt of a sample grid."""
    return k * dt - hi - lo
