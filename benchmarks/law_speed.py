"""Paired speed of two trees of the exact reference under each impact law.

    python benchmarks/law_speed.py OTHER_TREE [--scene triangle-chatter]
        [--laws paper moreau] [--rounds 5] [--repeats 20]

Each round runs, in a fresh process per tree (the trees alternating, so that both see
the same load), the scene `repeats` times per law after an untimed warm-up run, and
takes the median of stats.impacts_per_s; the table gives, per law and tree, the median
over rounds, and the ratio of this tree to OTHER_TREE with its spread over rounds.
Each tree runs its own compiled core (build it first: `python -m reference.core.aot`).
A benchmark, not a test: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, statistics, sys
from reference import ReferenceOptions, simulate
scene, laws, repeats = sys.argv[1], sys.argv[2].split(","), int(sys.argv[3])
out = {}
for law in laws:
    opts = ReferenceOptions(impact_law=law)
    simulate(scene, options=opts)
    rates, impacts, simultaneous = [], 0, 0
    for _ in range(repeats):
        t = simulate(scene, options=opts)
        rates.append(t.stats.impacts_per_s)
        impacts = len(t.impacts)
        simultaneous = t.stats.get("simultaneous_impacts", -1)
    out[law] = {"rate": statistics.median(rates), "impacts": impacts,
                "simultaneous": simultaneous, "status": t.status.value}
print(json.dumps(out))
"""


def run_tree(tree: Path, scene: str, laws: list[str], repeats: int) -> dict:
    """One process of `tree`: per law, the median impacts/s over `repeats` runs."""
    res = subprocess.run(
        [sys.executable, "-c", CHILD, scene, ",".join(laws), str(repeats)],
        cwd=tree, capture_output=True, text=True, check=True,
        env={"PYTHONPATH": str(tree), "OPENBLAS_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"},
    )  # fmt: skip
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("other", type=Path, help="the tree to pair against (e.g. main's)")
    ap.add_argument("--scene", default="triangle-chatter")
    ap.add_argument("--laws", nargs="+", default=["paper", "moreau"])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args(argv)
    trees = {"this": ROOT, "other": args.other.resolve()}
    rounds: dict[str, list[dict]] = {"this": [], "other": []}
    for r in range(args.rounds):
        for name in ("other", "this") if r % 2 else ("this", "other"):
            rounds[name].append(run_tree(trees[name], args.scene, args.laws, args.repeats))
    print(f"{args.scene}: median impacts/s over {args.rounds} rounds of {args.repeats} runs")
    print(f"{'law':12} {'other':>12} {'this':>12} {'ratio':>7} {'min..max ratio':>16}  impacts")
    for law in args.laws:
        a = [x[law]["rate"] for x in rounds["other"]]
        b = [x[law]["rate"] for x in rounds["this"]]
        ratios = [bi / ai for ai, bi in zip(a, b, strict=True)]
        last = rounds["this"][-1][law]
        print(f"{law:12} {statistics.median(a):12.0f} {statistics.median(b):12.0f} "
              f"{statistics.median(ratios):7.3f} {min(ratios):7.3f}..{max(ratios):<7.3f}  "
              f"{last['impacts']} ({last['simultaneous']} simultaneous, {last['status']}; "
              f"other: {rounds['other'][-1][law]['status']})")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
