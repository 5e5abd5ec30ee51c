"""How the core's hot functions are compiled.

`hot`: numba's njit without its reference-counting runtime (`_nrt=False`), for functions
that allocate nothing and only read and write arrays they are given: every function
on the event path (all of the loop below `run_events`; numba compiles a callee with its
caller's flags, so nothing under a hot function may allocate: scratch space lives in
records.SCRATCH and the caller's per-contact arrays).  With the runtime,
every array argument is reference-counted on each call (measured with perf on a bouncing
triangle: NRT_incref/NRT_decref took 12 % of the run); without it, none is.  `_nrt` is
numba's own switch for such code (numba.misc.mergesort uses it); a function that would
allocate fails to compile, so a misuse cannot pass silently.

`error_model="numpy"`: a float division by zero gives ±inf or nan, as in numpy, rather
than a test before every division to raise ZeroDivisionError (Python's model, numba's
default): the loop ends a run whose state is not finite with an explicit status
(STATUS_FAILED_NONFINITE), and the tests cost ~2 % of a run's instructions (callgrind,
five bench runs; results bit-identical on 17 check scenes).
One signature per event function: numba compiles a function once per tuple of argument
types, types a constant argument as its value (`Literal[int](0)`), an omitted optional
argument as a type of its own and a record's array field as a nested array of its
length, and every signature compiles the function and everything it calls again.  On
the event path a constant argument is therefore one of the typed constants below, a
counter passed on starts at `ZERO` (numba's type inference first types `m = 0` as
`Literal[int](0)` and resolves the calls with that type too), every argument is passed,
a record's contact list is passed as a view (`state.active[:]`), and a record's arrays
of one role share one shape.  The build
(`python -m reference.core.aot`) lists the functions still compiled more than once:
`search.examine` and the frame functions under it, specialised on the contact kind on
purpose (docs/performance.md, "Event search"), and small helpers that the exported
row functions (`arrays`, `multi_impact`) call with plain arrays.
"""

import numpy as np
from numba import njit

# Typed constants for calls on the event path: typed as int64 and bool, as the variables
# at the other call sites are (a literal `0` or `True` is typed as its value).
ZERO = np.int64(0)
ONE = np.int64(1)
FALSE = np.bool_(False)
TRUE = np.bool_(True)

hot = njit(cache=True, _nrt=False, error_model="numpy")
# `hot`, inlined into its callers by numba (its IR, before LLVM): for a helper that
# LLVM leaves as a call on the event path
hot_inline = njit(cache=True, _nrt=False, error_model="numpy", inline="always")


@hot
def copy_into(dst, src):
    """dst[:] = src, element by element: a slice assignment between two arrays makes
    numba allocate a temporary in case they overlap, which needs its runtime."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@hot
def sort_prefix(a, m):
    """Sort a[:m] in place (insertion sort: m, a count of contacts, is small)."""
    for i in range(1, m):
        k = i
        while k > 0 and a[k - 1] > a[k]:
            a[k - 1], a[k] = a[k], a[k - 1]
            k -= 1
