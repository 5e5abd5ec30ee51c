"""Effective restitution of MuJoCo's contact model, measured on a single vertex impact.

A pentagon tilted by θ about y (vertex 0 lowest, the next ones ≥ 0.07 a higher) falls
without spin at speed v0 from a gap h0, so that only vertex 0 touches the ground in the
first 0.06 s.  The effective restitution is e = −vₙ(after)/vₙ(before) of that vertex,
with `before` the last sample above the ground and `after` the first sample above it
again (reference geometry, `engines.base.contact_kinematics`).  For soft
contacts that last many steps, gravity acts during the contact and is part of e.

    python -m engines.mujoco_restitution      # the table for both profiles

Measured (mujoco 4.0.0, v0 = 1, θ = 0.1, g = a = 1):

    profile  dt      γ=0.3              γ=0.5              γ=0.8              γ=0.95
    tuned    1e-3    0.29976 (−0.08 %)  0.49990 (−0.02 %)  0.80011 (+0.01 %)  0.95022 (+0.02 %)
    tuned    1e-4    0.29989 (−0.04 %)  0.49999 (−0.00 %)  0.80001 (+0.00 %)  0.95002 (+0.00 %)
    tuned    1e-5    0.29997 (−0.01 %)  0.49999 (−0.00 %)  0.79999 (−0.00 %)  0.94999 (−0.00 %)
    default  1e-3    0.36220 (+20.7 %)  0.51336 (+2.7 %)   0.77315 (−3.4 %)   3.91095 (unstable)
    default  1e-4    0.38646 (+28.8 %)  0.54306 (+8.6 %)   0.80376 (+0.5 %)   0.94779 (−0.2 %)
    default  1e-5    0.38730 (+29.1 %)  0.54395 (+8.8 %)   0.80480 (+0.6 %)   0.94914 (−0.1 %)
"""

from __future__ import annotations

import sys
import time

import numpy as np

from .drop import effective_restitution, single_vertex_drop
from .mujoco import simulate_mujoco

GAMMAS = (0.3, 0.5, 0.8, 0.95)
TIMESTEPS = (1e-3, 1e-4, 1e-5)


def measure(gamma: float, dt: float, profile: str) -> float:
    # soft default contacts last up to ~0.1 s: give them time to let go
    scene = single_vertex_drop(gamma, t_end=0.06 if profile == "tuned" else 0.3)
    traj = simulate_mujoco(scene, dt, profile=profile)
    states = np.column_stack([traj.position, traj.quaternion, traj.velocity, traj.angular_velocity])
    return effective_restitution(scene, states)


def main() -> None:
    print("profile  dt      " + "  ".join(f"gamma={g:<12g}" for g in GAMMAS))
    for profile in ("tuned", "default"):
        for dt in TIMESTEPS:
            t0 = time.perf_counter()
            cells = []
            for g in GAMMAS:
                e = measure(g, dt, profile)
                cells.append(f"{e:.5f} ({100 * (e - g) / g:+.2f}%)")
            print(
                f"{profile:8s} {dt:<7g} " + "  ".join(cells), f"[{time.perf_counter() - t0:.1f} s]"
            )
            sys.stdout.flush()


if __name__ == "__main__":
    main()
