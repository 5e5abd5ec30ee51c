"""States of the horizon study: the 12-component dimensionless difference of two states,
a perturbation drawn from the stated direction distribution, a restart of the exact
reference from any state, and the lift that puts a state's contacts back on the ground.

Units (the scene's speed group, `reference.scene.velocity_unit`): lengths in the radius
a, speeds in U = max(√(g a), a/t_end), angular velocities in U/a.  The difference of
states y, y' is the 12-vector (Δx/a, φ, Δv/U, Δω a/U) with φ the rotation vector of
q' q⁻¹ (an attitude difference in radians); its Euclidean norm is the "separation" and
the "error level" of docs/fidelity.md's horizon section.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from reference import ReferenceOptions, Scene, Trajectory, simulate
from reference import quaternion as qt
from reference.core import layout as L
from reference.geometry import initial_state, scene_contact_kinematics
from reference.scene import InitialState, RunSettings, velocity_unit

DIMENSION = 12  # position, attitude, velocity, angular velocity: 3 each


def units(scene: Scene) -> np.ndarray:
    """(12,) the unit of each component of a state difference (module docstring)."""
    a, u = scene.body.radius, velocity_unit(scene)
    return np.repeat([a, 1.0, u, u / a], 3)


def difference(scene: Scene, y: np.ndarray, y_ref: np.ndarray) -> np.ndarray:
    """(..., 12) the dimensionless difference y − y_ref of states (..., 13)."""
    y, y_ref = np.asarray(y, dtype=float), np.asarray(y_ref, dtype=float)
    rel = qt.multiply(y[..., L.QUATERNION], qt.conjugate(y_ref[..., L.QUATERNION]))
    phi = qt.to_rotation_vector(rel)
    dx = y[..., L.POSITION] - y_ref[..., L.POSITION]
    dv = y[..., L.VELOCITIES] - y_ref[..., L.VELOCITIES]
    d = np.concatenate([dx, phi, dv], axis=-1)
    return d / units(scene)


def separation(scene: Scene, y: np.ndarray, y_ref: np.ndarray) -> np.ndarray:
    """The norm of `difference`: how far apart two states are, dimensionless."""
    return np.linalg.norm(difference(scene, y, y_ref), axis=-1)


def random_directions(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 12) directions uniform on the unit sphere of the dimensionless difference
    space (normalised standard normal vectors): every component of position, attitude,
    velocity and angular velocity is perturbed, none preferred."""
    g = rng.standard_normal((n, DIMENSION))
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def displaced(scene: Scene, y: np.ndarray, step: np.ndarray) -> np.ndarray:
    """The state y moved by the dimensionless difference `step` (12,): position, velocity
    and angular velocity added, the attitude turned by the rotation vector (world
    frame), so that `difference(scene, displaced(y, s), y) = s` to roundoff."""
    s = np.asarray(step, dtype=float) * units(scene)
    out = np.array(y, dtype=float)
    out[L.POSITION] += s[0:3]  # s: (position, rotation vector, velocities), units()
    turn = qt.from_rotation_vector(s[3:6])
    out[L.QUATERNION] = qt.normalize(qt.multiply(turn, out[L.QUATERNION]))
    out[L.VELOCITIES] += s[6:12]
    return out


def lifted(scene: Scene, y: np.ndarray) -> tuple[np.ndarray, float]:
    """The state moved along the contact normal until no contact is below the ground,
    and by how much (0 if none was).  Flat ground: the centre up by the deepest vertex's
    depth; three-point ground: along the face normal e3 by the deepest bump's (every
    bump's gap (x − b_k)·e3 grows by the same amount).  Velocities are unchanged: this
    is the position projection a fixed-step engine makes after a step that ends inside
    the ground, and it changes the potential energy by m g times the depth."""
    from reference.core.records import RIM_VERTEX_ON_PLANE

    gap, _ = scene_contact_kinematics(scene, y)
    deepest = int(np.argmin(gap))
    depth = float(max(0.0, -gap.flat[deepest]))
    if depth == 0.0:
        return np.array(y, dtype=float), 0.0
    out = np.array(y, dtype=float)
    normal = np.array([0.0, 0.0, 1.0])
    if scene.contacts.kind(deepest) != RIM_VERTEX_ON_PLANE:
        normal = qt.body_axis(out[L.QUATERNION])
    out[L.POSITION] += depth * normal
    return out, depth


def flown(scene: Scene, y: np.ndarray, s: float) -> np.ndarray:
    """The state after a free flight of duration s from y, by the reference's closed
    form (reference.core.flight.free_flight: parabola and regular precession), through
    the ground if it lies in the way."""
    from reference.core.flight import flight_constants, free_flight

    y0 = np.ascontiguousarray(y, dtype=float)
    out = np.empty(13)
    i1, _, i3 = scene.body.inertia_diag
    free_flight(y0, flight_constants(y0, i1, i3), scene.gravity, float(s), out)
    return out


def scene_at(scene: Scene, y: np.ndarray, t_end: float, max_impacts: int) -> Scene:
    """The scene started from state y (13,) for t_end, at most max_impacts impacts (no
    scene-file checks: the caller has lifted y onto the ground)."""
    y = np.asarray(y, dtype=float)
    initial = InitialState(
        position=tuple(float(x) for x in y[L.POSITION]),
        rotation_vector=tuple(float(x) for x in qt.to_rotation_vector(y[L.QUATERNION])),
        velocity=tuple(float(x) for x in y[L.VELOCITY]),
        angular_velocity=tuple(float(x) for x in y[L.ANGULAR_VELOCITY]),
    )
    return replace(scene, initial=initial, run=RunSettings(t_end, max_impacts))


def sparse_options(t_end: float) -> ReferenceOptions:
    """Options for a restart: one regular sample (events add their own), small arrays."""
    return ReferenceOptions(sample_dt=max(t_end, 1e-300), max_samples=4096)


def run_from(scene: Scene, y: np.ndarray, t_end: float, max_impacts: int) -> Trajectory:
    """The exact reference from state y for t_end (times from 0), sparsely sampled."""
    return simulate(scene_at(scene, y, t_end, max_impacts), options=sparse_options(t_end))


def start_state(scene: Scene) -> np.ndarray:
    """The scene's initial 13-component state."""
    return initial_state(scene.initial)


def post_impact_states(traj: Trajectory) -> np.ndarray:
    """(n_impacts, 13) the state just after each impact: the last sample at the impact's
    time (the reference samples every event before and after it)."""
    t = traj.impact_times().astype(float)
    idx = np.searchsorted(traj.t, t, side="right") - 1
    states = np.concatenate(
        [traj.position, traj.quaternion, traj.velocity, traj.angular_velocity], axis=1
    )
    return states[np.clip(idx, 0, max(len(traj.t) - 1, 0))]


def pre_impact_state(traj: Trajectory, k: int) -> np.ndarray:
    """The state just before impact k: the first sample at the impact's time."""
    i = int(np.searchsorted(traj.t, traj.impacts[k].t, side="left"))
    return np.concatenate(
        [traj.position[i], traj.quaternion[i], traj.velocity[i], traj.angular_velocity[i]]
    )
