"""Speed of the exact reference against its targets (`make bench`).

    .venv/bin/python benchmarks/reference_speed.py [--repeats 5] [--only TEXT ...]
        [--json FILE] [--no-startup] [--no-sweep]

Every figure is a median over `repeats` runs (short runs: as many as add up to
MIN_TIMED_S) in one process after an untimed warm-up run (compilation and loading are
never timed: `stats.compile_s` says what they cost), on one core when the machine lets
us pin it, with the load average printed before and after.  Printed as one table per
target, each row with its target and whether it is met:

1. runs to their end, impacts/s (stats.impacts_per_s): every built-in scene; generic
   tumbling scenes (n = 3 … 10,000, γ = 0, 0.5, 1, flat and three-point ground, fast
   spin); target ≥ 100,000/s, and ≥ 300,000/s for plain bouncing (γ = 1, no contact
   phase), fast spin included;
2. event-search iterations per impact on fast-spinning scenes, target ≤ 3;
3. contact phases: time per phase (the loop run one step per call, each contact step
   timed, the cost of an empty call taken out), and that time without the integrator's
   right-hand side evaluations (their count × the measured cost of one), target ≤ 20 µs;
4. start-up of whole processes against `python -c "import numpy"`: `harness scenes`
   ≤ 3×, `harness simulate` of a short built-in scene ≤ 6×;
5. sweeps: the reference against the linear model per run on a subgrid of the paper's
   exponent map, target ≤ 5×, and the full 21 × 21 × 100 map estimated on 2 cores,
   target ≤ 5 min.

This is a benchmark, not a test: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # no BLAS threads spinning beside us

from harness.scenes import builtin_names, resolve_scene  # noqa: E402
from reference import ReferenceOptions, Scene, simulate  # noqa: E402
from reference.scene import scene_from_dict  # noqa: E402


@dataclass
class Row:
    case: str
    impacts: int
    status: str
    wall_s: float
    stats: object

    @property
    def rate(self) -> float:
        return self.impacts / self.wall_s if self.wall_s > 0 else math.inf


# ----------------------------------------------------------------------------- scenes


def tumbling(
    n: int, gamma: float, ground: str = "flat", rho: float = 0.45, scale: float = 1.0
) -> Scene:
    """A tilted polygon dropped with a wobble (linear coordinates, both × scale), run to
    its end or to 20,000 impacts."""
    return scene_from_dict(
        {
            "name": f"n{n}-g{gamma:g}-{ground}",
            "restitution": gamma,
            "body": {"n": n, "gyration": rho},
            "ground": {"kind": ground, "bump_radius": 0.5},
            "initial": {
                "q": [0.012 * scale, -0.007 * scale, 0.05 * scale],
                "p": [0.2 * scale, -0.15 * scale, -0.5 * scale],
            },
            "run": {"t_end": 1e4, "max_impacts": 20_000},
        }
    )


def fast_spin(n: int, gamma: float, spin: float = 20.0, alpha: float = 0.02) -> Scene:
    """A polygon tilted by α spinning fast about the vertical, dropped from a little
    above its lowest vertex."""
    return scene_from_dict(
        {
            "name": f"spin-n{n}-g{gamma:g}",
            "restitution": gamma,
            "body": {"n": n, "gyration": 0.5},
            "initial": {
                "position": [0.0, 0.0, math.sin(alpha) + 0.01],
                "rotation_vector": [alpha, 0.0, 0.0],
                "velocity": [0.0, 0.0, -0.1],
                "angular_velocity": [0.0, 0.3, spin],
            },
            "run": {"t_end": 1e4, "max_impacts": 20_000},
        }
    )


def cases() -> dict[str, Scene]:
    out = {f"builtin {name}": resolve_scene(name) for name in builtin_names()}
    # a simultaneous impact resolved by a law inside the loop (35 of its 150 impacts)
    out["builtin triangle-chatter moreau"] = resolve_scene("triangle-chatter").with_impact_law(
        "moreau"
    )
    for n in (3, 10, 100, 1000, 10_000):
        for gamma in (0.0, 0.5, 1.0):
            out[f"tumbling n={n} γ={gamma:g} flat"] = tumbling(n, gamma)
    for gamma in (0.0, 0.5, 1.0):  # (n plays no part on the three-point ground)
        out[f"tumbling γ={gamma:g} three-point"] = tumbling(3, gamma, "three_point")
        # a gentler drop, so that elastic bouncing stays on the bumps for 1,400 impacts
        # (the full drops tip the rim to the floor plane under the bumps, `left_model`,
        # after 4 and 3 impacts at γ = 0.5 and 1; γ = 0 reaches the singularity)
        out[f"tumbling γ={gamma:g} three-point ×0.03"] = tumbling(
            3, gamma, "three_point", scale=0.03
        )
    for n in (3, 7, 16, 100):
        for gamma in (0.5, 1.0):
            out[f"fast spin n={n} γ={gamma:g}"] = fast_spin(n, gamma)
    return out


# ----------------------------------------------------------------------------- timing


# A run shorter than MIN_TIMED_S / repeats is repeated until its timed runs add up to
# MIN_TIMED_S (at most MAX_REPEATS runs): five runs of 10 µs are 50 µs of timing, at
# the mercy of the scheduler and of what the case before left in the caches.
MIN_TIMED_S = 0.05
MAX_REPEATS = 5001


def measure(name: str, scene: Scene, repeats: int) -> Row:
    """Median wall time of the run itself (stats.wall_time_s) after a warm-up, over
    `repeats` runs or as many as MIN_TIMED_S takes; a large sample spacing, so the
    figure is the events' cost (samples at every event remain)."""
    opts = ReferenceOptions(sample_dt=scene.run.t_end)
    warm = simulate(scene, options=opts).stats.wall_time_s
    repeats = max(repeats, min(MAX_REPEATS, math.ceil(MIN_TIMED_S / max(warm, 1e-9))))
    walls, traj = [], None
    for _ in range(repeats):
        traj = simulate(scene, options=opts)
        walls.append(traj.stats.wall_time_s)
    return Row(name, len(traj.impacts), traj.status.value, statistics.median(walls), traj.stats)


def rhs_cost_s() -> float:
    """Seconds per right-hand-side evaluation of a held motion (one contact), timed in a
    compiled loop of a million evaluations."""
    import numpy as np
    from numba import njit

    from reference.core.held import held_rhs, new_work
    from reference.simulate import make_problem

    scene = resolve_scene("polygon25-rolling")
    p = make_problem(scene, 1.0, ReferenceOptions())
    work = new_work()

    @njit
    def loop(y, model, pts, idx, w, n):
        dy = np.empty(13)
        acc = 0.0
        for _ in range(n):
            y[12] += 1e-12
            held_rhs(y, model, pts, idx, 1, w, dy)
            acc += dy[9]
        return acc

    y = p.state["y"][0].copy()
    args = (y, p.model[0], p.points, np.array([0, 0, 0]), work[0])
    loop(*args, 10)
    t0 = time.perf_counter()
    loop(*args, 1_000_000)
    return (time.perf_counter() - t0) / 1_000_000


@dataclass
class PhaseCost:
    phases: int
    contact_s: float  # time in the steps of contact phases, call overhead taken out
    rhs_evals: int


def contact_phase_cost(scene: Scene, repeats: int) -> PhaseCost:
    """Time spent in contact phases, measured by running the loop one step per call
    (work_budget = 1) and timing each call: a step that starts in a contact phase (or
    with contacts held, opening one) counts, less the cost of a call that does nothing
    (the loop called on the finished run: argument passing and the call's contact
    lists); the median of `repeats` runs after an untimed one.  Flights, impacts and
    chatter completions are not counted: they are the impacts' cost (table 1)."""
    from reference import compiled

    kernel = compiled.run_events()
    opts = ReferenceOptions(sample_dt=scene.run.t_end, work_budget=1)
    runs = [_stepped_run(kernel, scene, opts) for _ in range(repeats + 1)][1:]
    return sorted(runs, key=lambda c: c.contact_s)[len(runs) // 2]


def _stepped_run(kernel, scene: Scene, opts: ReferenceOptions) -> PhaseCost:
    """One run step by step (`contact_phase_cost`)."""
    from reference.core import records as R
    from reference.simulate import make_problem

    p = make_problem(scene, scene.run.t_end, opts)
    spent, n_steps, code = 0.0, 0, R.RETURN_YIELD
    while code != R.RETURN_DONE:
        st = p.state[0]
        in_phase = bool(st["in_contact"] or (st["started"] and st["n_active"] > 0))
        t0 = time.perf_counter()
        code = kernel(*p.arguments())
        if in_phase:
            spent += time.perf_counter() - t0
            n_steps += 1
        if code == R.RETURN_GROW:
            p.grow(opts.max_samples)
    args = p.arguments()
    idle = []
    for _ in range(200):
        t0 = time.perf_counter()
        kernel(*args)
        idle.append(time.perf_counter() - t0)
    c = p.counters[0]
    return PhaseCost(
        int(c["contact_phases"]),
        max(spent - n_steps * statistics.median(idle), 0.0),
        int(c["contact_rhs_evals"]),
    )


def process_time(cmd: list[str], repeats: int) -> float:
    """Median wall time of a whole process (after one untimed run)."""
    subprocess.run(cmd, capture_output=True, check=False)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=False)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def sweep_ratio(samples: int) -> tuple[float, float, int]:
    """Mean seconds per run of the reference and the linear model on a 4 × 4 subgrid
    (ρ, γ from 0.2 to 0.8) of the paper's exponent map, `samples` initial states each."""
    from harness.sweep.grid import SweepConfig, grid_values, initial_state
    from harness.sweep.run import sample_runner

    rhos, gammas = grid_values(0.2, 0.8, 4), grid_values(0.2, 0.8, 4)
    cost = {}
    for engine in ("linear", "reference"):
        run = sample_runner(engine)
        cfg = SweepConfig(n=3, engine=engine, gyration=(0.2, 0.8, 4),
                          restitution=(0.2, 0.8, 4), samples=samples, seed=1)  # fmt: skip
        run(cfg, 0.5, 0.5, *initial_state(1, 0, 0, 0))  # warm-up
        t0 = time.perf_counter()
        for i, rho in enumerate(rhos):
            for j, gamma in enumerate(gammas):
                for s in range(samples):
                    run(cfg, rho, gamma, *initial_state(1, j, i, s))
        cost[engine] = (time.perf_counter() - t0) / (len(rhos) * len(gammas) * samples)
    return cost["reference"], cost["linear"], len(rhos) * len(gammas) * samples


# ----------------------------------------------------------------------------- report


def table(rows: list[list[str]], header: list[str]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in rows]
    return "\n".join(lines)


def plain_bouncing(row: Row) -> bool:
    return row.stats.contact_phases == 0 and row.status in ("max_impacts", "t_end", "left_model")


def rate_rows(rows: list[Row]) -> list[list[str]]:
    out = []
    for r in rows:
        target = 300_000 if plain_bouncing(r) else 100_000
        out.append([
            r.case, str(r.impacts), r.status, f"{r.wall_s * 1e3:.2f}", f"{r.rate / 1e3:.0f}k",
            f"≥ {target // 1000}k", "yes" if r.rate >= target else "NO",
        ])  # fmt: skip
    return out


def spin_rows(rows: list[Row]) -> list[list[str]]:
    return [
        [
            r.case,
            f"{r.stats.search_iterations_per_impact:.2f}",
            "≤ 3",
            "yes" if r.stats.search_iterations_per_impact <= 3 else "NO",
        ]  # fmt: skip
        for r in rows
        if r.case.startswith("fast spin")
    ]


def contact_rows(rows: list[Row], scenes: dict[str, Scene], t_rhs: float, repeats: int):
    """Per contact phase of the runs with at least 10: the time in its steps
    (`contact_phase_cost`), and that time less the integrator's right-hand-side
    evaluations (their count × the measured cost of one)."""
    out = []
    for r in rows:
        if r.stats.contact_phases < 10:
            continue
        cost = contact_phase_cost(scenes[r.case], repeats)
        per = cost.contact_s / cost.phases
        rest = (cost.contact_s - cost.rhs_evals * t_rhs) / cost.phases
        out.append([r.case, str(cost.phases), f"{per * 1e6:.1f}", f"{rest * 1e6:.1f}", "≤ 20",
                    "yes" if rest <= 20e-6 else "NO"])  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per case (default 5)")
    ap.add_argument("--only", action="append", help="cases whose name contains TEXT")
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    ap.add_argument("--no-startup", action="store_true", help="skip the start-up timings")
    ap.add_argument("--no-sweep", action="store_true", help="skip the sweep timing")
    args = ap.parse_args(argv)
    if hasattr(os, "sched_setaffinity") and len(os.sched_getaffinity(0)) > 1:
        os.sched_setaffinity(0, {max(os.sched_getaffinity(0))})
    from reference import compiled
    from reference.simulate import load_event_loop

    load0 = os.getloadavg()
    warm = load_event_loop()
    print(f"load average {load0[0]:.2f}; compiled core: {compiled.kernel_source()}; "
          f"compilation/loading before the first run: {warm:.2f} s (not timed)")  # fmt: skip
    scenes = {
        name: scene
        for name, scene in cases().items()
        if not args.only or any(t in name for t in args.only)
    }
    rows = [measure(name, scene, args.repeats) for name, scene in scenes.items()]
    head = ["run to its end", "impacts", "status", "ms", "impacts/s", "target", "met"]
    print("\n1. impacts per second\n" + table(rate_rows(rows), head))
    if spin := spin_rows(rows):
        print("\n2. search iterations per impact, fast spin\n"
              + table(spin, ["run", "iterations/impact", "target", "met"]))  # fmt: skip
    t_rhs = rhs_cost_s()
    if cont := contact_rows(rows, scenes, t_rhs, args.repeats):
        head = ["run", "phases", "µs/phase", "µs/phase without RHS", "target", "met"]
        print(f"\n3. contact phases (one RHS evaluation: {t_rhs * 1e9:.0f} ns)\n"
              + table(cont, head))  # fmt: skip
    doc = {"load_before": load0, "rows": [r.__dict__ | {"stats": r.stats.to_dict()} for r in rows]}
    if not args.no_startup:
        doc["startup"] = startup_report(args.repeats)
    if not args.no_sweep:
        doc["sweep"] = sweep_report()
    load1 = os.getloadavg()
    print(f"\nload average before {load0[0]:.2f}, after {load1[0]:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=1, default=str))
    return 0


def startup_report(repeats: int) -> dict:
    py = sys.executable
    harness = str(Path(py).with_name("harness"))
    numpy_s = process_time([py, "-c", "import numpy"], repeats)
    scenes_s = process_time([harness, "scenes"], repeats)
    simulate_s = process_time([harness, "simulate", "grazing-contact"], repeats)
    rows = [
        ["python -c 'import numpy'", f"{numpy_s:.3f}", "1.0", "-", "-"],
        ["harness scenes", f"{scenes_s:.3f}", f"{scenes_s / numpy_s:.1f}", "≤ 3",
         "yes" if scenes_s <= 3 * numpy_s else "NO"],
        ["harness simulate grazing-contact", f"{simulate_s:.3f}", f"{simulate_s / numpy_s:.1f}",
         "≤ 6", "yes" if simulate_s <= 6 * numpy_s else "NO"],
    ]  # fmt: skip
    print("\n4. start-up (whole processes, median)\n"
          + table(rows, ["command", "s", "× numpy", "target", "met"]))  # fmt: skip
    return {"numpy_s": numpy_s, "scenes_s": scenes_s, "simulate_s": simulate_s}


def sweep_report() -> dict:
    ref, lin, n = sweep_ratio(samples=5)
    full_s = 21 * 21 * 100 * ref / 2
    rows = [
        ["reference / linear per run", f"{ref * 1e3:.2f} / {lin * 1e3:.2f} ms",
         f"{ref / lin:.1f}×", "≤ 5×", "yes" if ref <= 5 * lin else "NO"],
        ["full 21 × 21 × 100 map on 2 cores", f"{full_s / 60:.1f} min", "-", "≤ 5 min",
         "yes" if full_s <= 300 else "NO"],
    ]  # fmt: skip
    print(f"\n5. sweeps ({n} runs of a 4 × 4 subgrid, one core)\n"
          + table(rows, ["figure", "value", "ratio", "target", "met"]))  # fmt: skip
    return {"reference_s": ref, "linear_s": lin, "full_map_2cores_s": full_s}


if __name__ == "__main__":
    sys.exit(main())
