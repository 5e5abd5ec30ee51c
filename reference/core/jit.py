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
types, types a constant argument as its value (`Literal[int](0)`) and a record's array
field as a nested array of its length, and every signature compiles the function and
everything it calls again.  The calls of the impact events (`events.resolve_impact`,
its law path) therefore pass counts as `np.int64(k)` and a record's contact list as a
view (`state.active[:]`): the law's chain is compiled once, not once per call site.
"""

from numba import njit

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
