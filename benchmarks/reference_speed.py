"""Speed of the exact reference: impacts per second and per-impact cost against n.

    .venv/bin/python benchmarks/reference_speed.py [--repeats 3] [--only NAME ...]
        [--profile] [--json FILE]

Each case runs once untimed (warm-up: imports, caches), then `repeats` timed runs;
reported: median and minimum wall time, impacts, impacts/s and µs/impact from the
median, with the machine's load average (the machine is shared: read timings with it).
Targets (issue 6): ≥ 100,000 impacts/s for the triangle (n = 3, flat, γ > 0), and a
per-impact cost within 2× from n = 10 to n = 10,000; the script prints both ratios.

Cases: the built-in `triangle-chatter` and `pentagon-bounce` scenes as they are, and a
family of flat n-gons started from elastic-hexagon's linear state (q = (0.01, −0.004,
0.03), p = (0.03, 0.05, −0.2), ρ = 0.5) with γ = 1 (elastic: the motion goes on, so the
cost per impact is a steady rate) and γ = 0.8 (impacts dissipate: chatter, sustained
contact phases), each to a fixed number of impacts (t_end = 1e6, so the grid sampling
costs nothing); and the triangle at γ = 0.5, 0.9, 0.99 run to its end (`…-to-end`).
The per-impact costs of the γ = 0.8 family depend on how often each polygon chatters
(every chatter is a completion and a contact phase, ~1 ms in Python whatever n): the
printed counts of completions and contact chunks say how the mixes differ.
`--profile` prints cProfile's top entries (cumulative and own time) for n = 3 and
n = 10,000, elastic and γ = 0.8.

This is a benchmark, not a test: nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from harness.scenes import resolve_scene  # noqa: E402
from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear  # noqa: E402
from reference.simulate import simulate  # noqa: E402

Q0 = (0.01, -0.004, 0.03)
P0 = (0.03, 0.05, -0.2)


def polygon(n: int, gamma: float, impacts: int) -> Scene:
    """Flat n-gon from elastic-hexagon's linear state, run to `impacts` impacts."""
    return Scene(
        name=f"n{n}-gamma{gamma:g}",
        body=Body(n=n, gyration=0.5),
        ground=Ground(),
        initial=initial_from_linear(Q0, P0),
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=1e6, max_impacts=impacts),
    )


def cases() -> dict[str, Scene]:
    """Name → scene.  Impact counts keep each run to seconds on this machine."""
    out = {
        "triangle-chatter": resolve_scene("triangle-chatter"),
        "pentagon-bounce": resolve_scene("pentagon-bounce"),
    }
    for n in (3, 10, 100, 1000, 10_000):
        out[f"n{n}-elastic"] = polygon(n, 1.0, 20_000)
    for n in (3, 10, 100, 1000, 10_000):
        out[f"n{n}-gamma0.8"] = polygon(n, 0.8, 2000)
    # the triangle with 0 < γ < 1 run to its end (a γ < 1 run is finite: chatter, then a
    # simultaneous impact or the singularity), so the rate includes every phase
    for gamma in (0.5, 0.9, 0.99):
        out[f"n3-gamma{gamma:g}-to-end"] = polygon(3, gamma, 1_000_000)
    return out


def measure(scene: Scene, repeats: int) -> dict:
    simulate(scene)  # warm-up
    walls, outside, in_loop, traj = [], [], [], None
    load = os.getloadavg()[0]
    for _ in range(repeats):
        t0 = time.perf_counter()
        traj = simulate(scene)
        walls.append(time.perf_counter() - t0)
        loop_s = traj.stats.get("bounce_loop_s", 0.0)
        outside.append(traj.stats["wall_time_s"] - loop_s)
        in_loop.append(loop_s)
    med = statistics.median(walls)
    n = len(traj.impacts)
    return {
        "scene": scene.name,
        "n": scene.body.n,
        "restitution": scene.restitution,
        "status": traj.status.value,
        "impacts": n,
        "t_final": traj.t_final,
        "wall_median_s": med,
        "wall_min_s": min(walls),
        "impacts_per_s": n / med if n else None,
        "us_per_impact": 1e6 * med / n if n else None,
        "contact_chunks": traj.stats.get("contact_chunks"),
        "contact_phases": sum(1 for ph in traj.phases if ph.kind == "contact"),
        # medians over the timed runs: time outside / inside the compiled flight loop
        "outside_bounce_loop_s": statistics.median(outside),
        "bounce_loop_us_per_impact": (
            1e6 * statistics.median(in_loop) / traj.stats["bounce_loop_impacts"]
            if traj.stats.get("bounce_loop_impacts")
            else None
        ),
        "chatter_completions": traj.stats.get("chatter_completions"),
        "load_1min": load,
    }


def profile(scene: Scene, top: int = 15) -> str:
    simulate(scene)  # warm-up
    prof = cProfile.Profile()
    prof.enable()
    traj = simulate(scene)
    prof.disable()
    out = io.StringIO()
    out.write(f"--- cProfile {scene.name}: {len(traj.impacts)} impacts ---\n")
    for key in ("cumulative", "tottime"):
        stats = pstats.Stats(prof, stream=out).strip_dirs().sort_stats(key)
        stats.print_stats(top)
    return out.getvalue()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", action="append", help="case names (default: all)")
    ap.add_argument(
        "--profile", action="store_true", help="cProfile n = 3 and n = 10,000 (both families)"
    )
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    all_cases = cases()
    names = args.only or list(all_cases)
    unknown = [n for n in names if n not in all_cases]
    if unknown:
        ap.error(f"unknown case(s) {unknown}; choose from {list(all_cases)}")
    load0 = os.getloadavg()
    rows = []
    header = f"{'case':22s} {'status':20s} {'impacts':>8s} {'median[s]':>10s} {'min[s]':>9s}"
    header += f" {'impacts/s':>10s} {'us/impact':>10s} {'chatter':>7s} {'chunks':>6s} {'load':>5s}"
    print(header)
    for name in names:
        r = measure(all_cases[name], args.repeats)
        r["case"] = name
        rows.append(r)
        print(
            f"{name:22s} {r['status']:20s} {r['impacts']:8d} {r['wall_median_s']:10.4f} "
            f"{r['wall_min_s']:9.4f} {r['impacts_per_s'] or 0:10.0f} "
            f"{r['us_per_impact'] or 0:10.1f} {r['chatter_completions']:7d} "
            f"{r['contact_chunks']:6d} {r['load_1min']:5.2f}",
            flush=True,
        )
    by = {r["case"]: r for r in rows}
    ratios = {}
    for fam in ("elastic", "gamma0.8"):
        a, b = by.get(f"n10-{fam}"), by.get(f"n10000-{fam}")
        if a and b and a["us_per_impact"] and b["us_per_impact"]:
            ratios[fam] = b["us_per_impact"] / a["us_per_impact"]
            print(f"per-impact cost n=10,000 / n=10 ({fam}): {ratios[fam]:.2f}x (target <= 2)")
            if fam != "elastic":
                # split: the compiled flight/impact loop per impact, everything else
                # (chatter completions, contact phases, events in Python) per contact phase
                for r in (a, b):
                    per_phase = r["outside_bounce_loop_s"] / max(r["contact_phases"], 1)
                    print(
                        f"  n={r['n']}: compiled loop {r['bounce_loop_us_per_impact'] or 0:.1f} "
                        f"us/impact; the rest {1e3 * per_phase:.2f} ms per contact phase "
                        f"({r['contact_phases']} phases, {r['chatter_completions']} chatter "
                        f"completions in {r['impacts']} impacts)"
                    )
    triangles = ["n3-elastic", "n3-gamma0.8", "triangle-chatter"]
    triangles += [k for k in by if k.startswith("n3-gamma") and k.endswith("-to-end")]
    for name in triangles:
        if name in by and by[name]["impacts_per_s"]:
            ips = by[name]["impacts_per_s"]
            print(f"{name}: {ips:,.0f} impacts/s = {ips / 1e5:.3g} of the 100,000/s target")
    load1 = os.getloadavg()
    print(
        f"load average before {' '.join(f'{x:.2f}' for x in load0)}, after "
        f"{' '.join(f'{x:.2f}' for x in load1)}; {os.cpu_count()} cpus; "
        f"median of {args.repeats} after a warm-up"
    )
    profiles = []
    if args.profile:
        for name in ("n3-elastic", "n3-gamma0.8", "n10000-elastic", "n10000-gamma0.8"):
            text = profile(all_cases[name])
            profiles.append(text)
            print(text)
    if args.json:
        doc = {
            "rows": rows,
            "per_impact_cost_ratio_n10000_vs_n10": ratios,
            "load": {"before": load0, "after": load1},
            "cpu_count": os.cpu_count(),
            "repeats": args.repeats,
            "profiles": profiles,
        }
        Path(args.json).write_text(json.dumps(doc, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
