"""Effective restitution of PyBullet for a single vertex impact.

A pentagon tilted by `tilt` about the y axis (vertex 0 lowest, the others at least
a(1 − cos 72°) sin(tilt) higher) falls without rotation from a vertex gap `drop`, so
vertex 0 hits alone at normal speed √(2 g drop).  The effective restitution is
e = −v_n⁺ / v_n⁻ of that contact point, measured two ways:

- `e`: from the first impact of the run as `engines.base` reports it (v_n⁻ in the step
  before the onset, v_n⁺ in the first step after the impulse window), what the harness
  shows;
- `e_step`: v_n⁺ at the end of the onset step itself, i.e. the engine's own velocity
  jump without the extra step of gravity (−g dt) that the window adds.

    python -m engines.pybullet_restitution      # the table of e for γ × dt × profile
"""

from __future__ import annotations

import math

import numpy as np

from reference.geometry import scene_contact_kinematics
from reference.scene import Scene, scene_from_dict


def single_vertex_scene(
    gamma: float, tilt: float = 0.3, drop: float = 0.02, gravity: float = 1.0
) -> Scene:
    """Pentagon (a = 1, m = 1, ρ = 1/2) with vertex 0 at height `drop`, at rest, tilted by
    `tilt` about y; runs until shortly after the first impact (flight time √(2 drop/g))."""
    z = drop + math.sin(tilt)  # vertex 0 at (cos tilt, 0, −sin tilt) from the centre
    t_hit = math.sqrt(2.0 * drop / gravity)
    return scene_from_dict(
        {
            "name": f"single-vertex-{gamma:g}",
            "gravity": gravity,
            "restitution": gamma,
            "body": {"n": 5, "radius": 1.0, "mass": 1.0, "gyration": 0.5},
            "ground": {"kind": "flat"},
            "initial": {
                "position": [0.0, 0.0, z],
                "rotation_vector": [0.0, tilt, 0.0],
                "velocity": [0.0, 0.0, 0.0],
                "angular_velocity": [0.0, 0.0, 0.0],
            },
            "run": {"t_end": 1.2 * t_hit},
        }
    )


def single_vertex_restitution(
    gamma: float, dt: float, profile: str = "tuned", **scene_options
) -> tuple[float, float]:
    """(e, t) of the first impact of `single_vertex_scene`: e = −v_n⁺/v_n⁻ and its time.

    Raises RuntimeError when the run shows no impact of vertex 0 first."""
    e, _, t = _first_impact(gamma, dt, profile, **scene_options)
    return e, t


def _first_impact(gamma, dt, profile, **scene_options) -> tuple[float, float, float]:
    """(e, e_step, t) of the first impact (see the module docstring)."""
    from engines.pybullet import simulate_pybullet

    scene = single_vertex_scene(gamma, **scene_options)
    traj = simulate_pybullet(scene, dt, profile=profile)
    if not traj.impacts or traj.impacts[0].contact != 0:
        raise RuntimeError(f"no single impact of vertex 0 in {traj.impacts[:3]}")
    first = traj.impacts[0]
    # onset row: the first sample after the impact time (its predecessor is the step
    # before, both are kept by simulate_pybullet around contact activity)
    j = int(np.searchsorted(traj.t, first.t, side="right"))
    vn = [scene_contact_kinematics(scene, _state(traj, i))[1][0, 0] for i in (j - 1, j)]
    return -first.v_normal_post / first.v_normal_pre, -vn[1] / vn[0], first.t


def _state(traj, i: int) -> np.ndarray:
    return np.concatenate(
        [traj.position[i], traj.quaternion[i], traj.velocity[i], traj.angular_velocity[i]]
    )


def restitution_table(
    gammas=(0.3, 0.5, 0.8, 0.95), dts=(1e-3, 1e-4, 1e-5), profiles=("tuned", "default")
) -> list[dict]:
    rows = []
    for profile in profiles:
        for dt in dts:
            for gamma in gammas:
                e, e_step, t = _first_impact(gamma, dt, profile)
                rows.append(
                    {"profile": profile, "dt": dt, "gamma": gamma, "e": e, "e_step": e_step, "t": t}
                )
    return rows


def main() -> None:
    rows = restitution_table()
    head = ["profile", "dt", "gamma", "e", "(e-g)/g", "e_step", "(e_step-g)/g"]
    print(" ".join(f"{h:>12}" for h in head))
    for r in rows:
        g = r["gamma"]
        print(
            f"{r['profile']:>12} {r['dt']:>12.0e} {g:>12} {r['e']:>12.5f}"
            f" {(r['e'] - g) / g:>+12.3%} {r['e_step']:>12.5f} {(r['e_step'] - g) / g:>+12.3%}"
        )


if __name__ == "__main__":
    main()
