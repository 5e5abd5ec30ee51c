"""Plain-text renderings of results for the terminal."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable
from typing import Any

from reference.linear._text import table  # noqa: F401  (the one table formatter)
from reference.trajectory import Trajectory

WIDTH = 100


def format_simulate(
    traj: Trajectory,
    scale: float | None = None,
    wide: bool = False,
    label: Callable[[int], str] = str,
) -> str:
    """The run's summary, one field a line; a long status is wrapped at WIDTH columns
    (`wide`: on one line).  `scale`: the --scale the scene's initial state was scaled by;
    `label`: a contact's name (v2, b1: GroundContacts.label)."""
    e = traj.energy
    lines = [f"engine      {traj.engine}", f"scene       {traj.scene}"]
    if scale is not None:
        lines.append(
            f"scaled      by ε = {scale:g}: q × ε² = {scale * scale:g}, p × ε = {scale:g} "
            "(the paper's scaling)"
        )
    status = f"status      {traj.status.value}: {traj.message}"
    lines += [status] if wide else textwrap.wrap(status, WIDTH, subsequent_indent=" " * 12)
    lines += [f"t_final     {traj.t_final:.17g}"]
    if traj.impact_law is not None:
        lines.append(f"impact law  {impact_law_text(traj.impact_law, traj.simultaneity_window)}")
    if traj.t_singularity is not None:
        lines.append(f"t_sing      {traj.t_singularity:.17g}")
    lines += [
        f"impacts     {len(traj.impacts)}{_simultaneous_text(traj)}",
        f"samples     {traj.n_samples}",
        f"energy      {e[0]:.6e} -> {e[-1]:.6e}" if traj.n_samples else "energy      -",
        f"wall time   {traj.stats.get('wall_time_s', float('nan')):.3f} s",
    ]
    if traj.impacts:
        lines.append("first impacts:")
        lines.append(
            table(
                [
                    [f"{ev.t:.15f}", label(ev.contact), f"{ev.impulse:.6e}"]
                    for ev in traj.impacts[:8]
                ],
                ["t [s]", "contact", "impulse [N s]"],
                align="rrr",
            )
        )
    return "\n".join(lines)


def quantile_cells(q: list[float] | None) -> list[str]:
    """[10 %, 90 %] of [10 %, 50 %, 90 %] quantiles of matched counts as two cells
    ('-', '-' without them)."""
    if not q:
        return ["-", "-"]
    return [f"{q[0]:.0f}", f"{q[2]:.0f}"]


def run_label(engine: str, dt: float | None) -> str:
    """'mujoco 1e-03' for a fixed-step run, the engine's name for an event-driven one:
    how every command names a run."""
    return engine if dt is None else f"{engine} {dt:.0e}"


def column_widths(rows: list[list[str]], header: list[str]) -> list[int]:
    """Each column's width in `table`: its longest cell or its header."""
    return [max([len(h), *(len(r[i]) for r in rows)]) for i, h in enumerate(header)]


def fit_table(rows: list[list[str]], header: list[str], align: str, width: int = WIDTH) -> str:
    """`table`, with the first column's long cells broken over lines of their own
    (`wrap_first_column`) when the table would be wider than `width`: a long name."""
    text = table(rows, header, align)
    if max(len(line) for line in text.splitlines()) <= width:
        return text
    return table(wrap_first_column(rows, header, width), header, align)


def wrap_first_column(rows: list[list[str]], header: list[str], width: int) -> list[list[str]]:
    """rows with each first cell longer than the room `width` leaves it (the other
    columns at their widths, two spaces apart) broken over lines of its own, the row's
    other cells on its first line: a long name keeps a table within `width` columns."""
    others = sum(w + 2 for w in column_widths(rows, header)[1:])
    room = max(width - others, len(header[0]), 8)
    out = []
    for row in rows:
        pieces = textwrap.wrap(row[0], room) or [""]  # at spaces and hyphens, else cut
        out.append([pieces[0], *row[1:]])
        out += [[p, *([""] * (len(row) - 1))] for p in pieces[1:]]
    return out


def column_tables(
    head: list[str],
    fixed: list[list[str]],
    columns: list[tuple[str, list[str]]],
    align: str,
    width: int = WIDTH,
) -> list[str]:
    """Tables of the rows `fixed` (header `head`, aligned by `align`) beside the named
    `columns` (name, one cell a row; right-aligned), as many tables as needed for each
    to fit `width` columns, each repeating the fixed columns."""
    used = sum(w + 2 for w in column_widths(fixed, head))
    chunks: list[list[tuple[str, list[str]]]] = [[]]
    room = used
    for name, cells in columns:
        w = column_widths([[c] for c in cells], [name])[0] + 2
        if chunks[-1] and room + w > width + 2:
            chunks.append([])
            room = used
        chunks[-1].append((name, cells))
        room += w
    return [
        table(
            [[*f, *(c[1][i] for c in chunk)] for i, f in enumerate(fixed)],
            [*head, *(c[0] for c in chunk)],
            align + "r" * len(chunk),
        )  # fmt: skip
        for chunk in chunks
        if chunk
    ]


def _simultaneous_text(traj: Trajectory) -> str:
    """' (35 in simultaneous impacts resolved in the loop)': the reference's count of
    simultaneous impacts its law resolved (RunStats.simultaneous_impacts), when any."""
    n = traj.stats.get("simultaneous_impacts", 0) if traj.stats else 0
    return f" ({n} simultaneous impacts resolved by the law in the loop)" if n else ""


# Bidirectional-text overrides and isolates: invisible, but they reorder what follows.
_BIDI = set(range(0x202A, 0x202F)) | set(range(0x2066, 0x206A))


def terminal_safe(text: str, encoding: str | None = None) -> str:
    r"""`text` with every control character escaped (\x1b, \u202e, ...), except the line
    breaks and tabs of multi-line text: a name read from a file cannot move the cursor,
    retitle the terminal or reorder a line (the CLI's every text output passes here).
    Symbols stdout's encoding (`encoding`) cannot show are spelled in ASCII (`ascii_text`)."""
    safe = "".join(_escaped(ch) for ch in text)
    return safe if _can_show(safe, encoding) else ascii_text(safe)


# The symbols of the tables and their ASCII spellings, for a stdout that cannot show them.
ASCII_SYMBOLS = {
    "ρ": "rho", "γ": "gamma", "Δ": "Delta", "α": "alpha", "ε": "eps", "λ": "lambda",
    "ψ": "psi", "β": "beta", "τ": "tau", "µ": "u", "μ": "u", "≈": "~", "±": "+-",
    "–": "-", "—": "-", "−": "-", "×": "x", "·": "*", "²": "^2", "³": "^3", "≤": "<=",
    "≥": ">=", "…": "...", "→": "->", "⁻": "-", "⁺": "+", "ᵢ": "_i", "√": "sqrt",
}  # fmt: skip


def ascii_text(text: str) -> str:
    """`text` with ASCII_SYMBOLS spelled out and any other non-ASCII character as '?'."""
    spelled = "".join(ASCII_SYMBOLS.get(ch, ch) for ch in text)
    return spelled.encode("ascii", "replace").decode("ascii")


def _can_show(text: str, encoding: str | None) -> bool:
    import sys

    encoding = encoding or getattr(sys.stdout, "encoding", None) or "utf-8"
    try:
        text.encode(encoding)
    except (UnicodeEncodeError, LookupError):
        return False
    return True


def _escaped(ch: str) -> str:
    code = ord(ch)
    if ch in "\n\t" or not (code < 32 or 127 <= code < 160 or code in _BIDI):
        return ch
    return f"\\x{code:02x}" if code < 256 else f"\\u{code:04x}"


def impact_law_text(law: str, window: float | None) -> str:
    """'moreau (simultaneity window 0)': the law of simultaneous impacts a run applied."""
    return f"{law} (simultaneity window {window or 0:g})"


def num(x: Any, spec: str = ".3g") -> str:
    """A table cell's text: '-' for None or a non-finite float, yes/no for a bool, ints
    as they are, floats by `spec`, anything else by str()."""
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        return format(x, spec) if math.isfinite(x) else "-"
    return str(x)
