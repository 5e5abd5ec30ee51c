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


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _resolve(importer: str, is_package: bool, node: ast.ImportFrom | ast.Import) -> set[str]:
    """The modules of the package an import statement names (absolute, dotted), with
    `from X import name` counted as X.name when that is a module of the package."""
    if isinstance(node, ast.Import):
        return {alias.name for alias in node.names}
    base = importer.split(".") if is_package else importer.split(".")[:-1]
    if node.level:
        base = base[: len(base) - (node.level - 1)]
        head = ".".join([*base, node.module] if node.module else base)
    else:
        head = node.module or ""
    return {head} | {f"{head}.{alias.name}" for alias in node.names}


def _runtime_nodes(tree: ast.AST):
    """Every node of the tree but those under `if TYPE_CHECKING:` (imported for the type
    checker only, never at run time)."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            continue
        yield node
        yield from _runtime_nodes(node)


def import_graph(package: str = "reference") -> dict[str, set[str]]:
    """module → the package's modules it imports, at module level or inside functions
    (a function-level import is a cycle all the same: it only moves the failure)."""
    files = {_module_name(p): p for p in (ROOT / package).rglob("*.py")}
    graph = {}
    for name, path in files.items():
        deps = set()
        for node in _runtime_nodes(ast.parse(path.read_text())):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                deps |= _resolve(name, path.name == "__init__.py", node)
        graph[name] = {d for d in deps if d in files and d != name}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import cycles of a graph (one path per strongly connected component with
    more than one module; Tarjan's algorithm)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def _package_edges(graph):
    """The graph without the edges of a package to its own modules (a package's
    __init__ re-exporting its modules is not a cycle: they never import it back for
    what it re-exports)."""
    return {m: {d for d in deps if not d.startswith(m + ".")} for m, deps in graph.items()}


def test_the_reference_package_has_no_import_cycle():
    assert cycles(_package_edges(import_graph("reference"))) == []


def test_the_cycle_check_finds_a_function_level_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == [["a", "b", "c"]]
    found = import_graph("reference")
    assert "reference.core.laws" in found["reference.scene"]
