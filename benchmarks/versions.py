"""The same runs timed on two versions of the reference, for before/after ratios.

    git worktree add --detach /tmp/before <commit>
    PYTHONPATH=/tmp/before python benchmarks/versions.py time before.json
    python benchmarks/versions.py time after.json
    python benchmarks/versions.py ratios before.json after.json

Each case is run once to warm up (compilation, loading), then timed 5 times; the median
wall time is kept.  Alternate the two versions a few times on a busy machine and keep
each one's best median.  Only the public API (reference.scene, reference.simulate,
harness.scenes) is used, so any version since the first works.
"""

from __future__ import annotations

import json
import statistics
import sys
import time

Q0, P0 = (0.01, -0.004, 0.03), (0.03, 0.05, -0.2)


def polygon(n: int, gamma: float, impacts: int):
    from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear

    return Scene(
        name=f"n{n}",
        body=Body(n=n, gyration=0.5),
        ground=Ground(),
        initial=initial_from_linear(Q0, P0),
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=1e6, max_impacts=impacts),
    )


def cases() -> dict:
    from harness.scenes import resolve_scene

    out = {
        name: resolve_scene(name)
        for name in ("triangle-chatter", "pentagon-bounce", "polygon25-rolling", "three-point-disk")
    }
    for n in (3, 10, 100, 1000, 10000):
        out[f"n{n}-elastic"] = polygon(n, 1.0, 20000)
    for n in (3, 10, 1000, 10000):
        out[f"n{n}-gamma0.8"] = polygon(n, 0.8, 2000)
    for g in (0.5, 0.9, 0.99):
        out[f"n3-gamma{g}-to-end"] = polygon(3, g, 1000000)
    return out


def time_cases(path: str, repeats: int = 5) -> None:
    from reference.simulate import simulate

    out = {}
    for name, scene in cases().items():
        simulate(scene)  # warm-up: compilation and loading are not timed
        walls = []
        for _ in range(repeats):
            start = time.perf_counter()
            traj = simulate(scene)
            walls.append(time.perf_counter() - start)
        wall = statistics.median(walls)
        out[name] = (len(traj.impacts), wall)
        print(f"{name:22s} {len(traj.impacts):6d} {wall * 1e3:9.2f} ms", flush=True)
    with open(path, "w") as fh:
        json.dump(out, fh)


def ratios(before_path: str, after_path: str) -> None:
    with open(before_path) as fh:
        before = json.load(fh)
    with open(after_path) as fh:
        after = json.load(fh)
    print(f"{'case':22s} {'before k/s':>10s} {'after k/s':>10s} {'speed-up':>8s}")
    for name, (n0, w0) in before.items():
        if name not in after:
            continue
        n1, w1 = after[name]
        r0, r1 = n0 / w0, n1 / w1
        print(f"{name:22s} {r0 / 1e3:10.1f} {r1 / 1e3:10.1f} {r1 / r0:8.2f}")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "time":
        time_cases(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "ratios":
        ratios(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
