"""MJX adapter (`mujoco-mjx` on JAX, the [mjx] extra): the scene's MuJoCo model run by
MuJoCo XLA, in float64 (`mjx`) or float32 (`mjx-f32`), and returned as a `Trajectory` in
the reference's conventions.

Same model as `mujoco`.  The model is the `mujoco` engine's own MjSpec
(engines/mujoco_model.build_spec, tuned profile: one-step damper, Euler, leapfrog reading
of velocities), compiled and put on the device with `mjx.put_model`, so that a difference
between `mujoco` and `mjx` is the variant's, not the model's.  One flag differs: MJX
refuses `diagexact` (the exact diagonal of A = J M⁻¹ Jᵀ in the regulariser), so it is
off; with d = 0.9999 the regulariser is 1e-4 of A, and the difference it makes is
O(1e-4) of a contact impulse's regularisation (docs/engines.md "MJX").

Precision.  `mjx` enables JAX's float64 (`jax.config.update("jax_enable_x64", True)`)
and reproduces MuJoCo C; `mjx-f32` runs the same model with float32 arrays (the
precision a GPU batch uses).  JAX's x64 flag is global to the process: each run sets it
for its own precision before it builds its arrays and compiles.

Stepping.  `jax.lax.scan` takes CHUNK_STEPS steps per compiled call and returns, per
step, qpos, qvel and the contact forces; the carry is cast back to the input's dtypes
after each step (MJX returns some integer fields, e.g. `contact.geom`, as int64).
Contact force: MJX's contact sensors read 0, so the normal force of contact k is read
from `efc_force` at the contact's constraint row (`contact.efc_address`; condim 1: one row
per contact); MJX's contact list has a fixed slot per geom pair, mapped once to the
scene's contact numbering.

Timing.  The JIT compilation (tens of seconds on CPU) is reported as
stats["compile_time_s"] and left out of wall_time_s (engines.stepping.run_fixed_step).

Batches.  `simulate_mjx_batch` runs many scenes with one model (scenes that differ only
in their initial state: the same body, ground, γ, gravity) as one vmapped scan; scenes
with different models are run group by group.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Sequence

import numpy as np

from reference.core import layout as L
from reference.geometry import initial_state
from reference.scene import Scene
from reference.trajectory import Trajectory

from .mujoco import from_mujoco_state, staggered_start, to_mujoco_state, whole_step_velocities
from .mujoco_model import build_spec, contact_geom_pairs, contact_settings
from .quiet import quiet_import
from .stepping import (
    NON_FINITE,
    Recording,
    Rows,
    check_dt,
    first_failure,
    simulate_fixed_step,
    step_count,
)

PRECISIONS = {"float64": "mjx", "float32": "mjx-f32"}
# Steps per compiled scan call: every chunk runs this one scan (`run_chunk`).
CHUNK_STEPS = 2_000


def _jax(precision: str):
    """jax and mjx with JAX's x64 flag set for `precision`."""
    import jax

    jax.config.update("jax_enable_x64", precision == "float64")
    # it prints "Failed to import warp" (its optional Warp backend) to stdout on import
    mjx = quiet_import("mujoco.mjx")
    return jax, mjx


def build_model(scene: Scene, dt: float):
    """The `mujoco` engine's tuned MjSpec of the scene with diagexact off (MJX refuses
    it), compiled to an MjModel."""
    import mujoco

    spec = build_spec(scene, dt, "tuned")
    spec.option.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_DIAGEXACT)
    return spec.compile()


def contact_slots(model, scene: Scene, geoms: np.ndarray) -> np.ndarray:
    """Scene contact index of each of MJX's contact slots (−1 for a slot that is none of
    the scene's contacts), from the geom pair of each slot (`geoms`, MJX's
    `contact.geom`: fixed per slot, read from the data a compiled step returns, so no
    eager, uncompiled MJX call is made)."""
    import mujoco

    name = {i: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in range(model.ngeom)}
    index = {}
    for k, (g1, g2) in enumerate(contact_geom_pairs(scene)):
        index[frozenset((g1, g2))] = k
    pairs = np.asarray(geoms).reshape(-1, 2)
    return np.array([index.get(frozenset((name.get(a), name.get(b))), -1) for a, b in pairs])


@functools.cache
def _scan(precision: str, steps: int, batched: bool):
    """A jitted function (model, data) → (data, (qpos, qvel, efc forces per contact
    slot)) that takes `steps` steps; vmapped over data when `batched`.  Output j holds the
    state after step j and the forces MJX computed at the state before it (mjx.step is
    forward, then Euler): MuJoCo's convention of engines.mujoco."""
    jax, mjx = _jax(precision)

    def run(m, d):
        dtypes = jax.tree_util.tree_map(lambda x: x.dtype, d)

        def step(carry, _):
            nxt = mjx.step(m, carry)
            nxt = jax.tree_util.tree_map(lambda x, t: x.astype(t), nxt, dtypes)
            forces = nxt._impl.efc_force[nxt._impl.contact.efc_address]
            return nxt, (nxt.qpos, nxt.qvel, forces)

        return jax.lax.scan(step, d, None, length=steps)

    fn = jax.vmap(run, in_axes=(None, 0)) if batched else run
    return jax.jit(fn)


_COMPILED: dict = {}


def compiled_scan(precision: str, steps: int, batched: bool, mx, dx) -> tuple[Callable, float]:
    """The scan compiled for these arrays' structure, shapes and dtypes (kept for the
    process), and the seconds spent compiling it now (0 when it was compiled before)."""
    import jax

    leaves, tree = jax.tree_util.tree_flatten((mx, dx))
    key = (precision, steps, batched, tree, tuple((x.shape, str(x.dtype)) for x in leaves))
    if key in _COMPILED:
        return _COMPILED[key], 0.0
    t0 = time.perf_counter()
    fn = _scan(precision, steps, batched).lower(mx, dx).compile()
    _COMPILED[key] = fn
    return fn, time.perf_counter() - t0


def run_chunk(precision: str, steps: int, batched: bool, mx, dx):
    """`steps` ≤ CHUNK_STEPS steps from dx (batched: dx stacked over scenes) by the one
    compiled scan of CHUNK_STEPS steps: (the data at the scan's end, past the steps
    when steps < CHUNK_STEPS; (qpos, qvel, forces) of the steps, step axis 0 (1 after
    the batch's); the seconds spent compiling now).  JAX compiles a program per scan
    length (docs/engines.md, "MJX"): with one length, runs of every length (a run's
    last chunk, fidelity's scales and pilot runs) share one program; a shorter chunk
    computes the steps past it and drops them (their time counts in the run's wall
    time)."""
    if not 0 < steps <= CHUNK_STEPS:
        raise ValueError(f"a chunk is 1 to {CHUNK_STEPS} steps, not {steps}")
    fn, seconds = compiled_scan(precision, CHUNK_STEPS, batched, mx, dx)
    dx_end, out = fn(mx, dx)
    if steps < CHUNK_STEPS:
        out = tuple(x[:, :steps] if batched else x[:steps] for x in out)
    return dx_end, out, seconds


class _Stepper:
    """engines.stepping.Adapter over MJX: one compiled scan per chunk."""

    def __init__(self, scene: Scene, dt: float, precision: str, n_steps: int):
        jax, mjx = _jax(precision)
        import mujoco

        self.scene, self.dt, self.precision = scene, dt, precision
        self.model = build_model(scene, dt)
        self.slots: np.ndarray | None = None  # from the first chunk's data
        self.y0 = initial_state(scene.initial)
        data = mujoco.MjData(self.model)
        qpos, qvel = to_mujoco_state(staggered_start(scene, self.y0, dt))
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(self.model, data)
        self.mx = mjx.put_model(self.model)
        self.dx = mjx.put_data(self.model, data)
        self.rows = [from_mujoco_state(qpos, qvel)]
        self.forces: list[np.ndarray] = []
        self.compile_s = 0.0
        self.first = 1

    def advance(self, steps: int) -> Rows:
        if self.dx is None:
            raise RuntimeError("the MJX run's last chunk has run: no steps follow it")
        self.first = len(self.rows)
        dx, (qpos, qvel, f), seconds = run_chunk(self.precision, steps, False, self.mx, self.dx)
        self.compile_s += seconds
        if self.slots is None:
            self.slots = contact_slots(self.model, self.scene, dx._impl.contact.geom)
        self.dx = dx if steps == CHUNK_STEPS else None  # None: past the run's end
        states = from_mujoco_state(np.asarray(qpos, float), np.asarray(qvel, float))
        self.rows.extend(states)
        self.forces.extend(_per_contact(np.asarray(f, float), self.slots, self.scene.n_contacts))
        t = self.dt * np.arange(self.first, len(self.rows))
        return Rows(t, states)

    def cut(self, keep: int) -> None:
        del self.rows[self.first + keep :]

    def settle(self) -> float:
        return (len(self.rows) - 1) * self.dt

    def recording(self, loop) -> Recording:
        rec = _recording(self.scene, self.dt, np.array(self.rows), self.forces, self.y0)
        rec.stats.update(
            {"precision": self.precision, "compile_time_s": self.compile_s, **_versions()}
        )
        return rec


def _per_contact(forces: np.ndarray, slots: np.ndarray, n_contacts: int) -> np.ndarray:
    """(steps, slots) efc forces → (steps, n_contacts) normal forces per scene contact."""
    out = np.zeros(forces.shape[:-1] + (n_contacts,))
    for i, k in enumerate(slots):
        if k >= 0:
            out[..., k] += np.clip(forces[..., i], 0.0, None)
    return out


def _recording(scene, dt, states, forces, y0) -> Recording:
    """Rows in the reference's conventions: the leapfrog reading of MuJoCo's tuned
    profile (whole-step velocities), impulses = force × dt on the row of the state the
    force was computed at."""
    n_rows = len(states)
    impulses = np.zeros((n_rows, scene.n_contacts))
    F = np.asarray(forces)[:n_rows] if len(forces) else np.zeros((0, scene.n_contacts))
    impulses[: len(F)] = F * dt
    states = whole_step_velocities(scene, states, None, impulses > 0.0, dt)
    states[0, L.VELOCITIES] = y0[L.VELOCITIES]
    settings = contact_settings(scene, dt, "tuned")
    stats = {
        "profile": "tuned (diagexact off)",
        "restitution_model": settings.restitution_model,
        "half_step_velocities": True,
    }
    return Recording(dt * np.arange(n_rows), states, impulses, n_rows - 1, stats)


def _versions() -> dict:
    from importlib import metadata

    out = {}
    for dist in ("mujoco-mjx", "jax"):
        try:
            out[f"{dist.replace('-', '_')}_version"] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[f"{dist.replace('-', '_')}_version"] = None
    return out


def simulate_mjx(
    scene: Scene,
    dt: float,
    t_end: float | None = None,
    precision: str = "float64",
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the scene in MJX at fixed step dt until t_end (scene.run.t_end by default)
    through the fixed-step driver (engines.stepping); stats: the driver's (wall_time_s
    without the JIT compilation), compile_time_s, precision, versions."""
    if precision not in PRECISIONS:
        raise ValueError(f"unknown MJX precision {precision!r}; choose float64 or float32")
    dt = check_dt(dt)

    def build(n_steps: int) -> _Stepper:
        return _Stepper(scene, dt, precision, n_steps)

    return simulate_fixed_step(
        scene,
        PRECISIONS[precision],
        dt,
        t_end,
        build,
        chunk_steps=CHUNK_STEPS,
        progress=progress,
    )


# --------------------------------------------------------------------------- batches
def _model_key(scene: Scene) -> tuple:
    """Scenes with equal keys share one MJX model (they differ only in initial state)."""
    return (scene.body, scene.ground, scene.restitution, scene.gravity)


def simulate_mjx_batch(
    scenes: Sequence[Scene],
    *,
    dt: float,
    t_end: float | None = None,
    precision: str = "float64",
) -> list[Trajectory]:
    """Many scenes, one dt, one call: the scenes that share a model (`_model_key`) run as
    one vmapped scan per chunk; each result is the Trajectory `simulate_mjx` gives for
    that scene alone (the same rows, impacts and status; tested on CPU).  t_end: the
    same for every scene (each scene's own scene.run.t_end when None)."""
    dt = check_dt(dt)
    out: list[Trajectory | None] = [None] * len(scenes)
    groups: dict[tuple, list[int]] = {}
    for i, sc in enumerate(scenes):
        t_run = sc.run.t_end if t_end is None else float(t_end)
        groups.setdefault((_model_key(sc), t_run), []).append(i)
    for (_, t_run), idx in groups.items():
        for i, traj in zip(
            idx, _run_group([scenes[i] for i in idx], dt, t_run, precision), strict=True
        ):
            out[i] = traj
    return out  # type: ignore[return-value]


def _run_group(scenes: list[Scene], dt: float, t_end: float, precision: str) -> list[Trajectory]:
    """One vmapped run of scenes sharing a model; the run loop's checks applied after
    (a failed scene is cut at its first failing row, as run_steps would)."""
    import jax.numpy as jnp
    import mujoco

    from reference.trajectory import Status

    from .base import build_trajectory

    jax, mjx = _jax(precision)
    t_wall = time.perf_counter()
    scene0 = scenes[0]
    model = build_model(scene0, dt)
    mx = mjx.put_model(model)
    y0s = [initial_state(sc.initial) for sc in scenes]
    datas, rows0 = [], []
    for sc, y0 in zip(scenes, y0s, strict=True):
        data = mujoco.MjData(model)
        qpos, qvel = to_mujoco_state(staggered_start(sc, y0, dt))
        data.qpos[:], data.qvel[:] = qpos, qvel
        mujoco.mj_forward(model, data)
        datas.append(mjx.put_data(model, data))
        rows0.append(from_mujoco_state(qpos, qvel))
    dx = jax.tree_util.tree_map(lambda *xs: jnp.stack(xs), *datas)
    n_steps = step_count(t_end, dt)
    qs, vs, fs = [], [], []
    compile_s, done = 0.0, 0
    while done < n_steps:
        steps = min(CHUNK_STEPS, n_steps - done)  # (shorter: the last chunk)
        dx, (q, v, f), seconds = run_chunk(precision, steps, True, mx, dx)
        compile_s += seconds
        if done == 0:  # every scene of the group has the model's slots
            slots = contact_slots(model, scene0, np.asarray(dx._impl.contact.geom)[0])
        qs.append(np.asarray(q, float))
        vs.append(np.asarray(v, float))
        fs.append(np.asarray(f, float))
        done += steps
    wall = time.perf_counter() - t_wall - compile_s
    Q, V, Fs = (np.concatenate(x, axis=1) for x in (qs, vs, fs))
    out = []
    for b, (sc, y0) in enumerate(zip(scenes, y0s, strict=True)):
        states = np.concatenate([rows0[b][None], from_mujoco_state(Q[b], V[b])])
        forces = _per_contact(Fs[b], slots, sc.n_contacts)
        status, message = Status.T_END, f"reached t_end = {t_end:g}"
        failure = first_failure(sc, states)
        if failure is not None:
            row, what = failure
            keep = row if what == NON_FINITE else row + 1
            message = f"{what} at t = {row * dt:.6g}"
            states, status = states[:keep], Status.FAILED
        rec = _recording(sc, dt, states, forces, y0)
        stats = {
            "wall_time_s": wall / len(scenes),
            "steps": rec.steps,
            "steps_per_s": None,
            **rec.stats,
            "precision": precision,
            "compile_time_s": compile_s,
            "batch_size": len(scenes),
            "batch_wall_time_s": wall,
            **_versions(),
        }
        out.append(
            build_trajectory(
                sc,
                PRECISIONS[precision],
                dt,
                rec.t,
                rec.states,
                rec.impulses,
                status,
                message,
                stats,
            )
        )
    return out
