"""The terminal text of `harness branches`: the undecidable state, then one row per
branch (energy after it, the next impacts, final status, t_f, c)."""

from __future__ import annotations

from ..text import num, table


def format_spread(spread) -> str:
    lines = [f"{spread.scene}: paper's rule until t_end = {spread.t_end:g}"]
    u = spread.undecidable
    if u is None:
        lines.append(
            f"no undecidable state: the paper's run ends {spread.paper.status} "
            f"({spread.paper.message}); every law gives the same run"
        )
        return "\n".join(lines)
    lines.append(f"first undecidable state at t_u = {u['t']:.17g}, contacts {u['contacts']}")
    rows = []
    for b in [spread.paper, *spread.branches]:
        took = ",".join(str(r["contact"]) for r in b.impacts_at) or "-"
        nxt = " ".join(f"{r['contact']}@{r['t'] - u['t']:.3g}" for r in b.next_impacts) or "-"
        rows.append([b.name, took, num(b.energy_after, ".6g"), nxt, b.status,
                     num(b.t_f, ".10g"), num(b.c, ".4g")])  # fmt: skip
    header = ["branch", "impulses at t_u", "E after", "next impacts (contact@t - t_u)",
              "status", "t_f", "c"]  # fmt: skip
    lines.append(table(rows, header, align="lllllrr"))
    lines.append(
        "E after: energy above the resting level just after t_u; t_f: t_singularity, else "
        "the final time; c: the exponent of E = a (t_f - t)^c (runs reaching the "
        "singularity)"
    )
    return "\n".join(lines)
