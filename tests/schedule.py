"""The order in which `make test` hands whole test files to its workers.

`make test` runs `pytest -n auto --dist loadfile --no-loadscope-reorder`: pytest-xdist
hands each worker whole files, in the order of the collected tests, the next file to
whichever worker is about to run out.  Without `--no-loadscope-reorder` it hands out the
files with the most tests first, which sends the long files (a few slow tests each: the
oracle comparisons, MJX, the report) last, and one worker then runs the last of them
while the other idles.  `ordered` sorts the collected tests so that:

1. files whose tests start process pools from the test process (the sweep's pool, a
   capped engine run) come first.  A process that has imported JAX starts such pools by
   spawn, not fork (harness/child_processes.py): every child then imports and loads the
   harness again.  Measured on one process: the three sweep files took 19 s with fork,
   42 s once JAX was imported;
2. then the file that imports JAX (MJX's tests);
3. then the other long files, longest first, so that the files handed out last are
   short and the two workers end together;
4. then the rest, as collected.

FILE_SECONDS holds the files that take ≥ 2 s, their CPU seconds (the test process's and
its children's) in one run of `make test`'s command on a clean clone of a 2-core machine,
numba's and JAX's caches as `make setup` leaves them (docs/performance.md, "Where the
tests' time goes").  The order only moves time between the workers: any order gives the
same results."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

FILE_SECONDS = {
    "test_engine_mjx.py": 12.3,
    "test_readme_commands.py": 11.6,
    "test_sweep.py": 9.4,
    "test_paper_figures.py": 8.2,
    "test_fuzz_cli.py": 7.9,
    "test_oracle.py": 7.5,
    "test_core_flight.py": 6.5,
    "test_reference_search.py": 5.9,
    "test_signals.py": 5.5,
    "test_sweep_parts.py": 4.7,
    "test_law_registry.py": 4.3,
    "test_engine_drake.py": 4.1,
    "test_compliant_law.py": 4.0,
    "test_core_dop853.py": 3.3,
    "test_report.py": 3.3,
    "test_horizon.py": 3.2,
    "test_core_roots.py": 3.2,
    "test_reference_rim.py": 3.0,
    "test_makefile.py": 2.8,
    "test_docs_figures.py": 2.8,
    "test_write_faults.py": 2.7,
    "test_core_contacts.py": 2.7,
    "test_stall_guard.py": 2.6,
    "test_extras_ci.py": 2.5,
    "test_reference_end.py": 2.5,
    "test_cli.py": 2.1,
    "test_recording.py": 2.0,
    "test_warm_bytecode.py": 2.0,
}

# files whose tests start process pools in the test process
POOL_FILES = frozenset(
    {
        "test_readme_commands.py",
        "test_sweep.py",
        "test_sweep_parts.py",
        "test_sweep_heal.py",
        "test_fuzz_cli.py",
        "test_write_faults.py",
        "test_cli_inputs.py",
        "test_stress.py",
        "test_engine_isolation.py",
    }
)
# files that import JAX (when their tests run: none imports it when collected)
JAX_FILES = frozenset({"test_engine_mjx.py"})
# whether JAX was loaded once this process had collected the tests (conftest.py)
JAX_AT_COLLECTION = pytest.StashKey[bool]()


def file_rank(name: str) -> tuple[int, float]:
    """Where a test file (its name) goes: (group 0 pools, 1 JAX, 2 the rest; longest
    first within a group)."""
    group = 0 if name in POOL_FILES else 1 if name in JAX_FILES else 2
    return group, -FILE_SECONDS.get(name, 0.0)


def ordered(items: list) -> list:
    """The collected tests sorted by their file's rank; the tests of a file keep their
    order, and files of equal rank theirs (a stable sort)."""
    return sorted(items, key=lambda item: file_rank(Path(str(item.path)).name))


def jax_loaded() -> bool:
    """Whether this process has imported JAX (what harness.child_processes checks)."""
    return "jax" in sys.modules
