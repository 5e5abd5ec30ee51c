"""Write the bytecode of the installed modules that the project and its tests import:
`python -m tests.warm_bytecode` (run by `make setup` right after the install, at the
lowest priority, on the core the install leaves idle while the reference's core builds
on the other).

`make setup` installs the packages without their bytecode (pip's --no-compile): pip
would compile all of their ~12,000 modules, most of which nothing here imports (their own
tests, OpenGL, pybullet's example environments, ...).  Without bytecode each module is
compiled when it is first imported; in the test suite that is in every worker and every
process the tests start at the same time, before any has written it.  Here every module
named by an import statement in the project's and the tests' sources (at module level or
inside a function: the command line imports most of them where they are used) is
imported once, so that its bytecode, and that of the modules it imports, is written
beforehand.  A module that cannot be imported here (an engine's extra not installed) is
left to be compiled where it is used."""

from __future__ import annotations

import ast
import sys
import time
from pathlib import Path

from reference.process_exit import exit_now

ROOT = Path(__file__).resolve().parents[1]
SOURCE_FOLDERS = ("harness", "reference", "engines", "tests")


def imported_modules(source: str) -> set[str]:
    """The absolute module names an import statement in `source` names: `import a.b`
    gives a.b; `from a.b import c` gives a.b and a.b.c (c may be a submodule)."""
    names = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def third_party(names: set[str]) -> list[str]:
    """The names outside the standard library and the project's own folders, sorted."""
    left_out = {*SOURCE_FOLDERS, "scripts", "benchmarks", *sys.stdlib_module_names}
    return sorted(n for n in names if n.split(".")[0] not in left_out)


def project_imports(root: Path = ROOT) -> list[str]:
    """Every installed module the project's and the tests' sources import."""
    names = set()
    for folder in SOURCE_FOLDERS:
        for path in sorted((root / folder).rglob("*.py")):
            names |= imported_modules(path.read_text(encoding="utf-8"))
    return third_party(names)


def import_each(names: list[str]) -> tuple[int, int]:
    """Import each module (its bytecode written as it is compiled; a banner a library
    prints from C, such as PyBullet's, kept off the terminal: engines.quiet); returns
    (modules imported, names that are not importable modules here)."""
    from engines.quiet import quiet_import

    missing = 0
    for name in names:
        try:
            quiet_import(name)
        except Exception:  # an attribute, not a module; an extra not installed; no GPU
            missing += 1
    return len(names) - missing, missing


def main() -> int:
    t0 = time.perf_counter()
    before = len(sys.modules)
    imported, missing = import_each(project_imports())
    print(
        f"{len(sys.modules) - before} modules imported, their bytecode written where "
        f"missing ({imported} named by the sources, {missing} names not importable "
        f"here; {time.perf_counter() - t0:.0f} s)",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    exit_now(main())
