"""The branches paragraph of `harness compare` (when the reference ends
`simultaneous_impact`): which branch each run follows after the undecidable state and
how far it stays with it (harness.branches.follow), in at most 100 columns, and the same
as one sentence per run (the JSON's `branch.sentence`, the recording's summary)."""

from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

from ..branches.follow import FOLLOW_FACTOR, BranchFollow
from ..text import WIDTH, num, table

if TYPE_CHECKING:
    from . import CompareResult, EngineRun

LEFT = "left the reference before t_u: no branch"


def skipped_text(skipped: int) -> str:
    """' (s chatter-tail bounces skipped)' when the run passed over any."""
    return f" ({skipped} chatter-tail bounces skipped)" if skipped else ""


def decided_text(b: BranchFollow) -> str:
    """'yes' when the nearest branch is FOLLOW_FACTOR times nearer than every other,
    'no: tie' otherwise, '-' when there is no other branch."""
    if len(b.candidates) < 2:
        return "-"
    return "yes" if b.decided and b.runner_up is not None else "no: tie"


def branch_row(run: EngineRun) -> list[str]:
    """One run's row: nearest branch, its distance, the next branch and its distance,
    whether that is decided, the branch's impacts reproduced, skipped and listed, and the
    time of the first disagreement."""
    b = run.branch
    n, r = b.nearest, b.runner_up
    return [run.label, n.branch, num(n.distance, ".3g"),
            "-" if r is None else r.branch, "-" if r is None else num(r.distance, ".3g"),
            decided_text(b), str(n.impacts), str(n.skipped), str(n.of),
            num(n.until, ".7g")]  # fmt: skip


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
        f"{head}): it reproduces {n.impacts} of {n.branch}'s {n.of} impacts after t_u"
        f"{skipped_text(n.skipped)}, until t = {until}"
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
        rows.append(branch_row(run))
    if not rows and not left:
        return []
    header = ["simulator", "nearest", "distance", "next", "distance", "decided", "matched",
              "skipped", "of", "until [s]"]  # fmt: skip
    legend = (
        "distance: to the branch (docs/output.md), from the first impacts after t_u in "
        "windows plus the energy difference over E(t_u). decided: the nearest branch is "
        f"{FOLLOW_FACTOR:g} times nearer than the next (which law an engine follows: "
        "harness branches SCENE --engine E --dt ..., docs/laws.md). matched, skipped, of: "
        "the branch's impacts after t_u reproduced in order, its chatter-tail bounces "
        "passed over, and how many it lists; until: the first disagreement."
    )
    shown = [table(rows, header, align="llrlrlrrrr")] if rows else []
    explained = textwrap.wrap(legend, WIDTH) if rows else []  # the columns, when shown
    return [*textwrap.wrap(head, WIDTH), *shown, *left, *explained]
