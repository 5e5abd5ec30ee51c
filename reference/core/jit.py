"""How the core's hot functions are compiled.

`hot`: numba's njit without its reference-counting runtime (`_nrt=False`), for functions
that allocate nothing and only read and write arrays they are given: every function
on the event path (all of the loop below `run_events`, which allocates the contact
lists of a call; numba compiles a callee with its caller's flags, so nothing under a
hot function may allocate: scratch space lives in records.SCRATCH).  With the runtime,
every array argument is reference-counted on each call (measured with perf on a bouncing
triangle: NRT_incref/NRT_decref took 12 % of the run); without it, none is.  `_nrt` is
numba's own switch for such code (numba.misc.mergesort uses it); a function that would
allocate fails to compile, so a misuse cannot pass silently.
"""

from numba import njit

hot = njit(cache=True, _nrt=False)


@hot
def copy_into(dst, src):
    """dst[:] = src, element by element: a slice assignment between two arrays makes
    numba allocate a temporary in case they overlap, which needs its runtime."""
    for i in range(src.shape[0]):
        dst[i] = src[i]
