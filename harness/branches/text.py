"""The terminal text of `harness branches`: the undecidable state, then one row per
branch (energy after it, the next impacts, final status, t_f, c)."""

from __future__ import annotations

import textwrap

from ..text import WIDTH, column_tables, num, run_label, table


def format_spread(spread, label=str) -> str:
    """The report; `label` names contact k (v2, b1: GroundContacts.label)."""
    lines = [f"{spread.scene}: paper's rule until t_end = {spread.t_end:g}"]
    u = spread.undecidable
    if u is None:
        lines.append(
            f"no undecidable state: the paper's run ends {spread.paper.status} "
            f"({spread.paper.message}); every law gives the same run"
        )
        return "\n".join(lines)
    contacts = ", ".join(label(int(k)) for k in u["contacts"])
    lines.append(f"first undecidable state at t_u = {u['t']:.17g} s, contacts {contacts}")
    rows = []
    for b in [spread.paper, *spread.branches]:
        took = " ".join(label(int(r["contact"])) for r in b.impacts_at) or "-"
        first = b.next_impacts[0] if b.next_impacts else None
        rows.append([b.name, took, num(b.energy_after, ".6g"),
                     "-" if first is None else label(int(first["contact"])),
                     "-" if first is None else num(first["t"] - u["t"], ".2g"),
                     b.status, num(b.t_f, ".8g"), num(b.c, ".4g")])  # fmt: skip
    header = ["branch", "at t_u", "E after [J]", "next at", "next in [s]", "status", "t_f [s]",
              "c"]  # fmt: skip
    lines.append(table(rows, header, align="llrlrlrr"))
    legend = (
        "at t_u: the contacts that took an impulse at t_u; E after: energy above the resting "
        "level just after t_u; next at, next in: the contact of the first impact after t_u "
        "and the time from t_u to it (--json has the first 4); t_f: t_singularity, else "
        "the final time; c: the exponent of E = a (t_f − t)^c (runs reaching the singularity)"
    )
    lines += textwrap.wrap(legend, WIDTH)
    return "\n".join(lines)


def format_study(study, label=str) -> str:
    """The engines at the undecidable impact (harness.branches.engines): the distance of
    each run (engine and dt, columns) to each outcome (rows), then each run's verdict;
    `label` names contact k (v2, b1)."""
    if study.t_u is None:
        return f"{study.scene}: {study.message}"
    contacts = ", ".join(label(int(k)) for k in study.contacts)
    head = (
        f"{study.scene}: first undecidable state at t_u = {study.t_u:.17g} s, contacts "
        f"{contacts}; engines start {study.lead:.3g} a/U before it (a fixed-step engine half "
        f"a step earlier still), measured {study.after:.3g} a/U after it; U = max(√(g a), "
        "a/t_end)"
    )
    intro = (
        "Distance after the impact from each run (engine and dt, columns) to each outcome "
        "(rows; branches that reach the same state named together): the norm of the "
        "velocity, angular velocity and contact normal velocity differences over U; the "
        f"nearest two outcomes are {num(study.apart, '.3g')} apart"
    )
    lines = [*textwrap.wrap(head, WIDTH, subsequent_indent="  "), *textwrap.wrap(intro, WIDTH)]
    fixed = [[o.name] for o in study.outcomes]
    columns = [
        (run_label(r.engine, r.dt), [num(r.distances.get(o.name), ".3g") for o in study.outcomes])
        for r in study.runs
    ]
    lines += column_tables(["outcome"], fixed, columns, "l")
    for r in study.runs:
        why = f" ({r.reason})" if r.reason else ""
        ended = "" if r.status == "t_end" else f" (ended {r.status})"
        text = f"{run_label(r.engine, r.dt)}{ended}: {r.verdict}{why}"
        lines += textwrap.wrap(text, WIDTH, initial_indent="  ", subsequent_indent="    ")
    legend = (
        "follows L: L 3 times nearer than any other and its distance falling by half or more "
        "as dt falls tenfold; between L and M: the two within a factor 3 (docs/laws.md)"
    )
    lines += textwrap.wrap(legend, WIDTH)
    return "\n".join(lines)
