"""Plain-text tables for the analyses' terminal output (no dependency on the harness)."""

from __future__ import annotations


def table(rows: list[list[str]], header: list[str], align: str | None = None) -> str:
    """Columns separated by two spaces; `align` has one letter per column, "l" (left)
    or "r" (right, the default for every column)."""
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows, strict=False)]
    align = align or "r" * len(widths)
    fmt = "  ".join(
        f"{{:{'<' if a == 'l' else '>'}{w}}}" for a, w in zip(align, widths, strict=True)
    )
    out = [fmt.format(*header), fmt.format(*["-" * w for w in widths])]
    out += [fmt.format(*[str(x) for x in r]) for r in rows]
    return "\n".join(line.rstrip() for line in out)
