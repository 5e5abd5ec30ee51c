"""The terminal text of `harness branches`: the undecidable state, then one row per
branch (energy after it, the next impacts, final status, t_f, c)."""

from __future__ import annotations

import textwrap

from ..text import num, table

WIDTH = 100  # the terminal text fits this many columns


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
        first = b.next_impacts[:1]
        nxt = "".join(f"{label(int(r['contact']))} +{r['t'] - u['t']:.2g} s" for r in first)
        rows.append([b.name, took, num(b.energy_after, ".6g"), nxt or "-", b.status,
                     num(b.t_f, ".8g"), num(b.c, ".4g")])  # fmt: skip
    header = ["branch", "at t_u", "E after t_u", "next impact", "status", "t_f [s]", "c"]
    lines.append(table(rows, header, align="lllllrr"))
    legend = (
        "at t_u: the contacts that took an impulse at t_u; E after t_u: energy above the "
        "resting level just after t_u; next impact: the first impact after t_u, its contact "
        "and its time after t_u (--json has the first 4); t_f: t_singularity, else the final "
        "time; c: the exponent of E = a (t_f − t)^c (runs reaching the singularity)"
    )
    lines += textwrap.wrap(legend, WIDTH)
    return "\n".join(lines)


def format_study(study) -> str:
    """The engines at the undecidable impact (harness.branches.engines): one row per
    engine and dt, its distance to each outcome and the verdict."""
    if study.t_u is None:
        return f"{study.scene}: {study.message}"
    head = (
        f"{study.scene}: first undecidable state at t_u = {study.t_u:.17g} s, contacts "
        f"{study.contacts}; engines start {study.lead:.3g} a/U before it (a fixed-step "
        f"engine half a step earlier still), measured {study.after:.3g} a/U after it"
    )
    outcomes = (
        "outcomes: "
        + "; ".join(f"({i + 1}) {o.name}" for i, o in enumerate(study.outcomes))
        + f" (the nearest two {num(study.apart, '.3g')} apart)"
    )
    lines = [*textwrap.wrap(head, WIDTH, subsequent_indent="  "),
             *textwrap.wrap(outcomes, WIDTH, subsequent_indent="  ")]  # fmt: skip
    labels = sorted(((o.name, f"({i + 1})") for i, o in enumerate(study.outcomes)),
                    key=lambda kv: -len(kv[0]))  # fmt: skip
    rows = []
    for r in study.runs:
        dist = [num(r.distances.get(o.name), ".3g") for o in study.outcomes]
        text = r.verdict
        for name, label in labels:
            text = text.replace(name, label)
        rows.append([r.engine, num(r.dt, "g"), *dist, text])
    header = ["engine", "dt [s]", *(f"({i + 1})" for i in range(len(study.outcomes))), "verdict"]
    lines.append(table(rows, header, align="lr" + "r" * len(study.outcomes) + "l"))
    legend = (
        "(i): distance to outcome i after the impact: the norm of the velocity, angular "
        "velocity and contact normal velocity differences in units of max(sqrt(g a), "
        "a/t_end), U that unit; follows L: L 3 times nearer than any other and its distance "
        "falling by half or more as dt falls tenfold (docs/laws.md)"
    )
    lines += textwrap.wrap(legend, WIDTH)
    return "\n".join(lines)
