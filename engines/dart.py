"""DART adapter (`dartpy`, the [dart] extra): run a scene in DART's LCP contact solver and
return a `Trajectory` in the reference's conventions.

DART resolves contacts as velocity constraints of one linear complementarity problem per
step (a boxed LCP, Dantzig's pivoting solver), with a restitution target: a contact whose
approach speed is u⁻ must leave at least at e·u⁻ (ContactConstraint::getInformation), where
e is the product of the two shapes' restitution coefficients
(`shapeNode.getDynamicsAspect().setRestitutionCoeff(e)`).  Three constants compiled into
DART shape it (dart/constraint/ContactConstraint.cpp):

- a rebound target e·u⁻ below DART_BOUNCING_VELOCITY_THRESHOLD = 0.1 (m/s) is set to
  zero: the impact is plastic (the **rebound cut-off**);
- one above DART_MAX_BOUNCING_VELOCITY = 100 (m/s) is clamped to it;
- a penetrating contact is pushed out at ERP·depth/h, at most DART_MAX_ERV = 1e-3 (m/s),
  and the larger of that and the rebound is the target.

Geometry (docs/engines.md "Geometry that is exactly a point contact"): a sphere of radius
r at each vertex over a thick box whose top face is the plane z = −r (flat ground), or
world spheres at the bumps under a thin box on the body whose bottom face is at body height
+r (three_point ground).  DART's own collision detector (`DARTCollisionDetector`) gives
the sphere–box pair its exact distance and face normal.  Frictionless: friction
coefficient 0 on every shape (DART then builds the one-row frictionless constraint).

Profiles (how γ maps to the engine):

- `tuned` (engine name "dart"): restitution γ on the body's shapes and 1 on the ground's
  (the product is exactly γ); the scene is run in units scaled by λ (`length_scale`) so
  that DART's fixed velocity constants fall outside the scene's speeds: the cut-off
  becomes 0.1/λ and the clamp 100/λ in the scene's units; DART's collision detector; the
  leapfrog reading of its semi-implicit Euler step (velocities at half steps, as MuJoCo's
  tuned profile: `engines.mujoco.staggered_start`, `whole_step_velocities`).
- `default` ("dart-default"): what a typical user writes: restitution √γ on every shape
  (the pair's product is γ), DART's default collision detector (FCL) and the scene's own
  units, so the cut-off acts at 0.1 in the scene's units.

State conventions.  A FreeJoint's positions are (rotation vector, translation) of the
body frame, its velocities the spatial velocity in the body frame; the adapter sets and
reads velocities in world axes through `FreeJoint.setLinearVelocity/setAngularVelocity(·,
World, World)` and `BodyNode.getLinearVelocity/getAngularVelocity(World, World)`.  Per-contact
data after a step: `world.getLastCollisionResult().getContacts()`, whose `force` is
impulse / h of the contacts found at the state before the step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from reference import quaternion as qt
from reference.core import layout as L
from reference.geometry import initial_state
from reference.scene import Scene
from reference.trajectory import Trajectory

from .mujoco import staggered_start, whole_step_velocities
from .stepping import (
    SPHERE_RADIUS_FRACTION,
    Recording,
    Rows,
    check_dt,
    simulate_fixed_step,
)

PROFILES = ("tuned", "default")
ENGINE_NAMES = {"tuned": "dart", "default": "dart-default"}
GROUND_KINDS = ("flat", "three_point")
# DART's compiled constants (dart/constraint/ContactConstraint.cpp), in DART's units.
BOUNCING_VELOCITY_THRESHOLD = 0.1
MAX_BOUNCING_VELOCITY = 100.0
# Steps per chunk of the run loop: progress and the fall-through check after each.
CHUNK_STEPS = 20_000
# Tuned units: the bound of any contact's speed (`speed_bound`) maps to 1/CLAMP_MARGIN of
# DART's clamp, so no rebound is clamped (a factor 3 to spare); the cut-off, 1/1000 of the
# clamp, then sits at 3e-3 of that bound (3e-3 √(g a) on pentagon-bounce).
CLAMP_MARGIN = 3.0
# Ground box: thickness and half-width in units of the body radius (only its top face
# is touched; wide enough that the body never leaves it).
GROUND_THICKNESS = 1.0
GROUND_HALF_WIDTH = 1e3
# Half-thickness of the body's face over three_point bumps, in units of a (as MuJoCo's).
FACE_HALF_THICKNESS = 0.1


@dataclass(frozen=True)
class DartSettings:
    """Everything a profile chooses."""

    profile: str
    body_restitution: float
    ground_restitution: float
    length_scale: float  # DART length = length_scale × scene length
    detector: str  # "dart" or "fcl"
    half_step_velocities: bool
    restitution_model: str

    @property
    def cutoff(self) -> float:
        """The rebound speed below which DART sets the rebound to zero, in the scene's
        units."""
        return BOUNCING_VELOCITY_THRESHOLD / self.length_scale


def speed_bound(scene: Scene, dt: float) -> float:
    """A bound of any contact point's speed over the run: with kinetic energy at most
    the initial total energy E (γ ≤ 1, potential ≥ 0 above the ground),
    |v + ω × r| ≤ √(2E/m) (1 + 1/ρ), plus g dt (engines.pybullet's bound)."""
    from reference.geometry import energies

    ke, pe = energies(scene, initial_state(scene.initial))
    energy = max(float(ke[0] + pe[0]), 0.0)
    v = math.sqrt(2.0 * energy / scene.body.mass) * (1.0 + 1.0 / scene.body.gyration)
    return v + scene.gravity * dt


def contact_settings(scene: Scene, dt: float, profile: str) -> DartSettings:
    """The profile's settings for this scene (module docstring)."""
    gamma = scene.restitution
    if profile == "tuned":
        # λ: the fastest possible rebound (≤ the speed bound) stays CLAMP_MARGIN below
        # DART's clamp; the cut-off then sits at CLAMP_MARGIN·bound/1000.
        bound = speed_bound(scene, dt)
        scale = MAX_BOUNCING_VELOCITY / (CLAMP_MARGIN * bound) if bound > 0 else 1.0
        return DartSettings(
            "tuned",
            gamma,
            1.0,
            scale,
            "dart",
            True,
            f"restitution gamma on the body, 1 on the ground; units scaled by {scale:.4g} "
            f"(rebound cut-off {BOUNCING_VELOCITY_THRESHOLD / scale:.3g})",
        )
    if profile == "default":
        e = math.sqrt(gamma)
        return DartSettings(
            "default",
            e,
            e,
            1.0,
            "fcl",
            False,
            "restitution sqrt(gamma) on every shape; "
            f"rebound cut-off {BOUNCING_VELOCITY_THRESHOLD}",
        )
    raise ValueError(f"unknown DART profile {profile!r}; choose from {', '.join(PROFILES)}")


# --------------------------------------------------------------------------- model
@dataclass
class DartModel:
    world: object
    skeleton: object
    joint: object
    body: object
    contact_of: dict[str, int]  # shape node name → scene contact index
    scale: float


def _shape(dart, parent, shape, name: str, at, restitution: float):
    """A colliding, frictionless shape node at `at` (parent frame) with restitution."""
    node = parent.createShapeNode(shape, name)
    node.setRelativeTranslation(np.asarray(at, dtype=float))
    node.createCollisionAspect()
    aspect = node.createDynamicsAspect()
    aspect.setRestitutionCoeff(restitution)
    aspect.setFrictionCoeff(0.0)
    return node


def build_model(scene: Scene, dt: float, settings: DartSettings) -> DartModel:
    """The scene's body (free joint, explicit inertia m(ρa)² diag(1, 1, 2) about the
    centre of mass) and ground in a DART world at step dt, in DART units (× length_scale)."""
    import dartpy as dart

    s = settings.length_scale
    a = scene.body.radius * s
    r = SPHERE_RADIUS_FRACTION * a
    world = dart.simulation.World()
    world.setTimeStep(dt)
    world.setGravity(np.array([0.0, 0.0, -scene.gravity * s]))
    if settings.detector == "dart":
        world.setCollisionDetector(dart.collision.DARTCollisionDetector())
    skel = dart.dynamics.Skeleton("body")
    joint, body = skel.createFreeJointAndBodyNodePair()
    body.setMass(scene.body.mass)
    i1, i2, i3 = (v * s * s for v in scene.body.inertia_diag)
    body.setMomentOfInertia(i1, i2, i3, 0.0, 0.0, 0.0)
    ground = dart.dynamics.Skeleton("ground")
    _, gbody = ground.createWeldJointAndBodyNodePair()
    contacts = scene.contacts
    contact_of: dict[str, int] = {}
    e_body, e_ground = settings.body_restitution, settings.ground_restitution
    if contacts.has_plane:
        h, w = GROUND_THICKNESS * a, GROUND_HALF_WIDTH * a
        box = dart.dynamics.BoxShape(np.array([2 * w, 2 * w, h]))
        _shape(dart, gbody, box, "ground", [0.0, 0.0, -r - h / 2], e_ground)
        for k, p in enumerate(contacts.rim_points):
            sphere = dart.dynamics.SphereShape(r)
            _shape(dart, body, sphere, f"vertex{k}", np.asarray(p) * s, e_body)
            contact_of[f"vertex{k}"] = k
    if len(contacts.floor_points):
        for j, p in enumerate(contacts.floor_points):
            sphere = dart.dynamics.SphereShape(r)
            _shape(dart, gbody, sphere, f"bump{j}", np.asarray(p) * s, e_ground)
            contact_of[f"bump{j}"] = contacts.n_rim + j
        hh = FACE_HALF_THICKNESS * a
        face = dart.dynamics.BoxShape(np.array([2 * a, 2 * a, 2 * hh]))
        _shape(dart, body, face, "face", [0.0, 0.0, r + hh], e_body)
    world.addSkeleton(skel)
    world.addSkeleton(ground)
    return DartModel(world, skel, joint, body, contact_of, s)


def set_state(model: DartModel, y: np.ndarray) -> None:
    """Put a reference state (scene units) into the DART model (DART units): rotation
    vector and position, then world-axis velocities."""
    import dartpy as dart

    y = np.asarray(y, dtype=float)
    s = model.scale
    rotvec = qt.to_rotation_vector(y[L.QUATERNION])
    model.skeleton.setPositions(np.concatenate([rotvec, y[L.POSITION] * s]))
    world = dart.dynamics.Frame.World()
    model.joint.setLinearVelocity(y[L.VELOCITY] * s, world, world)
    model.joint.setAngularVelocity(y[L.ANGULAR_VELOCITY], world, world)


def read_state(model: DartModel) -> np.ndarray:
    """The body's reference state (scene units) from DART's world-frame kinematics."""
    import dartpy as dart

    world = dart.dynamics.Frame.World()
    pos = np.asarray(model.skeleton.getPositions())
    b = model.body
    return np.concatenate(
        [
            pos[3:6] / model.scale,
            qt.from_rotation_vector(pos[0:3]),
            np.asarray(b.getLinearVelocity(world, world)) / model.scale,
            np.asarray(b.getAngularVelocity(world, world)),
        ]
    )


def contact_impulses(model: DartModel, n_contacts: int, dt: float) -> np.ndarray:
    """Normal impulse (scene units) of every scene contact in the last step, from the
    last collision result's contacts (force = impulse / h, along the contact normal)."""
    out = np.zeros(n_contacts)
    for c in model.world.getLastCollisionResult().getContacts():
        names = (
            c.collisionObject1.getShapeFrame().getName(),
            c.collisionObject2.getShapeFrame().getName(),
        )
        k = next((model.contact_of[n] for n in names if n in model.contact_of), None)
        if k is not None:
            out[k] += abs(float(np.dot(c.force, c.normal))) * dt / model.scale
    return out


# --------------------------------------------------------------------------- running
class _Stepper:
    """engines.stepping.Adapter over one DART world: every step recorded (state after it;
    the impulses of a step on the row of the state before it)."""

    def __init__(self, scene: Scene, dt: float, settings: DartSettings, n_steps: int):
        self.scene, self.dt, self.settings = scene, dt, settings
        self.model = build_model(scene, dt, settings)
        self.y0 = initial_state(scene.initial)
        half = settings.half_step_velocities
        set_state(self.model, staggered_start(scene, self.y0, dt) if half else self.y0)
        self.rows = [read_state(self.model)]
        self.impulses: list[np.ndarray] = []
        self.first = 1

    def advance(self, steps: int) -> Rows:
        model, n, dt = self.model, self.scene.n_contacts, self.dt
        self.first = len(self.rows)
        for _ in range(steps):
            model.world.step()
            self.impulses.append(contact_impulses(model, n, dt))
            self.rows.append(read_state(model))
        t = dt * np.arange(self.first, len(self.rows))
        return Rows(t, np.array(self.rows[self.first :]))

    def cut(self, keep: int) -> None:
        del self.rows[self.first + keep :]

    def settle(self) -> float:
        kept = min(len(self.rows), len(self.impulses) + 1)
        del self.rows[kept:]
        return (len(self.rows) - 1) * self.dt

    def recording(self, loop) -> Recording:
        scene, dt, s = self.scene, self.dt, self.settings
        states = np.array(self.rows)
        n_rows = len(states)
        impulses = np.zeros((n_rows, scene.n_contacts))
        known = np.array(self.impulses[:n_rows]) if self.impulses else impulses[:0]
        impulses[: len(known)] = known
        if s.half_step_velocities:  # the last row's next half step: from free flight
            states = whole_step_velocities(scene, states, None, impulses > 0.0, dt)
            states[0, L.VELOCITIES] = self.y0[L.VELOCITIES]
        stats = {
            "profile": s.profile,
            "restitution_model": s.restitution_model,
            "body_restitution": s.body_restitution,
            "ground_restitution": s.ground_restitution,
            "length_scale": s.length_scale,
            "rebound_cutoff": s.cutoff,
            "collision_detector": s.detector,
            "half_step_velocities": s.half_step_velocities,
            "dartpy_version": _version(),
        }
        return Recording(dt * np.arange(n_rows), states, impulses, n_rows - 1, stats)


def simulate_dart(
    scene: Scene,
    dt: float,
    t_end: float | None = None,
    profile: str = "tuned",
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the scene in DART at fixed step dt until t_end (scene.run.t_end by default)
    through the fixed-step driver (engines.stepping): one row per step, impacts from
    contact onsets (engines.base); stats: the driver's and the profile's settings
    (rebound_cutoff in the scene's units)."""
    if profile not in PROFILES:
        raise ValueError(f"unknown DART profile {profile!r}; choose from {', '.join(PROFILES)}")
    dt = check_dt(dt)
    settings = contact_settings(scene, dt, profile)

    def build(n_steps: int) -> _Stepper:
        return _Stepper(scene, dt, settings, n_steps)

    return simulate_fixed_step(
        scene,
        ENGINE_NAMES[profile],
        dt,
        t_end,
        build,
        chunk_steps=CHUNK_STEPS,
        progress=progress,
    )


def _version() -> str | None:
    from importlib import metadata

    try:
        return metadata.version("dartpy")
    except metadata.PackageNotFoundError:
        return None
