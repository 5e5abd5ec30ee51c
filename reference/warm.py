"""Fill numba's on-disk cache with the parts of the reference compiled just in time:
`python -m reference.warm` (run by `make setup` beside the core's ahead-of-time build).

The exact model's event loop is in the ahead-of-time module (`reference.core.aot`); the
paper's linearised model (`reference/linear/kernel.py`) is compiled by numba on its first
run and cached in `reference/linear/__pycache__`.  One short linear run under an impact
law compiles its kernel (the law's path included: the kernel is one compiled loop), so
that the first `harness ... --engine linear` and every process of the test suite load it
from the cache instead of compiling it again.  The run's result is discarded."""

from __future__ import annotations

import dataclasses
import time

from .process_exit import exit_now

WARM_SCENE = "triangle-chatter"  # a built-in scene with a simultaneous impact
WARM_LAW = "moreau"


def warm_linear_kernel() -> float:
    """Run the linear model once on WARM_SCENE under WARM_LAW; returns the seconds taken
    (the compilation, or the cache's loading when it is already filled)."""
    from reference.linear.simulate import simulate_linear
    from reference.scenes import load_scene

    scene = dataclasses.replace(load_scene(WARM_SCENE), impact_law=WARM_LAW)
    t0 = time.perf_counter()
    simulate_linear(scene)
    return time.perf_counter() - t0


def main() -> int:
    print("compiling the linear model's kernel into numba's cache ...", flush=True)
    seconds = warm_linear_kernel()
    print(f"the linear model's kernel is in numba's cache ({seconds:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    exit_now(main())
