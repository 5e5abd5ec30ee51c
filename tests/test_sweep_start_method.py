"""The local sweep pool forks only where forking is safe."""

import sys

from harness.sweep.executors import start_method


def test_the_pool_forks_when_no_threaded_runtime_is_loaded(monkeypatch):
    monkeypatch.delitem(sys.modules, "jax", raising=False)
    assert start_method(["fork", "spawn", "forkserver"]) == "fork"


def test_the_pool_spawns_once_jax_is_loaded(monkeypatch):
    monkeypatch.setitem(sys.modules, "jax", object())
    assert start_method(["fork", "spawn", "forkserver"]) == "spawn"


def test_the_pool_spawns_where_the_platform_cannot_fork(monkeypatch):
    monkeypatch.delitem(sys.modules, "jax", raising=False)
    assert start_method(["spawn"]) == "spawn"
