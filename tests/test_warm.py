"""The set-up's warm-up of the linear model (reference/warm.py, `make setup`) calls every
function of the linear kernel that Python calls, so that numba's cache holds each
before the first command or test process needs it."""

from __future__ import annotations

from numba import typeof

from reference import warm
from reference.linear import kernel as K

# the law event's helpers that reference.linear.laws calls from Python (compiled into
# the kernel, they are not among PYTHON_ENTRY_POINTS)
LAW_HELPERS = {"_law_impulses", "_law_completes", "_add_law_impulses"}


class _recording:
    """A compiled function that records the numba types of each call's arguments in
    calls[name] (and is otherwise the function: its `compile`, `signatures`, ...)."""

    def __init__(self, function, name, calls):
        self._function, self._name, self._calls = function, name, calls

    def __call__(self, *args):
        self._calls.setdefault(self._name, set()).add(tuple(str(typeof(a)) for a in args))
        return self._function(*args)

    def __getattr__(self, attribute):
        return getattr(self._function, attribute)


def test_the_warm_up_calls_every_function_of_the_linear_kernel_that_python_calls(monkeypatch):
    calls: dict[str, set] = {}
    for name in K.PYTHON_ENTRY_POINTS | LAW_HELPERS:
        monkeypatch.setattr(K, name, _recording(getattr(K, name), name, calls))
    warm.warm_all()
    assert set(calls) == K.PYTHON_ENTRY_POINTS | LAW_HELPERS


def test_the_warm_up_passes_the_types_the_energy_exponent_passes(monkeypatch):
    """numba compiles a function once per tuple of argument types: the warm-up's calls of
    the exponent's sums have the types of reference.linear.exponent_estimates' calls (on
    a triangle's run to the end of its energy)."""
    from reference.linear.simulate import run_linear_exponent

    sums = ("log2_time_to_go", "log2_segment_sums")
    original = {name: getattr(K, name) for name in sums}
    product: dict[str, set] = {}
    warmed: dict[str, set] = {}
    for calls, run in (
        (product, lambda: run_linear_exponent(3, 0.3, 0.2, (0.01, 0.0, 0.02), (0.0, 0.1, -0.1))),
        (warmed, warm.warm_python_calls),
    ):
        for name in sums:
            monkeypatch.setattr(K, name, _recording(original[name], name, calls))
        run()
    assert set(product) == set(sums)
    assert all(product[name] <= warmed[name] for name in sums)
