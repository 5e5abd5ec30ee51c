"""MuJoCo adapter: run a scene in MuJoCo and return a `Trajectory` in the reference's
conventions.

Profiles (engines/mujoco_model.py explains every parameter):
- "tuned"   → engine name "mujoco": one-step damper contact that applies Newton's law;
- "default" → engine name "mujoco-default": MuJoCo's defaults + the documented dampratio.

State conventions.  MuJoCo's free joint stores qpos = (x, q wxyz body → world) and
qvel = (v world, ω **body frame**) (MuJoCo overview, "free joints": "the rotational
velocities of a free joint are in the local body frame").  The reference uses ω in the
world frame, so ω_world = R(q) ω_body (tests/test_engine_mujoco.py checks this against
MuJoCo's own `mj_objectVelocity`).

Leapfrog reading (tuned profile).  MuJoCo's Euler step is symplectic Euler,
v⁺ = v + h a(x, v), x⁺ = x ⊕ h v⁺.  Read with v(t) as the stored velocity it is first
order (heights under gravity lag by g h t/2, impacts come early by ~g h t/(2|vₙ|)); read
with the stored velocity as v(t − h/2) it is the leapfrog scheme, second order in flight.
The tuned profile starts MuJoCo at v(−h/2) (`staggered_start`) and reports whole-step
velocities (`whole_step_velocities`).  The impact itself still happens at the first
penetrating step: an O(h) timing error per impact that no reading removes.

Recording.  `mujoco.rollout` steps in C and returns the full physics state and the
sensor data of every step; one `contact` sensor per contact point reports the normal
force of contact k (vertex k on flat ground, bump k on three_point).  MuJoCo detects a
contact at the start of a step, from a state that already penetrates, and applies its
force during that step; the impulse (force × dt) is recorded on the row of that state,
so that `engines.base` finds the gap's zero crossing between the row before the onset
and the onset row.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from reference import quaternion as qt
from reference.core import layout as L
from reference.geometry import free_acceleration, initial_state
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

from .base import build_trajectory
from .mujoco_model import contact_settings, load_model
from .stepping import Recording, Rows, run_fixed_step

ENGINE_NAMES = {"tuned": "mujoco", "default": "mujoco-default"}
STATE_SPEC = mujoco.mjtState.mjSTATE_FULLPHYSICS
# Steps per rollout call: bounds the memory of one call and lets a broken run stop early.
CHUNK_STEPS = 200_000


# --------------------------------------------------------------------------- states
def to_mujoco_state(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference state [x, q wxyz, v, ω world] (13) → MuJoCo (qpos (7), qvel (6)) with
    qvel's angular part in the body frame: ω_body = R(q)ᵀ ω_world."""
    y = np.asarray(y, dtype=float)
    q = y[L.QUATERNION]
    q_inv = np.array([q[0], -q[1], -q[2], -q[3]])
    w_body = qt.rotate(q_inv, y[L.ANGULAR_VELOCITY])
    return y[L.POSE].copy(), np.concatenate([y[L.VELOCITY], w_body])


def from_mujoco_state(qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
    """MuJoCo (qpos (..., 7), qvel (..., 6)) → reference states (..., 13), ω_world = R ω_body."""
    qpos = np.asarray(qpos, dtype=float)
    qvel = np.asarray(qvel, dtype=float)
    w_world = qt.rotate(qpos[..., 3:7], qvel[..., 3:6])
    return np.concatenate([qpos, qvel[..., 0:3], w_world], axis=-1)


def set_state(model: mujoco.MjModel, data: mujoco.MjData, y: np.ndarray) -> None:
    """Put a reference state into MuJoCo data (time 0) and run the position/velocity stages."""
    mujoco.mj_resetData(model, data)
    data.qpos[:], data.qvel[:] = to_mujoco_state(y)
    mujoco.mj_forward(model, data)


def state_from_kinematics(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Reference state read from MuJoCo's own world-frame kinematics (after mj_forward):
    body position and quaternion (xpos, xquat) and the body's 6D velocity in the world
    frame from `mj_objectVelocity` (rotation first).  Independent of `from_mujoco_state`."""
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "body")
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, bid, vel, 0)
    return np.concatenate([data.xpos[bid], data.xquat[bid], vel[3:6], vel[0:3]])


# --------------------------------------------------------------------------- warnings
# At most this many of MuJoCo's warnings are kept per run (the first ones).
MAX_WARNINGS = 20


@contextlib.contextmanager
def captured_warnings():
    """Collect MuJoCo's warnings (e.g. "Nan, Inf or huge value in QACC") into a list
    instead of its default handler, which prints them to stdout (where they would break
    `--json`) and appends them to MUJOCO_LOG.TXT in the working directory
    (`mujoco.set_mju_user_warning`; the previous handler is restored on exit)."""
    caught: list[str] = []

    def keep(message: str) -> None:
        if len(caught) < MAX_WARNINGS:
            caught.append(str(message).strip())

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(keep)
    try:
        yield caught
    finally:
        mujoco.set_mju_user_warning(previous)


# --------------------------------------------------------------------------- running
@dataclass
class MujocoRun:
    """Per-step output of one MuJoCo run, in the reference's conventions.

    Row 0 is the initial state and row j the state after step j.  `impulses[j, k]` is
    the normal impulse (force × dt) of contact k that MuJoCo computed at state j and
    applied during step j → j + 1."""

    scene: Scene
    profile: str
    dt: float
    t: np.ndarray  # (N,)
    states: np.ndarray  # (N, 13): x, q wxyz, v, ω world
    impulses: np.ndarray  # (N, k)
    status: Status
    message: str
    stats: dict

    @property
    def forces(self) -> np.ndarray:
        return self.impulses / self.dt


def run_mujoco(
    scene: Scene,
    dt: float,
    t_end: float | None = None,
    profile: str = "tuned",
    half_step: bool | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> MujocoRun:
    """Step the scene's MuJoCo model with timestep dt until t_end (scene.run.t_end by
    default) and record every step.  `half_step` overrides the profile's leapfrog reading
    of velocities (`staggered_start`, `whole_step_velocities`).  `progress(done, total)`
    is called after every chunk of CHUNK_STEPS steps.  Ctrl-C stops the run at the end of
    the current chunk: status failed, stats["interrupted"], the steps so far kept.
    MuJoCo's warnings go to stats["mujoco_warnings"] (`captured_warnings`), not to
    stdout and MUJOCO_LOG.TXT."""
    with captured_warnings() as warnings:
        run = _run_mujoco(scene, dt, t_end, profile, half_step, progress)
    if warnings:
        run.stats["mujoco_warnings"] = warnings
    return run


class _RolloutStepper:
    """engines.stepping.Stepper over `mujoco.rollout`: one rollout call per chunk, one
    step more than kept, so that the contact force at the chunk's last state is known.
    rows[i] are rollout rows (time, qpos, qvel, ...); forces[i] the contact forces at
    the state of rows[i]."""

    def __init__(self, scene: Scene, model, data, dt: float) -> None:
        self.scene, self.model, self.dt = scene, model, dt
        self.nq, self.nv = model.nq, model.nv
        self.state = np.empty(mujoco.mj_stateSize(model, STATE_SPEC))
        mujoco.mj_getState(model, data, self.state, STATE_SPEC)
        self.data = data
        self.rows = [self.state[None].copy()]
        self.forces: list[np.ndarray] = []
        self.after = None  # the state one step past the last row, when known
        self.done = 0
        self.n_steps = 0  # set by run: the last chunk keeps its extra force row

    def advance(self, steps: int) -> Rows:
        done, dt = self.done, self.dt
        # from state `done`: st[i] = state done + i + 1, sd[i] = sensors at state done + i
        st, sd = rollout.rollout(self.model, self.data, self.state[None], nstep=steps + 1)
        st, sd = st[0], sd[0][:, 0::3]  # contact-frame force: normal component first
        ok = _valid_rows(st, done * dt, dt)
        if ok < steps + 1:
            self.rows.append(st[:ok])
            self.forces.append(sd[:ok])
            self.after = None
            why = f"MuJoCo's state became invalid (NaN or reset) at t = {(done + ok) * dt:.6g}"
            return Rows(st[:ok, 0], _states(st[:ok], self.nq, self.nv), broken=why)
        last = done + steps == self.n_steps
        self.rows.append(st[:steps])
        self.forces.append(sd[: steps + 1 if last else steps])
        self.after = st[steps]
        self.done = done + steps
        self.state = st[steps - 1].copy()
        return Rows(st[:steps, 0], _states(st[:steps], self.nq, self.nv))

    def cut(self, keep: int) -> None:
        rows = self.rows[-1]
        self.after = rows[keep] if keep < len(rows) else None
        self.rows[-1] = rows[:keep]
        self.forces[-1] = self.forces[-1][: keep + 1]

    def settle(self) -> float:  # rows are appended only after a whole rollout
        self.rows, self.after = [np.concatenate(self.rows)[: self.done + 1]], None
        return self.done * self.dt

    def recording(self, loop) -> Recording:
        return _recording(self)


def _build(scene: Scene, dt: float, profile: str, half_step: bool | None):
    """The Adapter builder of `run_fixed_step`: the model, its data at the initial state
    (at v(−h/2) under the leapfrog reading) and the rollout stepper."""
    if profile not in ENGINE_NAMES:
        raise ValueError(f"unknown MuJoCo profile {profile!r}; choose tuned or default")
    settings = contact_settings(scene, dt, profile)
    half = settings.half_step_velocities if half_step is None else half_step

    def build(n_steps: int) -> _RolloutStepper:
        model = load_model(scene, dt, profile)
        data = mujoco.MjData(model)
        y0 = initial_state(scene.initial)
        set_state(model, data, staggered_start(scene, y0, dt) if half else y0)
        stepper = _RolloutStepper(scene, model, data, dt)
        stepper.n_steps, stepper.settings, stepper.half, stepper.y0 = n_steps, settings, half, y0
        return stepper

    return build


def _recording(stepper: _RolloutStepper) -> Recording:
    """The rollout rows in the reference's conventions (whole-step velocities under the
    leapfrog reading), the contact impulses and the profile's parameters."""
    scene, dt, settings, half = stepper.scene, stepper.dt, stepper.settings, stepper.half
    nq, nv = stepper.nq, stepper.nv
    rows_all = np.concatenate(stepper.rows)
    t = dt * np.arange(len(rows_all))  # = MuJoCo's time, without its accumulated roundoff
    states = _states(rows_all, nq, nv)
    F = np.concatenate(stepper.forces) if stepper.forces else np.zeros((0, scene.n_contacts))
    if len(F) < len(t):  # a failed run: no force known at the last valid state
        F = np.concatenate([F, np.zeros((len(t) - len(F), scene.n_contacts))])
    impulses = np.clip(F[: len(t)], 0.0, None) * dt
    if half:
        after = stepper.after
        y_after = _states(after[None], nq, nv)[0] if after is not None else None
        states = whole_step_velocities(scene, states, y_after, impulses > 0.0, dt)
        # known exactly: MuJoCo started from v(−h/2) built from it
        states[0, L.VELOCITIES] = stepper.y0[L.VELOCITIES]
    stats = {
        "profile": settings.profile,
        "integrator": settings.integrator or "Euler (MuJoCo default)",
        "solref": list(settings.solref) if settings.solref else "MuJoCo default",
        "solimp": list(settings.solimp) if settings.solimp else "MuJoCo default",
        "half_step_velocities": half,
        "restitution_model": settings.restitution_model,
        "mujoco_version": mujoco.__version__,
    }
    return Recording(t, states, impulses, len(t) - 1, stats)


def _run_mujoco(scene, dt, t_end, profile, half_step, progress) -> MujocoRun:
    build = _build(scene, dt, profile, half_step)
    run = run_fixed_step(scene, dt, t_end, build, chunk_steps=CHUNK_STEPS, progress=progress)
    rec = run.recording
    return MujocoRun(
        scene, profile, dt, rec.t, rec.states, rec.impulses, run.status, run.message, run.stats
    )


def simulate_mujoco(
    scene: Scene,
    dt: float,
    t_end: float | None = None,
    profile: str = "tuned",
    sample_every: int = 1,
    half_step: bool | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the scene in MuJoCo (`run_mujoco`) and return its Trajectory: samples every
    step (thinned by `sample_every`), impacts = onsets of contact force per contact point
    (engines.base).  stats: wall_time_s (model build + stepping + conversion, not the
    Trajectory assembly), steps, steps_per_s (stepping alone), and the profile's
    parameters."""
    run = run_mujoco(
        scene, dt, t_end=t_end, profile=profile, half_step=half_step, progress=progress
    )
    return build_trajectory(
        scene,
        ENGINE_NAMES[profile],
        dt,
        run.t,
        run.states,
        run.impulses,
        run.status,
        run.message,
        run.stats,
        sample_every,
    )


def staggered_start(scene: Scene, y0: np.ndarray, dt: float) -> np.ndarray:
    """Initial MuJoCo state for the leapfrog reading: velocities at t = −h/2,
    [v; ω](−h/2) = [v; ω](0) − (h/2)·[v̇; ω̇]_free(y0) (gravity and gyroscopic term).

    MuJoCo's Euler step is symplectic Euler, v⁺ = v + h a(x, v), x⁺ = x ⊕ h v⁺: with
    the stored velocity read as v(t − h/2) it is the leapfrog (Störmer–Verlet) scheme,
    whose positions are second-order accurate; read as v(t) they lag by (h/2)·a, which
    under gravity makes every flight's height low by g h t/2 and its impacts early by
    ~g h t/(2|vₙ|) (first order in h)."""
    y = np.array(y0, dtype=float)
    y[L.VELOCITIES] -= 0.5 * dt * free_acceleration(scene, y0)[0]
    return y


def whole_step_velocities(
    scene: Scene,
    states: np.ndarray,
    after: np.ndarray | None,
    active: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Velocities at whole steps from MuJoCo's half-step velocities.

    Row n of `states` holds x(t_n) and v(t_n − h/2); `after` is the state one step past
    the last row (None when unknown).  In flight and in sustained contact
    v(t_n) = (v(t_n − h/2) + v(t_n + h/2))/2 (exact for constant acceleration).  On a row
    where a contact starts, the one-step damper applies an impact between those two
    half steps, so the mean would mix pre- and post-impact velocities: there
    v(t_n) = v(t_n + h/2) − (h/2)·a_free (post-impact, as the exact motion is at t_n,
    after the gap's zero crossing)."""
    out = states.copy()
    nxt = np.empty_like(states[:, L.VELOCITIES])
    nxt[:-1] = states[1:, L.VELOCITIES]
    if after is not None:
        nxt[-1] = after[L.VELOCITIES]
    else:
        nxt[-1] = states[-1, L.VELOCITIES] + dt * free_acceleration(scene, states[-1])[0]
    out[:, L.VELOCITIES] = 0.5 * (states[:, L.VELOCITIES] + nxt)
    onset = active.any(axis=1)
    onset[1:] &= (active[1:] & ~active[:-1]).any(axis=1)
    for j in np.flatnonzero(onset):
        y = states[j].copy()
        y[L.VELOCITIES] = nxt[j]
        out[j, L.VELOCITIES] = nxt[j] - 0.5 * dt * free_acceleration(scene, y)[0]
    return out


def _valid_rows(st: np.ndarray, t_start: float, dt: float) -> int:
    """Number of leading rollout rows that are finite and not a MuJoCo reset (MuJoCo
    resets the data, time included, when its accelerations blow up)."""
    finite = np.isfinite(st).all(axis=1)
    expected = t_start + dt * np.arange(1, len(st) + 1)
    sane = finite & (np.abs(st[:, 0] - expected) <= 0.5 * dt)
    bad = np.flatnonzero(~sane)
    return int(bad[0]) if bad.size else len(st)


def _states(rows: np.ndarray, nq: int, nv: int) -> np.ndarray:
    """Reference states of rollout rows (time, qpos, qvel, ...)."""
    return from_mujoco_state(rows[:, 1 : 1 + nq], rows[:, 1 + nq : 1 + nq + nv])
