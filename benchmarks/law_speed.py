"""Paired speed of two trees of the exact reference under each impact law.

    python benchmarks/law_speed.py OTHER_TREE [--scene triangle-chatter ...]
        [--laws paper moreau] [--rounds 5] [--repeats 20]

Each round runs, in a fresh process per tree (the trees alternating, so that both see
the same load), each scene `repeats` times per law after an untimed warm-up run, and
keeps stats.impacts_per_s of every run.  Per scene and law the table gives, per tree,
the median over rounds of the rounds' medians (for this tree also their min … max);
the ratio of this tree to OTHER_TREE (median over rounds of the rounds' ratios of
medians, and their min … max); and the ratio of the rounds' best runs (median over
rounds: the least disturbed runs of a shared machine).  The load average before and
after is printed with it.  Each tree runs its own compiled core (build it first:
`python -m reference.core.aot`).  A benchmark, not a test: nothing here asserts a
speed.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys
from reference import ReferenceOptions, simulate
scenes, laws, repeats = sys.argv[1].split(","), sys.argv[2].split(","), int(sys.argv[3])
out = {}
for scene in scenes:
    for law in laws:
        opts = ReferenceOptions(impact_law=law)
        simulate(scene, options=opts)
        rates = []
        for _ in range(repeats):
            t = simulate(scene, options=opts)
            rates.append(t.stats.impacts_per_s)
        out[scene + " " + law] = {
            "rates": rates, "impacts": len(t.impacts), "status": t.status.value,
            "simultaneous": t.stats.get("simultaneous_impacts", -1),
        }
print(json.dumps(out))
"""


def run_tree(tree: Path, scenes: list[str], laws: list[str], repeats: int) -> dict:
    """One process of `tree`: per scene and law, impacts/s of `repeats` runs."""
    res = subprocess.run(
        [sys.executable, "-c", CHILD, ",".join(scenes), ",".join(laws), str(repeats)],
        cwd=tree, capture_output=True, text=True, check=True,
        env={"PYTHONPATH": str(tree), "OPENBLAS_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"},
    )  # fmt: skip
    return json.loads(res.stdout.strip().splitlines()[-1])


def summary(this: list[dict], other: list[dict]) -> dict:
    """Per-tree medians over rounds, the rounds' ratios of medians and of best runs."""
    med_a = [statistics.median(x["rates"]) for x in other]
    med_b = [statistics.median(x["rates"]) for x in this]
    ratios = [b / a for a, b in zip(med_a, med_b, strict=True)]
    best = [max(b["rates"]) / max(a["rates"]) for a, b in zip(other, this, strict=True)]
    return {
        "other": statistics.median(med_a),
        "this": statistics.median(med_b),
        "this_range": (min(med_b), max(med_b)),
        "ratio": statistics.median(ratios),
        "low": min(ratios),
        "high": max(ratios),
        "best": statistics.median(best),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("other", type=Path, help="the tree to pair against (e.g. main's)")
    ap.add_argument("--scene", nargs="+", default=["triangle-chatter"], dest="scenes")
    ap.add_argument("--laws", nargs="+", default=["paper", "moreau"])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args(argv)
    trees = {"this": ROOT, "other": args.other.resolve()}
    rounds: dict[str, list[dict]] = {"this": [], "other": []}
    load0 = os.getloadavg()
    for r in range(args.rounds):
        for name in ("other", "this") if r % 2 else ("this", "other"):
            rounds[name].append(run_tree(trees[name], args.scenes, args.laws, args.repeats))
    load1 = os.getloadavg()
    print(f"impacts/s, median over {args.rounds} rounds of each round's median of "
          f"{args.repeats} runs; load average (1, 5, 15 min) "
          f"{'/'.join(f'{x:.1f}' for x in load0)} before, "
          f"{'/'.join(f'{x:.1f}' for x in load1)} after")  # fmt: skip
    print(f"{'scene':18} {'law':7} {'other':>7} {'this':>7} {'this min..max':>15} "
          f"{'ratio':>6} {'min..max':>13} {'best':>6}  impacts")  # fmt: skip
    for key in rounds["this"][0]:
        s = summary([x[key] for x in rounds["this"]], [x[key] for x in rounds["other"]])
        last, last_other = rounds["this"][-1][key], rounds["other"][-1][key]
        scene, law = key.rsplit(" ", 1)
        lo, hi = s["this_range"]
        print(f"{scene:18} {law:7} {s['other']:7.0f} {s['this']:7.0f} {lo:7.0f}..{hi:<7.0f}"
              f" {s['ratio']:6.3f} {s['low']:6.3f}..{s['high']:<6.3f} {s['best']:6.3f}  "
              f"{last['impacts']} ({last['simultaneous']} simultaneous, {last['status']}; "
              f"other: {last_other['impacts']}, {last_other['status']})")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
