"""A toy engine for the Euler's disk harness: rigid body, semi-implicit Euler, and at
every vertex a one-step velocity projection (Newton's law vₙ⁺ = −γ vₙ⁻ on contacts that
penetrate and approach, solved one contact at a time, Gauss–Seidel).

It shows what an engine adapter does (docs/engines.md): build the scene's body (from the
harness's `engines.base` helpers); wrap the stepping in an Adapter (`ToyStepper`) that the
harness's driver `engines.stepping.simulate_fixed_step` runs (end time and step count,
progress, checks for a non-finite state or a fall-through, Ctrl-C, the common stats); hand
it the per-step states (reference conventions: x, q wxyz, v, ω world) and per-contact
normal impulses (`recording`), from which it builds the Trajectory (impacts from contact
onsets, energies, the impact budget); declare the entry point's attributes with
`engines.interface.engine_entry`.
Flat ground only.
"""

from __future__ import annotations

import numpy as np

from engines.base import initial_state, scene_points
from engines.interface import engine_entry
from engines.stepping import Recording, Rows, simulate_fixed_step
from reference.scene import Scene, SceneError
from reference.trajectory import Trajectory

__version__ = "0.1.0"
GAUSS_SEIDEL_SWEEPS = 4  # resting n-gons need a few sweeps to share the load
CHUNK_STEPS = 1_000  # steps between two checks (and progress reports) of the run loop


def _rotation(q):
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _rotate_by(q, phi):
    """exp(φ/2) ⊗ q: q turned by the world rotation vector φ."""
    th = np.sqrt(phi @ phi)
    s = np.sinc(th / (2 * np.pi)) / 2  # sin(θ/2)/θ
    a0, (a1, a2, a3) = np.cos(th / 2), s * phi
    b0, b1, b2, b3 = q
    out = np.array(
        [
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ]
    )
    return out / np.sqrt(out @ out)


def _step(y, dt, g, m, inertia, points, gamma):
    """One semi-implicit Euler step: gravity, gyroscopic torque, contact impulses from the
    state at the start of the step, then positions from the new velocities."""
    x, q, v, w = y[0:3], y[3:7], y[7:10].copy(), y[10:13].copy()
    R = _rotation(q)
    I_inv = R @ np.diag(1.0 / inertia) @ R.T  # world-frame inverse inertia
    v[2] -= g * dt
    w = w - dt * I_inv @ np.cross(w, R @ (inertia * (R.T @ w)))  # Euler's equations
    r = points @ R.T  # lever arms in the world
    impulses = np.zeros(len(points))
    touching = np.flatnonzero(x[2] + r[:, 2] <= 0.0)
    arms = np.cross(r[touching], [0.0, 0.0, 1.0])  # (r × ẑ): vₙ = v_z + arm·ω
    targets = -gamma * np.minimum(v[2] + arms @ w, 0.0)  # Newton: vₙ⁺ = −γ vₙ⁻
    k_inv = 1.0 / m + np.einsum("ij,jk,ik->i", arms, I_inv, arms)  # 1/m_eff per contact
    for _ in range(GAUSS_SEIDEL_SWEEPS):
        for i, k in enumerate(touching):
            vn = v[2] + arms[i] @ w
            p = max(-impulses[k], (targets[i] - vn) / k_inv[i])  # total impulse ≥ 0
            impulses[k] += p
            v[2] += p / m
            w = w + I_inv @ arms[i] * p
    return np.concatenate([x + dt * v, _rotate_by(q, w * dt), v, w]), impulses


class ToyStepper:
    """The engine as an `engines.stepping.Stepper`: the shared run loop calls `advance`
    chunk by chunk and checks the rows it returns (non-finite state, fall-through),
    calls `cut` when a row fails, `settle` after Ctrl-C."""

    def __init__(self, scene: Scene, dt: float) -> None:
        self.dt, self.g = dt, scene.gravity
        self.m, self.gamma = scene.body.mass, scene.restitution
        self.points = scene_points(scene)
        self.inertia = np.array(scene.body.inertia_diag)
        self.states = [initial_state(scene.initial)]  # row j: the state after step j
        self.impulses = [np.zeros(len(self.points))]  # row j: applied in step j
        self.first = 0

    def advance(self, steps: int) -> Rows:
        self.first = len(self.states)
        for _ in range(steps):
            y, p = _step(
                self.states[-1], self.dt, self.g, self.m, self.inertia, self.points, self.gamma
            )
            self.states.append(y)
            self.impulses.append(p)
        t = self.dt * np.arange(self.first, len(self.states))
        return Rows(t, np.array(self.states[self.first :]))

    def cut(self, keep: int) -> None:
        del self.states[self.first + keep :], self.impulses[self.first + keep :]

    def settle(self) -> float:
        kept = min(len(self.states), len(self.impulses))
        del self.states[kept:], self.impulses[kept:]
        return self.dt * (kept - 1)

    def recording(self, loop) -> Recording:
        """The rows for the driver: every step's state and impulses."""
        states, impulses = np.array(self.states), np.array(self.impulses)
        t = self.dt * np.arange(len(states))
        return Recording(t, states, impulses, len(states) - 1, {"toy_engine_version": __version__})


@engine_entry(fixed_step=True, reports_progress=True)
def simulate(scene: Scene, *, dt: float, t_end: float | None = None, progress=None) -> Trajectory:
    """The entry point: `harness` calls it with the scene, the step and the end time (and
    a progress callback, since it says `reports_progress`).  The shared driver sets the
    end time and step count, runs the loop, fills the common stats and builds the
    Trajectory."""
    if scene.ground.kind != "flat":
        raise SceneError("the toy engine models flat ground only")
    return simulate_fixed_step(
        scene,
        "toy",
        dt,
        t_end,
        lambda n_steps: ToyStepper(scene, dt),
        chunk_steps=CHUNK_STEPS,
        progress=progress,
    )
