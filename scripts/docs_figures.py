"""Re-measure every figure README.md and docs/api.md quote and write each between its
markers, `<!-- fig:NAME -->…<!-- /fig:NAME -->` (`make docs-figures`).

    demo          README: the output of `make demo`'s compare (the legend included)
    stress        README: the reference's verdicts on the hard cases, its worst energy gain
                  and the time its runs took together
    sweep         README: how the runs of its `sweep exponent` example end, the mapped c
    startup       README and docs/performance.md: `harness simulate pentagon-bounce
                  --json` against `python -c "import numpy"`, median of the ratios of
                  alternating pairs of whole processes (the package byte-compiled first,
                  as an installed one is)
    api-output    docs/api.md: what its example prints
    api-time      docs/api.md: the example's wall time

tests/test_docs_figures.py checks the copies against what the code prints (the numbers
exactly; timings are re-measured here, not asserted in tests).

Run: python scripts/docs_figures.py [--only NAME ...] [--pairs N]
"""

from __future__ import annotations

import argparse
import json
import re
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
API = ROOT / "docs" / "api.md"
PERFORMANCE = ROOT / "docs" / "performance.md"
DEMO = ["compare", "triangle-chatter", "--engine", "mujoco", "--engine", "pybullet"]
DEMO += ["--engine", "linear"]
STRESS = ["stress", "--engine", "reference", "--json"]
STARTUP = ["simulate", "pentagon-bounce", "--json"]
# README's sweep (its `## Commands` block), to a temporary folder
SWEEP = ["sweep", "exponent", "--gyration", "0.05:1:4", "--restitution", "0:1:5"]
SWEEP += ["--samples", "10", "--seed", "1", "--impact-law", "moreau", "--json"]
MARKER = re.compile(r"<!-- fig:(?P<name>[\w-]+) -->(?P<body>.*?)<!-- /fig:(?P=name) -->", re.S)


def harness(args: list[str]) -> str:
    """stdout of `python -m harness ARGS` run from the repository's root."""
    done = subprocess.run(
        [sys.executable, "-m", "harness", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout


def figure(text: str, name: str) -> str:
    """The text between the markers of figure `name` (KeyError when there are none)."""
    for m in MARKER.finditer(text):
        if m.group("name") == name:
            return m.group("body")
    raise KeyError(name)


def replace_figure(path: Path, name: str, body: str) -> None:
    text = path.read_text(encoding="utf-8")
    figure(text, name)  # the markers must be there
    new = MARKER.sub(
        lambda m: (
            m.group(0)
            if m.group("name") != name
            else f"<!-- fig:{name} -->{body}<!-- /fig:{name} -->"
        ),
        text,
    )
    path.write_text(new, encoding="utf-8")
    print(f"{path.relative_to(ROOT)}: {name}")


# ----------------------------------------------------------------------------- figures


def demo_block() -> str:
    """The demo's output as a fenced block (the block is the figure's body)."""
    return "\n```text\n" + harness(DEMO).rstrip("\n") + "\n```\n"


def stress_summary(doc: dict) -> str:
    """'reference `ok` on 14 of 14, energy gain ≤ 1.1e-14, 0.4 s together'."""
    rows = [r for r in doc["cases"] if r["engine"] == "reference"]
    ok = sum(r["verdict"] == "ok" for r in rows)
    gain = max(r["energy_gain"] for r in rows if r["energy_gain"] is not None)
    wall = sum(r["wall_time_s"] for r in rows)
    return f"reference `ok` on {ok} of {len(rows)}, energy gain ≤ {gain:.1e}, {wall:.1g} s together"


def sweep_summary(doc: dict) -> str:
    """What README's sweep shows: how its runs end and the range of the mapped c."""
    counts = {k: v for k, v in doc["counts"].items() if v}
    total = sum(counts.values())
    ends = ", ".join(f"{v} `{k}`" for k, v in counts.items())
    cs = [p["mean_c"] for p in doc["points"] if p["mean_c"] is not None]
    rng = f"{min(cs):.2f} … {max(cs):.2f}" if cs else "-"
    return (
        f"its {total} runs end {ends} (none `simultaneous_impact`: under Moreau's law "
        f"every simultaneous impact is resolved); {len(cs)} of {len(doc['points'])} cells "
        f"have a fitted mean c, from {rng}"
    )


def run_sweep() -> dict:
    import tempfile

    with tempfile.TemporaryDirectory() as out:
        return json.loads(harness([*SWEEP, "--out", out]))


def startup_ratio(pairs: int) -> tuple[float, float, float]:
    """(median ratio, median harness s, median numpy s) over `pairs` alternating runs
    (after one warm-up of each)."""
    cmd_a = [sys.executable, "-m", "harness", *STARTUP]
    cmd_b = [sys.executable, "-c", "import numpy"]

    def once(cmd: list[str]) -> float:
        t = time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, capture_output=True, check=True)
        return time.perf_counter() - t

    # the package's bytecode, as an installed package has it (pip compiles it; here
    # PYTHONDONTWRITEBYTECODE may be set, and every run would compile the sources again)
    packages = ("harness", "reference", "engines")
    subprocess.run([sys.executable, "-m", "compileall", "-q", *packages], cwd=ROOT, check=True)
    once(cmd_a), once(cmd_b)
    a, b = [], []
    for _ in range(pairs):
        a.append(once(cmd_a))
        b.append(once(cmd_b))
    ratio = statistics.median(x / y for x, y in zip(a, b, strict=True))
    return ratio, statistics.median(a), statistics.median(b)


def api_example() -> str:
    """The Python block of docs/api.md that precedes "Output (" (the example)."""
    text = API.read_text(encoding="utf-8")
    head = text.split("\nOutput (", 1)[0]
    return head.rsplit("```python\n", 1)[1].split("```", 1)[0]


def run_api_example() -> tuple[str, float]:
    t = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", api_example()], cwd=ROOT, capture_output=True, text=True, check=True
    )
    return done.stdout, time.perf_counter() - t


# ----------------------------------------------------------------------------- main


def load_average() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "?"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", action="append", help="this figure only (repeatable)")
    p.add_argument("--pairs", type=int, default=11, help="start-up: alternating pairs")
    args = p.parse_args(argv)
    want = set(args.only or ("demo", "stress", "sweep", "startup", "api"))
    if "demo" in want:
        replace_figure(README, "demo", demo_block())
    if "stress" in want:
        replace_figure(README, "stress", stress_summary(json.loads(harness(STRESS))))
    if "sweep" in want:
        replace_figure(README, "sweep", sweep_summary(run_sweep()))
    if "startup" in want:
        ratio, a, b = startup_ratio(args.pairs)
        replace_figure(README, "startup", f'{ratio:.2f}× `python -c "import numpy"`')
        replace_figure(
            PERFORMANCE,
            "startup",
            f"\n| `python -m harness {shlex.join(STARTUP)}`, {args.pairs} alternating pairs | "
            f"{load_average()} | {a:.3f} s | {b:.3f} s | {ratio:.2f}× |\n",
        )
    if "api" in want:
        out, wall = run_api_example()
        replace_figure(API, "api-output", "\n```text\n" + out.rstrip("\n") + "\n```\n")
        replace_figure(API, "api-time", f"{wall:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
