"""How the package's modules depend on each other (docs/architecture.md)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def imported_modules(path: Path) -> set[str]:
    """Every module a file imports, anywhere in it (relative imports keep their dots)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            found.add("." * node.level + (node.module or ""))
    return found


def test_the_compiled_core_access_imports_nothing_of_the_package():
    # reference.geometry imports reference.compiled: anything compiled imported from the
    # package (even inside a function) would close a cycle through scene and simulate
    own = imported_modules(ROOT / "reference" / "compiled.py")
    assert not {m for m in own if m.startswith((".", "reference"))}, own
