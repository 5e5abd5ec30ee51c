"""The branches paragraph of `harness compare` (when the reference ends
`simultaneous_impact`): which branch each run follows after the undecidable state and
how far it stays with it (harness.branches.follow), in at most 100 columns, and the same
as one sentence per run (the JSON's `branch.sentence`, the recording's summary)."""

from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

from ..branches.follow import FOLLOW_FACTOR, BranchFollow
from ..text import num, table

if TYPE_CHECKING:
    from . import CompareResult, EngineRun

WIDTH = 100
LEFT = "left the reference before t_u: no branch"


def impacts_text(c) -> str:
    """'3/8', or '0+89/89' when s chatter-tail bounces were skipped (as `impacts`)."""
    return f"{c.impacts}{f'+{c.skipped}' if c.skipped else ''}/{c.of}"


def runner_up_text(b: BranchFollow) -> str:
    """'sequential 1.56', with '≈ ' before it when the choice is not decided."""
    r = b.runner_up
    if r is None:
        return "≈ every branch" if len(b.candidates) > 1 else "-"
    return f"{'' if b.decided else '≈ '}{r.branch} {r.distance:.3g}"


def branch_sentence(run: EngineRun) -> str | None:
    """The run's branch as one sentence with the numbers (None without one)."""
    b = run.branch
    if b is None:
        return None
    if not b.followed_reference:
        return f"{run.label} {LEFT}."
    n, r = b.nearest, b.runner_up
    if r is None and len(b.candidates) > 1:
        head = f"{run.label} is as near to every branch (distance {n.distance:.3g}: undecided"
    elif r is None or b.decided:
        head = f"{run.label} is nearest to {n.branch} (distance {n.distance:.3g}"
        head += "" if r is None else f"; next {r.branch} {r.distance:.3g}"
    else:
        head = (f"{run.label} is as near to {n.branch} as to {r.branch} (distance "
                f"{n.distance:.3g} and {r.distance:.3g}: undecided")  # fmt: skip
    until = "-" if n.until is None else f"{n.until:.7g} s"
    text = (
        f"{head}): it reproduces {impacts_text(n)} of {n.branch}'s impacts after t_u, "
        f"until t = {until}"
    )
    return text + "."


def branch_lines(result: CompareResult) -> list[str]:
    """The paragraph under the verdict table; [] when the reference reached no
    undecidable state."""
    spread = result.spread
    if spread is None or spread.undecidable is None:
        return []
    u = spread.undecidable
    contacts = ", ".join(result.scene.contacts.label(int(k)) for k in u["contacts"])
    head = (
        f"After the undecidable state at t_u = {u['t']:.7g} s ({contacts}) the reference "
        f"goes on under each law (harness branches {result.scene.name}): the branch that each "
        "run stays on, nearest by its next impacts and its energy:"
    )
    rows, left = [], []
    for run in result.runs:
        b = run.branch
        if b is None:
            continue
        if not b.followed_reference:
            left.append(f"{run.label}: {LEFT}")
            continue
        n = b.nearest
        rows.append([run.label, n.branch, num(n.distance, ".3g"), runner_up_text(b),
                     impacts_text(n), num(n.until, ".7g"),
                     "yes" if b.followed_reference else "no"])  # fmt: skip
    if not rows and not left:
        return []
    header = ["simulator", "branch", "d", "next nearest", "impacts", "until [s]", "on ref"]
    legend = (
        "d: distance to the branch (docs/output.md): the first "
        "impacts after t_u in windows plus the energy difference over E(t_u); ≈: no branch "
        f"{FOLLOW_FACTOR:g} times nearer than the next (which law an engine follows: "
        "harness branches SCENE --engine E --dt ..., docs/laws.md). impacts: k+s/N of "
        "the branch's impacts after t_u reproduced in order (s chatter tails skipped), "
        "until the first disagreement. on ref: the run had not diverged from the "
        "reference before t_u."
    )
    shown = [table(rows, header, align="llrlrrl")] if rows else []
    return [*textwrap.wrap(head, WIDTH), *shown, *left, *textwrap.wrap(legend, WIDTH)]
