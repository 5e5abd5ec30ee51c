"""The order `make test` hands out the test files in (tests/schedule.py): files that
start process pools before the file that imports JAX, then the longest first; and no test
file imports JAX when it is collected."""

from __future__ import annotations

from pathlib import Path

from tests.schedule import FILE_SECONDS, JAX_AT_COLLECTION, JAX_FILES, POOL_FILES, ordered

TESTS = Path(__file__).resolve().parent


class Item:
    def __init__(self, name: str, test: str):
        self.path = TESTS / name
        self.nodeid = f"tests/{name}::{test}"


def test_every_file_the_schedule_names_exists():
    named = set(FILE_SECONDS) | POOL_FILES | JAX_FILES
    assert {name for name in named if not (TESTS / name).is_file()} == set()


def test_pool_files_come_before_jax_files_and_the_longest_first():
    items = [
        Item("test_short.py", "a"),
        Item("test_engine_mjx.py", "a"),
        Item("test_oracle.py", "a"),
        Item("test_sweep_heal.py", "a"),
        Item("test_report.py", "a"),
        Item("test_sweep.py", "a"),
        Item("test_oracle.py", "b"),
        Item("test_short.py", "b"),
    ]
    assert [item.nodeid for item in ordered(items)] == [
        "tests/test_sweep.py::a",  # pools, 10.7 s
        "tests/test_sweep_heal.py::a",  # pools, under 2 s: unlisted
        "tests/test_engine_mjx.py::a",
        "tests/test_oracle.py::a",  # 20.9 s, its tests in their order
        "tests/test_oracle.py::b",
        "tests/test_report.py::a",  # 16.1 s
        "tests/test_short.py::a",  # unlisted: as collected
        "tests/test_short.py::b",
    ]


def test_collecting_the_tests_leaves_jax_unloaded(pytestconfig):
    """A test process with JAX loaded starts its pools by spawn: no test file imports
    JAX at collection (MJX's tests import it when they run)."""
    assert pytestconfig.stash[JAX_AT_COLLECTION] is False
