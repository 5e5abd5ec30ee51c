"""Effective restitution of Drake's contact models against the impact speed, measured on
a single vertex impact (engines/drop.py), over the range of impact speeds of the scenes.

The profile's parameters are those it would use on a scene whose typical impact speed
(`engines.base.typical_impact_speed`) is `v_star`: the continuous profile's Hunt &
Crossley d makes e(v_star) = γ, so e(v) shows how far the bounce moves away from γ at
other speeds; the SAP profile's linear damper should not depend on v at all.

    python -m engines.drake_restitution      # the table (docs/engines.md)
"""

from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from . import drake as dk
from .drop import effective_restitution, single_vertex_drop

GAMMAS = (0.3, 0.5, 0.8, 0.95)
# impact speeds relative to the typical one: the scenes' first impacts come at
# 0.45–1.5 v*, the later ones far slower (median of pentagon-bounce: 1e-4 v*)
SPEED_RATIOS = (3.0, 1.0, 0.3, 0.1, 0.01)
V_STAR = 0.3


def measure(gamma: float, v0: float, dt: float, profile: str, v_star: float = V_STAR) -> float:
    """e of the single-vertex drop at approach speed v0 with the parameters the profile
    gives a scene of typical impact speed v_star."""
    steps = dk.sap_contact_steps(gamma) if profile == "sap" else 0.0
    # the fall, then a few contact durations (SAP contacts last N steps)
    scene = single_vertex_drop(gamma, v0=v0, h0=0.002, t_end=0.002 / v0 + 0.05 + 4 * steps * dt)
    settings = dk.contact_settings(scene, dt, profile)
    if profile == "continuous":
        u = dk.hc_speed_factor(gamma)
        settings = dataclasses.replace(settings, hc_dissipation=u / v_star)
    traj = dk.run_with_settings(scene, settings)
    states = np.column_stack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])
    return effective_restitution(scene, states)


def main() -> None:
    head = "profile     dt     gamma  " + "  ".join(f"v={r:g}v*".ljust(9) for r in SPEED_RATIOS)
    print(head)
    for profile, dts in (("continuous", (1e-4,)), ("sap", (1e-3, 1e-4, 1e-5))):
        for dt in dts:
            for g in GAMMAS:
                t0 = time.perf_counter()
                es = [measure(g, r * V_STAR, dt, profile) for r in SPEED_RATIOS]
                cells = "  ".join(f"{e:.4f}".ljust(9) for e in es)
                took = time.perf_counter() - t0
                print(f"{profile:10s}  {dt:<6g} {g:<5g}  {cells} [{took:.1f} s]")
                sys.stdout.flush()


if __name__ == "__main__":
    main()
