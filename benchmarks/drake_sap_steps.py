"""Drake's SAP contact length as a per-scene choice: the adapter's contact of
N = 4·N₀(γ) steps (N₀ = π²/(2|ln γ|), `engines.drake.SAP_STEPS_FACTOR`) against shorter
ones, on the vertex drop of `harness restitution` at dt = 1e-4: e_eff/γ − 1 by impact
speed, the worst over the onset phases 0.1, 0.5, 0.9 of a step.  A shorter contact
carries less of gravity's impulse (slow impacts), a longer one spreads less over the
onset phase (fast impacts); docs/engines.md, "The restitution contract", has the table.

    python benchmarks/drake_sap_steps.py
"""

from __future__ import annotations

import dataclasses
import math

from engines import drake as dk
from harness.restitution.drops import drop_scene, watched_point
from harness.restitution.impact import read_impact
from harness.restitution.text import percent

DT = 1e-4
GAMMAS = (0.5, 0.8, 0.95)
FACTORS = (1.5, 2.0, 4.0)
SPEEDS = (0.01, 0.03, 0.1, 0.3, 1.0)
PHASES = (0.1, 0.5, 0.9)


def bounce_error(gamma: float, speed: float, phase: float, steps: float) -> float | None:
    """e_eff/γ − 1 of one drop with an N-step SAP contact (None: no bounce)."""
    lead = phase * DT
    scene = drop_scene("vertex", gamma, speed, lead, lead + 8 * steps * DT)
    tau_h = dk.sap_relaxation_time(gamma, steps)
    settings = dataclasses.replace(
        dk.contact_settings(scene, DT, "sap"),
        contact_steps=steps,
        relaxation_time=tau_h * DT,
        stiffness=dk.effective_contact_mass(scene) * (math.pi / (steps * DT)) ** 2,
    )
    reading = read_impact(scene, dk.run_with_settings(scene, settings), *watched_point("vertex"))
    return reading.e_eff / gamma - 1.0 if reading.outcome == "ok" else None


def main() -> None:
    print("gamma  factor    N  " + "".join(f"{v:>8g}" for v in SPEEDS))
    for gamma in GAMMAS:
        n0 = math.pi**2 / (2.0 * -math.log(gamma))
        for factor in FACTORS:
            steps = float(min(dk.SAP_MAX_STEPS, max(dk.SAP_MIN_STEPS, math.ceil(factor * n0))))
            cells = []
            for v in SPEEDS:
                errs = [bounce_error(gamma, v, p, steps) for p in PHASES]
                ok = [e for e in errs if e is not None]
                worst = max(ok, key=abs) if len(ok) == len(errs) else None
                cells.append("stuck" if worst is None else percent(worst))
            print(f"{gamma:<6g} {factor:<6g} {steps:4.0f}  " + "".join(f"{c:>8}" for c in cells))


if __name__ == "__main__":
    main()
