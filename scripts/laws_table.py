"""The table of docs/laws.md ("The answer"): which impact law each engine follows at each
suite landing, from the JSON of `harness branches --suite --engine … --json`.

    harness branches --suite --engine mujoco … --dt 1e-3 --dt 1e-4 --dt 1e-5 --json > s.json
    python scripts/laws_table.py s.json

One row per engine, one column per landing; a cell gives the verdict at each dt (coarse
to fine) and, for the law it names, the distance at each dt.  Markdown on stdout.
"""

from __future__ import annotations

import json
import sys

SHORT = {"follows": "follows", "between": "between", "none of the laws": "none", "undecided": "?"}


def short_name(outcome: str) -> str:
    """'compliant = compliant-mass' -> 'compliant' (an outcome named by its first branch)."""
    return outcome.split(" = ")[0]


def verdict_word(verdict: str) -> str:
    """'follows moreau' -> 'follows', 'between a and b' -> 'between'."""
    for key, word in SHORT.items():
        if verdict.startswith(key):
            return word
    return verdict


def cell(runs: list[dict]) -> str:
    """One engine on one landing: the nearest law at the finest dt, its distance at each
    dt, and the verdicts."""
    runs = sorted(runs, key=lambda r: -(r["dt"] or 0.0))
    measured = [r for r in runs if r["distances"]]
    if not measured:
        return "not measured"
    nearest = min(measured[-1]["distances"], key=measured[-1]["distances"].get)
    dists = " / ".join(f"{r['distances'].get(nearest, float('nan')):.2g}" for r in measured)
    words = [verdict_word(r["verdict"]) for r in measured]
    verdicts = words[0] if len(set(words)) == 1 else ", ".join(words)
    name = short_name(nearest)
    bold = f"**{name}**" if words[-1] == "follows" else name
    return f"{bold} {dists}: {verdicts}"


def table(doc: dict) -> str:
    studies = doc["studies"]
    engines = list(dict.fromkeys(r["engine"] for s in studies for r in s["runs"]))
    head = "| engine | " + " | ".join(s["scene"].removeprefix("landing-") for s in studies)
    lines = [head + " |", "|---" * (len(studies) + 1) + "|"]
    for engine in engines:
        cells = [cell([r for r in s["runs"] if r["engine"] == engine]) for s in studies]
        lines.append(f"| {engine} | " + " | ".join(cells) + " |")
    apart = " / ".join(f"{s['outcomes_apart']:.2g}" for s in studies)
    lines.append("")
    lines.append(f"Nearest two outcomes apart, per landing: {apart}.")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python scripts/laws_table.py BRANCHES.json", file=sys.stderr)
        return 2
    with open(argv[0], encoding="utf-8") as f:
        print(table(json.load(f)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
