"""PyBullet model of a scene: the same body and ground, frictionless point contacts,
run at a fixed step and returned as a `Trajectory` in the reference's conventions.

Geometry (docs/engines.md "Geometry that is exactly a point contact"):

- `flat`: one `<collision><sphere>` of radius r at every vertex, in a URDF (the
  collision-shape-array API keeps only 16 shapes), and the ground plane lowered by r.
  Sphere–plane contact has the plane's normal e_z and acts on the vertex's vertical line,
  so it is the frictionless point contact at the vertex: the engine's contact distance
  equals the reference's gap z + (R r_k)_z.
- `three_point`: three fixed spheres of radius r with their tops at the bumps b_k, and a
  thin box on the body whose bottom face is the body's mid-plane.  Sphere–box contact
  has the face normal e3; its distance is the reference's gap (x − b_k)·e3 minus
  r (1 − cos α) (measured: −1.002000e-4 for gap −1e-4 at α = 0.02, normal e3 to 4
  digits printed) and its lever is off by r sin α, both negligible for r ≪ a.
- `bumpy` (both kinds): the plane with the vertex spheres, and spheres with their tops at
  the bumps (x, y, h) under a thin face.  Bullet filters collisions per link, not per
  shape, so the kinds are kept apart by geometry instead of masks: the face is a
  cylinder of the polygon's inscribed radius a cos(π/n) (`FACE_INSCRIBED`), whose
  bottom edge stays at or above the lowest vertex at every tilt, so it cannot reach the
  plane (lowered by r) before a vertex sinks r into it; the vertex spheres reach a bump
  only if the rim passes over it (bumps at b ≤ a/2 and a centre near the axis: never).
  Bumps between a cos(π/n) and a from the centre are out of the face's reach.

Inertia m(ρa)² diag(1, 1, 2) is written into the URDF and loaded with
URDF_USE_INERTIA_FROM_FILE; the inertial frame is the link frame, so PyBullet's base
pose is the centre of mass with principal axes.  Friction and damping are 0 and the
body never sleeps.

Profiles (how γ maps to the engine):

- `tuned` (engine name "pybullet"): the settings (docs/engines.md) that make a vertex
  impact Newtonian with coefficient γ; each value is explained where it is set.
- `default` ("pybullet-default"): what a typical user writes: the same body with
  restitution set on it (pair restitution γ, see `_restitutions`) and otherwise the
  engine's defaults (reduced coordinates from `loadURDF`, default solver parameters).

Contact impulses: `getContactPoints()[i][9]` is the normal force of the last step
(impulse / dt with numSubSteps = 0).  A manifold point that the solver did not process
(farther than the contact processing threshold) keeps its stale impulse in maximal
coordinates, so a point counts only when its distance is within that threshold.
Contact k of the scene is found from the point on the body: the vertex whose body-frame
angle is nearest (flat), or the bump body it touches (three_point).

Speed: on flat ground the state is read every step only while the body has contact
points in its manifold (within the contact breaking threshold of the ground), in flight
every `sample_every` steps; on three_point ground every step (sphere–box points appear
only at penetration, too late to mark the step before an onset).  Rows passed to
`build_trajectory` are every step around contact activity (the step before an onset,
the active steps, the step after) and the regular samples: impacts see every step that
matters, and the per-row cost of `build_trajectory` is not paid for quiet flight.

Not set, so at Bullet's defaults in both profiles: solver iterations (50; a single
impact needs one; three resting contacts reach m g / 3 to 1e-7 at dt = 1e-3 and 5e-10
at dt = 1e-4, relative), contact ERP of
the split-impulse position correction, deterministic overlapping pairs.
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from engines.quiet import quiet_import
from engines.stepping import (
    SPHERE_RADIUS_FRACTION,
    Recording,
    Rows,
    check_dt,
    simulate_fixed_step,
    step_count,
)
from reference import quaternion as qt
from reference.core import layout as L
from reference.geometry import energies, initial_state
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

pb = quiet_import("pybullet")  # it prints its build time to the terminal on import

PROFILES = ("tuned", "default")
ENGINE_NAMES = {"tuned": "pybullet", "default": "pybullet-default"}

# Steps per chunk of the run loop (engines.stepping): progress and the fall-through
# check come after every chunk.
CHUNK_STEPS = 1_000
# Thickness of the body face used on three_point ground, relative to a.  Only its bottom
# face (the mid-plane) touches the bumps; thick enough that a bump never crosses the
# whole box in one step of a sane run.
FACE_THICKNESS = 0.05


@dataclass(frozen=True)
class Handles:
    """Ids of one PyBullet world built from a scene."""

    client: int
    body: int
    ground: tuple[int, ...]  # the plane (if the ground has one), then the bump bodies
    processing_threshold: float  # contact points farther than this carry no force


# ----------------------------------------------------------------------------- model


def body_urdf(scene: Scene, sphere_radius: float) -> str:
    """URDF of the body: inertial frame = link frame (centre of mass, principal axes),
    mass m, inertia m(ρa)² diag(1, 1, 2); collisions: a sphere at every vertex
    a(cos 2πk/n, sin 2πk/n, 0) for the rim vertices of a ground, and a thin box whose
    bottom face is the mid-plane z = 0 for its floor points
    (reference.contact_kinds).  Numbers are written as plain floats."""
    b = scene.body
    i1, i2, i3 = b.inertia_diag

    def f(x: float) -> str:
        return repr(float(x))

    lines = [
        '<?xml version="1.0"?>',
        '<robot name="polygon">',
        '  <link name="body">',
        "    <inertial>",
        '      <origin xyz="0 0 0" rpy="0 0 0"/>',
        f'      <mass value="{f(b.mass)}"/>',
        f'      <inertia ixx="{f(i1)}" ixy="0" ixz="0" iyy="{f(i2)}" iyz="0" izz="{f(i3)}"/>',
        "    </inertial>",
    ]
    contacts = scene.contacts
    for x, y, _ in contacts.rim_points:  # rim vertices: spheres on the body
        lines += [
            "    <collision>",
            f'      <origin xyz="{f(x)} {f(y)} 0" rpy="0 0 0"/>',
            f'      <geometry><sphere radius="{f(sphere_radius)}"/></geometry>',
            "    </collision>",
        ]
    if len(contacts.floor_points):  # floor points: touch the body's face
        h = FACE_THICKNESS * b.radius
        if contacts.has_plane:  # both kinds: a face that never reaches the plane
            rf = b.radius * math.cos(math.pi / b.n)
            shape = f'<cylinder radius="{f(rf)}" length="{f(h)}"/>'
        else:
            side = 2.0 * b.radius  # a square face that covers the disk
            shape = f'<box size="{f(side)} {f(side)} {f(h)}"/>'
        lines += [
            "    <collision>",
            f'      <origin xyz="0 0 {f(h / 2)}" rpy="0 0 0"/>',
            f"      <geometry>{shape}</geometry>",
            "    </collision>",
        ]
    lines += ["  </link>", "</robot>", ""]
    return "\n".join(lines)


def _restitutions(scene: Scene) -> tuple[float, float]:
    """(body, ground) restitution.  Bullet combines a pair's restitution as the product
    of the two objects' values, so the body carries γ and the ground 1."""
    return scene.restitution, 1.0


def _engine_parameters(scene: Scene, dt: float, profile: str) -> dict:
    """`setPhysicsEngineParameter` keywords of a profile."""
    params = {
        "fixedTimeStep": dt,
        # 0: one internal step of exactly dt per stepSimulation (with k > 1 substeps the
        # reported contact force would also be wrong by the factor k).
        "numSubSteps": 0,
    }
    if profile == "default":
        # Bullet's default, set explicitly: the value is global to the process and a
        # tuned run before this one would otherwise leave its own value behind.
        params["contactBreakingThreshold"] = 0.02
        return params
    g = scene.gravity
    params.update(
        # Manifold points are made and kept within this distance.  Only points within
        # the processing threshold below carry force.  flat: sphere–plane points appear
        # from this distance on, so a few steps' travel of the fastest vertex (bound
        # from the energy) suffices instead of 0.02 m, and fewer points and state reads
        # are needed (`simulate_pybullet`).  three_point: sphere–box points appear only
        # once penetrating and the manifold's cache within 0.02 m is what lets a bump
        # rest at a small positive distance (with a smaller value the resting contact
        # flickers: 516 instead of 78 onsets in 1 s of the three-point-disk scene), so
        # Bullet's default is kept.  Global to the process (see the default profile).
        contactBreakingThreshold=(
            _breaking_threshold(scene, dt) if scene.contacts.rim_only else 0.02
        ),
        # Split impulse: penetration is removed by a separate pseudo-velocity, so the
        # position correction adds no velocity (no energy) to the bounce.  Threshold 0:
        # use it for every penetration (default −0.04 m: only past 4 cm, never here).
        # Without it γ = 0.5 came out as 0.540 (dt = 1e-4, impact at 0.2).
        useSplitImpulse=1,
        splitImpulsePenetrationThreshold=0.0,
        # No slop: a contact counts as penetrating from distance 0, not from −1e-5 m,
        # so a resting vertex sits at gap 0 and an impact starts at gap 0 (with the
        # default, the resting disk sank by 1e-5 and pentagon-bounce went wrong after
        # 4 impacts).
        contactSlop=0.0,
        # No warm starting: each step's impulses are solved from zero, so an impulse
        # left on a manifold point (even a stale one, see `simulate_pybullet`) is never
        # replayed.  Measured effect of the default 0.85 instead: none on γ or on the
        # impact sequences of the built-in scenes (50 solver iterations converge anyway).
        warmStartingFactor=0.0,
        # Below this approach speed Bullet applies no restitution (default 0.2 m/s:
        # every impact of the built-in scenes would be plastic).  A resting vertex
        # gains g·dt of approach speed per step from gravity; with a threshold under
        # that it bounces at every step (threshold 0: resting forces off by 0.7 %).
        # 2 g dt makes those micro-impacts plastic and keeps every impact whose
        # flight would last more than ~2 steps.
        restitutionVelocityThreshold=2.0 * g * dt,
    )
    return params


def _breaking_threshold(scene: Scene, dt: float) -> float:
    """8 dt × a bound of any vertex's speed, and at least 8 × the processing threshold.

    With kinetic energy K ≤ E(0) (γ ≤ 1, potential ≥ 0 above the ground),
    |v + ω × r| ≤ |v| + a|ω| ≤ √(2E/m) + a √(2E/I₁) = √(2E/m) (1 + 1/ρ); g dt is added
    for a body starting at rest."""
    ke, pe = energies(scene, initial_state(scene.initial))
    energy = max(float(ke[0] + pe[0]), 0.0)
    v_bound = math.sqrt(2.0 * energy / scene.body.mass) * (1.0 + 1.0 / scene.body.gyration)
    v_bound += scene.gravity * dt
    return max(8.0 * v_bound * dt, 16.0 * scene.gravity * dt * dt)


def _processing_threshold(scene: Scene, dt: float, profile: str) -> float | None:
    """Contact processing threshold of both bodies (tuned only), ≈ 2 g dt².

    Bullet processes every manifold point closer than this as a (speculative) contact:
    for a point at distance d > 0 it allows an approach of d/dt and applies restitution
    already, so a large value (default: 1e18) makes vertices bounce before they touch
    and kills restitution (measured: e = 0 for γ = 0.5).  It must still admit a vertex
    resting on the ground, which gravity moves down by g dt² per step; 2 g dt² keeps
    those and nothing else."""
    if profile == "default":
        return None
    return 2.0 * scene.gravity * dt * dt


def _write_urdf(scene: Scene, directory: str) -> str:
    path = os.path.join(directory, "body.urdf")
    with open(path, "w") as fh:
        fh.write(body_urdf(scene, SPHERE_RADIUS_FRACTION * scene.body.radius))
    return path


def build_world(scene: Scene, dt: float, profile: str = "tuned") -> Handles:
    """Connect a DIRECT client and build the scene's body and ground in it.

    The caller owns the client and must `pybullet.disconnect(handles.client)`."""
    if profile not in PROFILES:
        raise ValueError(f"unknown PyBullet profile {profile!r}; choose from {PROFILES}")
    client = pb.connect(pb.DIRECT)
    try:
        return _build(client, scene, dt, profile)
    except BaseException:
        pb.disconnect(client)
        raise


def _build(client: int, scene: Scene, dt: float, profile: str) -> Handles:
    cid = {"physicsClientId": client}
    g = scene.gravity
    a = scene.body.radius
    r = SPHERE_RADIUS_FRACTION * a
    tuned = profile == "tuned"
    # Maximal coordinates (btRigidBody) in the tuned profile: the rigid-body solver is
    # the one whose split impulse and restitution the settings above control.  The
    # default profile keeps loadURDF's default, reduced coordinates (btMultiBody).
    maximal = tuned
    pb.setGravity(0.0, 0.0, -g, **cid)
    pb.setPhysicsEngineParameter(**_engine_parameters(scene, dt, profile), **cid)

    y0 = initial_state(scene.initial)
    x0, q0 = y0[L.POSITION], y0[L.QUATERNION]
    with tempfile.TemporaryDirectory(prefix="pybullet-scene-") as tmp:
        body = pb.loadURDF(
            _write_urdf(scene, tmp),
            basePosition=[float(v) for v in x0],
            baseOrientation=[float(q0[1]), float(q0[2]), float(q0[3]), float(q0[0])],
            # implicit cylinder: a true btCylinderShape for the bumpy ground's face (by default
            # the importer makes a convex hull whose margin puts its bottom 1e-3 low)
            flags=pb.URDF_USE_INERTIA_FROM_FILE | pb.URDF_USE_IMPLICIT_CYLINDER,
            useMaximalCoordinates=maximal,
            **cid,
        )
    v0, w0 = y0[L.VELOCITY], y0[L.ANGULAR_VELOCITY]
    pb.resetBaseVelocity(body, [float(v) for v in v0], [float(v) for v in w0], **cid)

    ground: tuple[int, ...] = ()  # the plane first (if any), then the bumps in order
    if scene.contacts.has_plane:
        plane = pb.createCollisionShape(pb.GEOM_PLANE, **cid)
        ground += (
            pb.createMultiBody(
                0.0, plane, basePosition=[0.0, 0.0, -r], useMaximalCoordinates=maximal, **cid
            ),
        )
    if len(scene.contacts.floor_points):
        bump = pb.createCollisionShape(pb.GEOM_SPHERE, radius=r, **cid)
        ground += tuple(
            pb.createMultiBody(
                0.0,
                bump,
                basePosition=[float(x), float(y), float(z) - r],  # its top at the point
                useMaximalCoordinates=maximal,
                **cid,
            )
            for x, y, z in scene.contacts.floor_points
        )

    e_body, e_ground = _restitutions(scene)
    threshold = _processing_threshold(scene, dt, profile)
    for uid, e in [(body, e_body)] + [(gid, e_ground) for gid in ground]:
        extra = {} if threshold is None else {"contactProcessingThreshold": threshold}
        pb.changeDynamics(
            uid,
            -1,
            restitution=e,
            lateralFriction=0.0,
            spinningFriction=0.0,
            rollingFriction=0.0,
            linearDamping=0.0,
            angularDamping=0.0,
            **extra,
            **cid,
        )
    # A resting body must not be put to sleep (it would freeze the end of the motion).
    pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING, **cid)
    return Handles(
        client=client,
        body=body,
        ground=ground,
        processing_threshold=math.inf if threshold is None else threshold,
    )


# ----------------------------------------------------------------------------- state


def read_state(h: Handles) -> np.ndarray:
    """The body's 13-state in the reference's conventions: centre of mass, quaternion
    (w, x, y, z) body → world (PyBullet gives x, y, z, w), velocity and ω in the world
    frame."""
    pos, orn = pb.getBasePositionAndOrientation(h.body, physicsClientId=h.client)
    v, w = pb.getBaseVelocity(h.body, physicsClientId=h.client)
    return np.array([*pos, orn[3], orn[0], orn[1], orn[2], *v, *w])


def _contact_index_flat(points: np.ndarray, x: np.ndarray, q: np.ndarray, n: int) -> np.ndarray:
    """Vertex k whose body-frame angle 2πk/n is nearest to each world point on the body."""
    d = qt.rotate(qt.conjugate(q), points - x)  # rows: Rᵀ (p − x)
    ang = np.arctan2(d[:, 1], d[:, 0])
    return np.rint(ang * n / (2.0 * math.pi)).astype(int) % n


def contact_forces(h: Handles, scene: Scene) -> np.ndarray:
    """Normal force on every scene contact (vertex k or bump k) in the last step, read
    and assigned as `simulate_pybullet` does (impulse = force × dt)."""
    forces = np.zeros(scene.n_contacts)
    ground_index = {gid: k for k, gid in enumerate(h.ground)}
    y = read_state(h)
    contacts = scene.contacts
    for cp in pb.getContactPoints(bodyA=h.body, physicsClientId=h.client):
        if cp[9] > 0.0 and cp[8] <= h.processing_threshold:
            g = ground_index[cp[2]]
            if contacts.has_plane and g == 0:
                k = _contact_index_flat(
                    np.array([cp[5]]), y[L.POSITION], y[L.QUATERNION], scene.body.n
                )[0]
            else:
                k = contacts.n_rim + g - int(contacts.has_plane)
            forces[k] += cp[9]
    return forces


# ----------------------------------------------------------------------------- run


class _Stepper:
    """engines.stepping.Stepper over one PyBullet world: steps one at a time, collects
    the processed contact points with a force as hits (step j, bump k, point on the body
    x, y, z, normal force) and records the state (step index and raw pose and velocity
    tuples): on flat ground every step while the body has manifold points (they appear a
    few steps before a vertex can touch, so the step before every onset is recorded), on
    the sample grid otherwise; sphere–box points appear only at penetration, so on
    three_point ground every step."""

    def __init__(
        self, h: Handles, dt: float, sample_every: int, every_step: bool, n_steps: int
    ) -> None:
        self.h, self.dt, self.sample_every, self.every_step = h, dt, sample_every, every_step
        self.n_steps = n_steps
        self.ground_index = {gid: k for k, gid in enumerate(h.ground)}
        self.j = self.first = 0
        self.rows_j: list[int] = [0]
        self.rows_raw: list[tuple] = [self._read()]
        self.hits: list[tuple] = []

    def _read(self) -> tuple:
        client, body = self.h.client, self.h.body
        return pb.getBasePositionAndOrientation(body, physicsClientId=client) + pb.getBaseVelocity(
            body, physicsClientId=client
        )

    def advance(self, steps: int) -> Rows:
        client, body, threshold = self.h.client, self.h.body, self.h.processing_threshold
        step, contacts, read = pb.stepSimulation, pb.getContactPoints, self._read
        rows_j, rows_raw, hits, ground_index = (
            self.rows_j,
            self.rows_raw,
            self.hits,
            self.ground_index,
        )
        first = self.first = len(rows_j)
        last_step = self.j + steps
        for j in range(self.j + 1, last_step + 1):
            self.j = j
            step(physicsClientId=client)
            cps = contacts(bodyA=body, physicsClientId=client)
            for cp in cps:
                if cp[9] > 0.0 and cp[8] <= threshold:
                    p = cp[5]
                    hits.append((j, ground_index.get(cp[2], 0), p[0], p[1], p[2], cp[9]))
            if self.every_step or cps or j % self.sample_every == 0 or j == self.n_steps:
                rows_j.append(j)
                rows_raw.append(read())
        return Rows(np.array(rows_j[first:]) * self.dt, _states(rows_raw[first:]))

    def cut(self, keep: int) -> None:
        del self.rows_j[self.first + keep :], self.rows_raw[self.first + keep :]
        self._drop_hits_after(self.rows_j[-1])

    def settle(self) -> float:
        kept = min(len(self.rows_j), len(self.rows_raw))
        del self.rows_j[kept:], self.rows_raw[kept:]
        self._drop_hits_after(self.rows_j[-1])
        return self.rows_j[-1] * self.dt

    def recording(self, loop) -> Recording:
        return _recording(self, loop)

    def close(self) -> None:
        pb.disconnect(self.h.client)

    def _drop_hits_after(self, j_last: int) -> None:
        """Hits of steps after the last recorded row (every step with hits is recorded)."""
        while self.hits and self.hits[-1][0] > j_last:
            self.hits.pop()


def simulate_pybullet(
    scene: Scene,
    dt: float,
    t_end: float | None = None,
    profile: str = "tuned",
    sample_every: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the scene in PyBullet at fixed step dt up to t_end (scene.run.t_end by default).

    Driven by engines.stepping.simulate_fixed_step in chunks of CHUNK_STEPS:
    `progress(done, total)` before every chunk; Ctrl-C stops the run after the current
    step: status failed, stats["interrupted"], the steps so far kept.

    Rows of the result: t = 0 (the initial state read back from PyBullet), every step
    around contact activity, and every `sample_every`-th step in between (default: steps
    of about 1e-3 √(a/g), at least every step).  Impacts come from contact onsets
    (`engines.base`).  Status `failed` (and the run stops) on a non-finite state or when a
    contact point is more than FALL_THROUGH_DEPTH·a below its ground.

    stats: those of the driver (wall_time_s, steps, steps_per_s), setup_time_s (building
    the world), rows_read, rows_kept, profile."""
    if profile not in PROFILES:
        raise ValueError(f"unknown PyBullet profile {profile!r}; choose from {PROFILES}")
    dt = check_dt(dt)
    t_run = scene.run.t_end if t_end is None else float(t_end)
    if sample_every is None:
        a = scene.body.radius
        time_unit = math.sqrt(a / scene.gravity) if scene.gravity > 0 else 1.0
        sample_every = max(1, min(step_count(t_run, dt), int(1e-3 * time_unit / dt)))
    flat = scene.contacts.rim_only

    def build(n_steps: int) -> _Stepper:
        setup0 = time.perf_counter()
        h = build_world(scene, dt, profile)
        stepper = _Stepper(h, dt, sample_every, every_step=not flat, n_steps=n_steps)
        stepper.scene, stepper.profile = scene, profile
        stepper.setup_s = time.perf_counter() - setup0
        return stepper

    return simulate_fixed_step(
        scene,
        ENGINE_NAMES[profile],
        dt,
        t_run,
        build,
        chunk_steps=CHUNK_STEPS,
        progress=progress,
    )


def _recording(stepper: _Stepper, loop) -> Recording:
    """The recorded rows (finite ones only after a failure) and their impulses, thinned
    to the regular samples and the rows around contact activity (`_rows_to_keep`)."""
    scene, dt = stepper.scene, stepper.dt
    contacts = scene.contacts
    J = np.array(stepper.rows_j)
    Y = _states(stepper.rows_raw)
    steps_run = int(J[-1])
    impulses = _impulses(
        stepper.hits, J, Y, contacts.has_plane, contacts.n_rim, scene.n_contacts, dt
    )
    keep = _rows_to_keep(J, impulses, stepper.sample_every, steps_run)
    if loop.status is Status.FAILED:  # keep the finite rows only
        keep &= np.all(np.isfinite(Y), axis=1)
    stats = {
        "setup_time_s": stepper.setup_s,
        "profile": stepper.profile,
        "rows_read": int(len(J)),
        "rows_kept": int(keep.sum()),
    }
    return Recording(J[keep] * dt, Y[keep], impulses[keep], steps_run, stats)


def _states(rows: list[tuple]) -> np.ndarray:
    """(N, 13) states from raw PyBullet rows (pos, orn xyzw, v, ω): reorder to wxyz."""
    raw = np.array([c for row in rows for part in row for c in part]).reshape(-1, 13)
    return raw[:, [0, 1, 2, 6, 3, 4, 5, 7, 8, 9, 10, 11, 12]]


def _impulses(hits, J, Y, has_plane, n_rim, n_contacts, dt) -> np.ndarray:
    """(rows, n_contacts) normal impulses: force × dt of every processed contact point,
    summed per scene contact, on the row of the step that applied it.

    A point on the plane (ground body 0 when there is one) is assigned to a vertex with
    the pose of the previous recorded row: the collision pass that made the point ran at
    the start of its step.  A point on bump body j is floor contact n_rim + j."""
    out = np.zeros((len(J), n_contacts))
    if not hits:
        return out
    H = np.array(hits)
    steps = H[:, 0].astype(int)
    row = np.searchsorted(J, steps)  # a step with contact points is always recorded
    ground = H[:, 1].astype(int)
    k = n_rim + ground - int(has_plane)
    on_plane = (ground == 0) if has_plane else np.zeros(len(H), dtype=bool)
    prev = np.maximum(row - 1, 0)
    for r in np.unique(prev[on_plane]):
        sel = on_plane & (prev == r)
        y = Y[r]
        k[sel] = _contact_index_flat(H[sel, 2:5], y[L.POSITION], y[L.QUATERNION], n_rim)
    np.add.at(out, (row, k), H[:, 5] * dt)
    return out


def _rows_to_keep(J, impulses, sample_every, last_step) -> np.ndarray:
    """Rows for the Trajectory: regular samples (every `sample_every` steps, the first
    and last), and around contact activity the active rows and their neighbours, if
    those neighbours are the adjacent steps."""
    keep = (J % sample_every == 0) | (J == last_step)
    active = np.any(impulses > 0.0, axis=1)
    idx = np.flatnonzero(active)
    keep[idx] = True
    for off in (-1, 1):
        nb = idx + off
        ok = (nb >= 0) & (nb < len(J))
        nb, src = nb[ok], idx[ok]
        ok = np.abs(J[nb] - J[src]) == 1
        keep[nb[ok]] = True
    return keep
