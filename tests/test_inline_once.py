"""reference.core.inline_once: within `callee_ir_once()` numba runs its untyped pipeline
over an inlined callee once, not at every call site, and the inlined code computes what
it computes without the context."""

from __future__ import annotations

import pytest
from numba import njit
from numba.core.inline_closurecall import InlineWorker

from reference.core.inline_once import callee_ir_once


def _fresh_functions():
    """A callee inlined at three sites (two argument types) and its caller, new numba
    dispatchers each time (nothing compiled or cached yet)."""

    @njit(inline="always")
    def clipped_square(x):
        y = x * x
        if y > 10:
            y = 10
        return y

    @njit
    def caller(a, b):
        return clipped_square(a) + clipped_square(a + 1.0) + clipped_square(b)

    return clipped_square, caller


def _pipeline_runs(monkeypatch) -> list[str]:
    """The functions numba runs its untyped pipeline over for inlining, in order."""
    runs: list[str] = []
    default = InlineWorker.run_untyped_passes

    def counted(self, func, enable_ssa=False):
        runs.append(func.__name__)
        return default(self, func, enable_ssa)

    monkeypatch.setattr(InlineWorker, "run_untyped_passes", counted)
    return runs


def test_without_the_context_numba_runs_the_pipeline_at_every_site(monkeypatch):
    runs = _pipeline_runs(monkeypatch)
    _, caller = _fresh_functions()
    assert caller(1.5, 4) == 1.5**2 + 2.5**2 + 10
    assert runs.count("clipped_square") == 3


def test_within_the_context_the_callee_goes_through_the_pipeline_once(monkeypatch):
    runs = _pipeline_runs(monkeypatch)
    _, caller = _fresh_functions()
    with callee_ir_once():
        caller.compile("(float64, int64)")
    assert runs.count("clipped_square") == 1
    assert caller(1.5, 4) == 1.5**2 + 2.5**2 + 10
    assert caller(3.0, 2) == 9.0 + 10 + 4


def test_numbas_own_inlining_is_back_after_the_context_even_after_an_error():
    default = InlineWorker.inline_function
    with pytest.raises(RuntimeError), callee_ir_once():
        assert InlineWorker.inline_function is not default
        raise RuntimeError
    assert InlineWorker.inline_function is default
