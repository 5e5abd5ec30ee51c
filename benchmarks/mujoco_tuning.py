"""MuJoCo's tuned contact: a pure one-step damper against a damper with a stiffness
term, solref = (−c/h², −(1 + γ)/h), compared on the built-in scenes and a few generated
pentagons at dt = 1e-4: leading impacts matched beside the horizon (the band (a) of the
grid model at that dt and whether the count is within it, the run's own error and its
band (b); harness.horizon), effective restitution of the run's impacts and its error
against γ (docs/engines.md has the table).

    python benchmarks/mujoco_tuning.py
"""

from __future__ import annotations

import numpy as np

import engines.mujoco_model as mm
from harness.compare import compare
from harness.scenes import resolve_scene
from reference.scene import initial_from_linear

CANDIDATES = (0.0, 1e-4, 1e-3)  # stiffness in units of 1/h²
SCENES = ("pentagon-bounce", "triangle-chatter", "three-point-disk")
DT = 1e-4


def generated_pentagons(count: int = 3, seed: int = 7):
    rng = np.random.default_rng(seed)
    base = resolve_scene("pentagon-bounce")
    for i in range(count):
        q = (*rng.normal(0, 0.01, 2), 0.05)
        p = (*rng.normal(0, 0.05, 2), -0.1)
        yield base.__class__(
            **{**base.__dict__, "name": f"pentagon-{i}", "initial": initial_from_linear(q, p)}
        )


HORIZON_RUNS = 24


def _band(q) -> str:
    return "-" if not q else f"{q[0]:.0f}-{q[2]:.0f}"


def main() -> None:
    scenes = [resolve_scene(n) for n in SCENES] + list(generated_pentagons())
    print(
        "scene                stiffness  matched    band(a)  within  own_err  band(b)"
        "  e_eff    (e-g)/g"
    )
    for scene in scenes:
        for c in CANDIDATES:
            mm.TUNED_STIFFNESS_H2 = c
            run = compare(scene, ["mujoco"], dts=[DT], horizon_runs=HORIZON_RUNS).runs[0]
            m = run.to_dict()
            h = m["horizon"]
            e = m.get("effective_restitution")
            err = (e - scene.restitution) / scene.restitution if e and scene.restitution else None
            matched = f"{m['impacts_matched']}/{m['reference_impacts']}"
            own = "-" if h["own_error"] is None else f"{h['own_error']:.1e}"
            print(
                f"{scene.name:20s} {c:<9g}  {matched:10s} {_band(h['matched_quantiles']):8s} "
                f"{'yes' if h['within'] else 'no':6s}  {own:7s}  "
                f"{_band(h['own_error_quantiles']):7s}  {e if e is None else round(e, 5)!s:8s}"
                f" {'-' if err is None else f'{100 * err:+.3f} %'}",
                flush=True,
            )


if __name__ == "__main__":
    main()
