"""Fill JAX's compilation cache with the programs MJX's tests compile:
`python -m tests.warm_mjx` (run by `make setup`, at the lowest priority, on the core the
installs leave idle while the reference's core builds on the other).

tests/test_engine_mjx.py runs pentagon-bounce through three compiled scans of
engines.mjx.CHUNK_STEPS steps: float64, float32, and float64 vmapped over a batch of two
scenes.  JAX compiles each on its first use (XLA, several seconds of CPU each) and keeps it
in JAX_CACHE_DIR; the tests set that directory too (tests/conftest.py), so that their
workers load the three programs instead of compiling them.  A program depends on the
model's structure, the precision and the batch's size, not on the time step or the
initial state: the short runs below compile the same three.  The runs' results are
discarded; without the [mjx] extra nothing is done."""

from __future__ import annotations

import dataclasses
import importlib.util
import os
import time
from pathlib import Path

import numpy as np

from reference.process_exit import exit_now

JAX_CACHE_DIR = Path(__file__).resolve().parents[1] / ".cache" / "jax"
SCENE = "pentagon-bounce"  # MJX's tests' scene
DT = 1e-4


def batch_of_two(scene) -> list:
    """The batch MJX's tests run vmapped: the scene, and the scene spun 0.3 rad/s faster
    about the vertical (the batch's size, not its states, decides the program)."""
    from reference.geometry import initial_state

    w = initial_state(scene.initial)[10:13] + np.array([0.0, 0.0, 0.3])
    spun = dataclasses.replace(
        scene, initial=dataclasses.replace(scene.initial, angular_velocity=tuple(w))
    )
    return [scene, spun]


def compile_the_scans() -> float:
    """Run SCENE briefly in float64, float32 and as `batch_of_two`; returns the seconds
    JAX spent compiling or loading the programs."""
    from engines import mjx
    from reference.scenes import as_scene

    scene = as_scene(SCENE).with_run(t_end=10 * DT)
    runs = [mjx.simulate_mjx(scene, DT), mjx.simulate_mjx(scene, DT, precision="float32")]
    runs += mjx.simulate_mjx_batch(batch_of_two(scene), dt=DT)[:1]
    return sum(run.stats["compile_time_s"] for run in runs)


def main() -> int:
    if importlib.util.find_spec("jax") is None or importlib.util.find_spec("mujoco.mjx") is None:
        print("MJX's scans: no [mjx] extra installed, nothing to compile", flush=True)
        return 0
    os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", str(JAX_CACHE_DIR))
    print("compiling MJX's scans for its tests into JAX's cache ...", flush=True)
    t0 = time.perf_counter()
    seconds = compile_the_scans()
    print(
        f"MJX's scans are in JAX's cache ({seconds:.0f} s compiling, "
        f"{time.perf_counter() - t0:.0f} s in all)",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    exit_now(main())
