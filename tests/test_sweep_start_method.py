"""Child processes (the sweep's pool, a capped engine run) fork only where forking is safe."""

import functools
import multiprocessing
import sys

from harness.child_processes import start_method
from harness.stress.budget import run_capped


def test_the_pool_forks_when_no_threaded_runtime_is_loaded(monkeypatch):
    monkeypatch.delitem(sys.modules, "jax", raising=False)
    assert start_method(["fork", "spawn", "forkserver"]) == "fork"


def test_the_pool_spawns_once_jax_is_loaded(monkeypatch):
    monkeypatch.setitem(sys.modules, "jax", object())
    assert start_method(["fork", "spawn", "forkserver"]) == "spawn"


def test_the_pool_spawns_where_the_platform_cannot_fork(monkeypatch):
    monkeypatch.delitem(sys.modules, "jax", raising=False)
    assert start_method(["spawn"]) == "spawn"


def test_a_capped_run_is_spawned_once_jax_is_loaded_and_answers(monkeypatch):
    """With JAX loaded a capped engine run's child is spawned, not forked (a forked
    child can hang: harness.child_processes), and still returns its answer."""
    monkeypatch.setitem(sys.modules, "jax", object())
    methods = []
    real = multiprocessing.get_context
    monkeypatch.setattr(multiprocessing, "get_context", lambda m: methods.append(m) or real(m))
    assert run_capped(functools.partial(pow, 2, 10), 120.0) == (1024, None)
    assert methods == ["spawn"]
