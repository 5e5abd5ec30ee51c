"""Fill numba's on-disk cache with the parts of the reference compiled just in time:
`python -m reference.warm` (run by `make setup` beside the core's ahead-of-time build).

The exact model's event loop is in the ahead-of-time module (`reference.core.aot`); the
paper's linearised model (`reference/linear/kernel.py`) is compiled by numba on its first
run and cached in `reference/linear/__pycache__`.  One short linear run under an impact
law compiles its kernel (the law's path included: the kernel is one compiled loop); one
impact of `reference.linear.laws.apply_law` compiles the law event's helpers that Python
calls on their own (compiled into the kernel, they have no machine code of their own);
a call of each of the kernel's other functions that Python calls (the self-similar
analysis' root, the energy exponent's sums in log space) compiles those.  The first
`harness ... --engine linear`, `apply_law` or `sweep exponent` and every process of the
test suite then load them from the cache instead of compiling them again.  The results
are discarded (tests/test_warm.py checks that every such function is called)."""

from __future__ import annotations

import dataclasses
import time

from .process_exit import exit_now

WARM_SCENE = "triangle-chatter"  # a built-in scene with a simultaneous impact
WARM_LAW = "moreau"


def warm_linear_kernel() -> None:
    """Run the linear model once on WARM_SCENE under WARM_LAW."""
    from reference.linear.simulate import simulate_linear
    from reference.scenes import load_scene

    simulate_linear(dataclasses.replace(load_scene(WARM_SCENE), impact_law=WARM_LAW))


def warm_law_impulses() -> None:
    """One impact of `apply_law` under WARM_LAW (a triangle's contact 0 approaching)."""
    import numpy as np

    from reference.core.laws import law_code
    from reference.linear.laws import apply_law
    from reference.linear.model import LinearModel

    model = LinearModel.polygon(3, 0.5, 0.5)
    p = np.array([0.0, 0.0, -1.0])
    apply_law(model.F, model.theta, model.restitution, p, [0], law_code(WARM_LAW))


def warm_python_calls() -> None:
    """The kernel's other functions that Python calls: `first_hit` (the self-similar
    analysis) and `log2_time_to_go` and `log2_segment_sums` (the energy exponent's
    estimators, reference.linear.exponent_estimates), on three intervals."""
    import numpy as np

    from reference.linear import kernel as K

    log2_dt = np.array([-np.inf, -1.0, -2.0])
    K.first_hit(1.0, -1.0, -1.0)
    K.log2_time_to_go(log2_dt, -3.0)
    K.log2_segment_sums(log2_dt, np.array([0, 2], dtype=np.int64))


WARM_STEPS = (warm_linear_kernel, warm_law_impulses, warm_python_calls)


def warm_all() -> float:
    """Every step of WARM_STEPS; returns the seconds taken (the compilation, or the
    cache's loading when it is already filled)."""
    t0 = time.perf_counter()
    for step in WARM_STEPS:
        step()
    return time.perf_counter() - t0


def main() -> int:
    print("compiling the linear model's kernel into numba's cache ...", flush=True)
    seconds = warm_all()
    print(f"the linear model's kernel is in numba's cache ({seconds:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    exit_now(main())
