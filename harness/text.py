"""Plain-text renderings of results for the terminal."""

from __future__ import annotations

import math
from typing import Any

from reference.linear._text import table  # noqa: F401  (the one table formatter)
from reference.trajectory import Trajectory


def format_simulate(traj: Trajectory) -> str:
    e = traj.energy
    lines = [
        f"engine      {traj.engine}",
        f"scene       {traj.scene}",
        f"status      {traj.status.value}: {traj.message}",
        f"t_final     {traj.t_final:.17g}",
    ]
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
        lines.append("first impacts (t, contact, impulse):")
        for ev in traj.impacts[:8]:
            lines.append(f"  {ev.t:.15f}  {ev.contact:4d}  {ev.impulse:.6e}")
    return "\n".join(lines)


def _simultaneous_text(traj: Trajectory) -> str:
    """' (35 in simultaneous impacts resolved in the loop)': the reference's count of
    simultaneous impacts its law resolved (RunStats.simultaneous_impacts), when any."""
    n = traj.stats.get("simultaneous_impacts", 0) if traj.stats else 0
    return f" ({n} simultaneous impacts resolved by the law in the loop)" if n else ""


# Bidirectional-text overrides and isolates: invisible, but they reorder what follows.
_BIDI = set(range(0x202A, 0x202F)) | set(range(0x2066, 0x206A))


def terminal_safe(text: str) -> str:
    r"""`text` with every control character escaped (\x1b, \u202e, ...), except the line
    breaks and tabs of multi-line text: a name read from a file cannot move the cursor,
    retitle the terminal or reorder a line (the CLI's every text output passes here)."""
    return "".join(_escaped(ch) for ch in text)


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
