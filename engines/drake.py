"""Drake adapter: the scene as a Drake MultibodyPlant, run and returned as a `Trajectory`
in the reference's conventions.

Geometry (the same as engines/mujoco_model.py and engines/pybullet.py): frictionless
compliant **point contact** (`ContactModel.kPoint`; hydroelastic contact would make a
patch, not a vertex contact).  `flat`: a sphere of radius r at every vertex
a(cos 2πk/n, sin 2πk/n, 0) and a `HalfSpace` ground at z = −r, so the sphere–half-space
signed distance is the reference's gap z + (R p_k)_z exactly and the force acts along
ẑ through the vertex.  `three_point`: a sphere of radius r at every bump b_k (z = 0,
fixed to the world) and on the body a box whose bottom face lies at body height +r, so
sphere–face distance = (x − b_k)·e3, the reference's gap, and the normal is e3.
`bumpy` (both kinds): the half space with the vertex spheres and the bump spheres (at
their heights) with the face box; a SceneGraph collision filter excludes the face–half
space and vertex–bump pairs, so each body geometry meets only its own kind's partner.

Contact law (Drake's "Contact Modeling" documentation, multibody/plant): point contact
force fₙ = k x (1 + d ẋ)₊ (x penetration, ẋ its rate; Hunt & Crossley dissipation d in
s/m) in the continuous plant and in the kTamsi/kSimilar/kLagged discrete approximations;
the SAP approximation (`DiscreteContactApproximation.kSap`) instead uses a linear
Kelvin–Voigt damper with a relaxation time τ: an implicit step solves
fₙ = k(−φ₀ − (h + τ) vₙ⁺)₊ with φ₀ the signed distance at the start of the step and vₙ⁺
the normal velocity at its end.  Combination rules for two geometries: stiffness
k = k₁k₂/(k₁ + k₂) (so both geometries carry 2k), dissipation d weighted by stiffness
(both carry d), relaxation times add (measured: τ on both gave the bounce of 2τ; the body
carries τ, the ground 0).

Profiles (how γ maps to Drake; `contact_settings`):

- `sap` → engine "drake": discrete plant, time step dt, SAP.  The contact lasts
  N(γ) steps (stiffness k = m_eff (π/(N h))², `sap_contact_steps`) and τ solves the SAP
  step map for e = γ (`sap_relaxation_time`): the bounce of a linear implicit oscillator
  does not depend on the impact speed, and the map is exactly what Drake computes
  (measured: 1-D map vs Drake's single-vertex drop agree to ±0.01 in e).
- `continuous` → engine "drake-continuous": continuous plant, Hunt & Crossley
  dissipation, error-controlled RK3.  With fₙ = k x (1 + d ẋ)₊ the restitution of a
  free point contact depends only on u = d·v (v the impact speed; k and the mass drop
  out): u(1 + e) = ln(1 + u) − ln(1 − e u) (`hc_restitution`).  d is chosen so that
  e(v*) = γ at the scene's typical impact speed v* (`engines.base.typical_impact_speed`);
  faster impacts are more dissipative and slower ones bounce more (e → 1 as v → 0):
  docs/engines.md has the measured e(v).  `--dt` is the integrator's maximum step and
  sets its target accuracy to dt/√(a/g) (so a work-precision sweep over dt refines both).

State conventions.  Drake's quaternion floating joint stores q = (qw, qx, qy, qz, x, y,
z) (quaternion body → world first, then the position of the body origin) and
v = (ω, v), both **expressed in the world frame** (MultibodyPlant's free bodies:
"angular velocity w_WB expressed in W").  The reference's row is (x, q, v, ω): only the
order changes (tests/test_engine_drake.py checks it against Drake's own
EvalBodyPoseInWorld / EvalBodySpatialVelocityInWorld).

Recording: a simulator monitor stores the plant's state and the contact results after
every step (every time step of the discrete plant, every accepted integrator step of the
continuous one).  Discrete plant: the contact results port is sampled, so the row after
step j holds the force of the step that produced it; impulse = fₙ h.  Continuous plant:
the force at each step's end; impulse of row j = the trapezoid ½(f_{j−1} + f_j)(t_j −
t_{j−1}).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from reference.core import layout as L
from reference.scene import Scene
from reference.trajectory import Status, Trajectory

from .base import (
    effective_contact_mass,
    initial_state,
    typical_impact_speed,
)
from .stepping import (
    SPHERE_RADIUS_FRACTION,
    Recording,
    Rows,
    first_failure,
    simulate_fixed_step,
)

PROFILES = ("sap", "continuous")
ENGINE_NAMES = {"sap": "drake", "continuous": "drake-continuous"}

# Contact sphere radius / body radius: engines.stepping.SPHERE_RADIUS_FRACTION (any r gives
# the exact point contact, module docstring).
# three_point: half-thickness of the body's contact box (only its bottom face is touched);
# a bump deeper than this would come out of the top (engines.stepping.FALL_THROUGH_DEPTH
# ends the run before).
FACE_HALF_THICKNESS_FRACTION = 0.1
# SAP: steps per contact.  The implicit step loses energy even without a damper: with
# τ = 0 the bounce is e_max(N) ≈ exp(−π²/(2N)) (0.79 at N = 20, measured in Drake), so N
# must exceed N₀(γ) = π²/(2 |ln γ|); N = 4 N₀ leaves room for τ and keeps the spread of
# e over the onset phase (where in a step the contact starts) under ±1 % (the map gives
# ±0.4 % at γ = 0.8, N = 64).  At least 16 steps; at most 400 (γ ≥ 0.988: e_max(400) =
# 0.988, τ = 0, the bounce is as elastic as SAP gets with 400-step contacts).
SAP_STEPS_FACTOR = 4.0
SAP_MIN_STEPS = 16
SAP_MAX_STEPS = 400
# Continuous plant: the contact's undamped half-period in units of √(a/g): k =
# m_eff (π/T)².  Short against the scenes' flights (first impact intervals ≥ 0.01) and
# long enough for an explicit integrator (RK3 takes ~20–40 steps per contact).
CONTINUOUS_CONTACT_TIME = 1e-3
# Continuous plant: the loosest target accuracy (at dt ≥ 1e-3 √(a/g)).
CONTINUOUS_MAX_ACCURACY = 1e-3
# The continuous profile's smallest restitution at the typical speed: γ = 0 is taken as
# 0.01 (u = d v* = 100; Drake's guide calls d > 500 s/m unphysical and hard on solvers).
HC_MIN_RESTITUTION = 0.01


class _HalfSpaceNotice(logging.Filter):
    """Drops SceneGraph's notice that a rigid half space takes no part in deformable
    contact (there is no deformable body here); every other Drake message passes."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "half spaces are not currently supported for deformable" not in record.getMessage()


def _quiet_half_space_warning() -> None:
    """Install the filter on pydrake's Python logger "drake" once."""
    logger = logging.getLogger("drake")
    if not any(isinstance(f, _HalfSpaceNotice) for f in logger.filters):
        logger.addFilter(_HalfSpaceNotice())


@dataclass(frozen=True)
class DrakeSettings:
    """Everything a profile chooses."""

    profile: str
    time_step: float  # 0: continuous plant
    stiffness: float  # effective point-contact stiffness k (N/m)
    hc_dissipation: float  # Hunt & Crossley d (s/m); ignored by SAP
    relaxation_time: float  # SAP's τ (s); ignored by the continuous plant
    contact_steps: float | None  # SAP: steps per contact half-period
    max_step: float | None  # continuous: the integrator's maximum step
    accuracy: float | None  # continuous: the integrator's target accuracy
    restitution_model: str


# ----------------------------------------------------------------------------- γ → Drake


def hc_restitution(u: float) -> float:
    """Restitution of a free point contact with fₙ = k x (1 + d ẋ)₊ for u = d·v > 0:
    m ẍ = −k x (1 + d ẋ) integrates to m[(ẋ − v)/d − ln((1 + dẋ)/(1 + dv))/d²] = −k x²/2,
    and at x = 0 again with ẋ = −e v: u(1 + e) = ln(1 + u) − ln(1 − e u), e ∈ (0, 1)
    (no k, no mass).  e ≈ 1 − 2u/3 for small u; e → 0 as u → ∞."""
    if u <= 0.0:
        return 1.0
    lo, hi = 0.0, min(1.0, 1.0 / u)
    for _ in range(200):  # bisection: f(e) = ln(1+u) − ln(1−eu) − u(1+e) rises through 0
        e = 0.5 * (lo + hi)
        if e * u < 1.0 and math.log1p(u) - math.log1p(-e * u) - u * (1.0 + e) < 0.0:
            lo = e
        else:
            hi = e
    return 0.5 * (lo + hi)


def hc_speed_factor(gamma: float) -> float:
    """u = d·v giving restitution γ (`hc_restitution` inverted; e decreases with u).
    γ is taken as at least HC_MIN_RESTITUTION (γ = 0 would need d = ∞)."""
    if gamma >= 1.0:
        return 0.0
    gamma = max(gamma, HC_MIN_RESTITUTION)
    lo, hi = 0.0, 1.0
    while hc_restitution(hi) > gamma:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if hc_restitution(mid) > gamma:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def sap_bounce(steps: float, tau_over_h: float, phase: float = 0.5) -> float:
    """e of SAP's step map for one contact with N = `steps` steps per undamped
    half-period: per step, while φ < 0 at the step's start,
    vₙ⁺ = vₙ + (h k/m)(−φ − (h + τ) vₙ⁺)₊ and φ⁺ = φ + h vₙ⁺ (k = m(π/(N h))²; gravity
    and rotation neglected); the first penetrating state has φ = −phase·|vₙ| h.
    Dimensionless: depends on N, τ/h and the phase only."""
    c = (math.pi / steps) ** 2  # h² k / m
    phi, v = -phase, -1.0  # in units of |vₙ⁻| h and |vₙ⁻|
    for _ in range(100 * int(steps) + 100):
        if phi >= 0.0:
            return v
        v_new = (v - c * phi) / (1.0 + c * (1.0 + tau_over_h))
        if -(phi + (1.0 + tau_over_h) * v_new) <= 0.0:
            v_new = v
        phi += v_new
        v = v_new
    return 0.0  # never left: plastic


def sap_contact_steps(gamma: float) -> float:
    """Steps per contact half-period for γ (see SAP_STEPS_FACTOR)."""
    if gamma <= 0.0:
        return float(SAP_MIN_STEPS)
    if gamma >= 1.0:
        return float(SAP_MAX_STEPS)
    n0 = math.pi**2 / (2.0 * -math.log(gamma))
    return float(min(SAP_MAX_STEPS, max(SAP_MIN_STEPS, math.ceil(SAP_STEPS_FACTOR * n0))))


def sap_relaxation_time(gamma: float, steps: float) -> float:
    """τ/h with `sap_bounce`(N, τ/h) = γ at the middle onset phase (bisection; e falls
    as τ grows); 0 when even τ = 0 bounces less than γ.  At most critical damping,
    τ = 2/ω₀ = 2N h/π (e = 0.14 there at N = 16): a stronger damper only makes the
    contact creep (γ = 0 unbounded gave τ = 1700 h, and a resting disk still sinking
    after 3000 steps)."""
    critical = 2.0 * steps / math.pi
    if sap_bounce(steps, 0.0) <= gamma:
        return 0.0
    if sap_bounce(steps, critical) >= gamma:
        return critical
    lo, hi = 0.0, critical
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if sap_bounce(steps, mid) > gamma:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def contact_settings(scene: Scene, dt: float, profile: str) -> DrakeSettings:
    """The profile's Drake parameters for the scene at step dt (module docstring)."""
    m_eff = effective_contact_mass(scene)
    gamma = scene.restitution
    if profile == "sap":
        steps = sap_contact_steps(gamma)
        tau_h = sap_relaxation_time(gamma, steps)
        return DrakeSettings(
            profile=profile,
            time_step=dt,
            stiffness=m_eff * (math.pi / (steps * dt)) ** 2,
            hc_dissipation=0.0,
            relaxation_time=tau_h * dt,
            contact_steps=steps,
            max_step=None,
            accuracy=None,
            restitution_model=(
                f"SAP Kelvin-Voigt: contact of {steps:g} steps, relaxation time "
                f"{tau_h:.4g} dt from the SAP step map"
            ),
        )
    if profile == "continuous":
        unit = math.sqrt(scene.body.radius / scene.gravity) if scene.gravity > 0 else 1.0
        v_star = typical_impact_speed(scene)
        u = hc_speed_factor(gamma)
        return DrakeSettings(
            profile=profile,
            time_step=0.0,
            stiffness=m_eff * (math.pi / (CONTINUOUS_CONTACT_TIME * unit)) ** 2,
            hc_dissipation=u / v_star,
            relaxation_time=0.0,
            contact_steps=None,
            max_step=dt,
            accuracy=min(CONTINUOUS_MAX_ACCURACY, dt / unit),
            restitution_model=(
                f"Hunt-Crossley d = {u:.4g}/v* with v* = {v_star:.4g} "
                "(e = gamma at the typical impact speed)"
            ),
        )
    raise ValueError(f"unknown Drake profile {profile!r}; choose from {', '.join(PROFILES)}")


# ----------------------------------------------------------------------------- model


@dataclass
class DrakeModel:
    """One built diagram: the plant, its free body and the scene contact of each
    geometry that represents one (vertex sphere or bump sphere)."""

    diagram: object
    plant: object
    body: object
    contact_of: dict  # GeometryId → scene contact k
    settings: DrakeSettings


def _proximity(stiffness: float, dissipation: float, relaxation: float | None):
    from pydrake.geometry import AddContactMaterial, ProximityProperties
    from pydrake.multibody.plant import CoulombFriction

    props = ProximityProperties()
    AddContactMaterial(
        dissipation=dissipation,
        point_stiffness=stiffness,
        friction=CoulombFriction(0.0, 0.0),  # frictionless: normal force only
        properties=props,
    )
    if relaxation is not None:
        props.AddProperty("material", "relaxation_time", relaxation)
    return props


def build_model(scene: Scene, settings: DrakeSettings) -> DrakeModel:
    """The scene's diagram (MultibodyPlant + SceneGraph) under the settings."""
    from pydrake.geometry import Box, CollisionFilterDeclaration, GeometrySet, HalfSpace, Sphere
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import (
        AddMultibodyPlantSceneGraph,
        ContactModel,
        DiscreteContactApproximation,
    )
    from pydrake.multibody.tree import RotationalInertia, SpatialInertia
    from pydrake.systems.framework import DiagramBuilder

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, settings.time_step)
    plant.set_contact_model(ContactModel.kPoint)
    if settings.time_step > 0:
        plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    b = scene.body
    i1, i2, i3 = b.inertia_diag
    body = plant.AddRigidBody(
        "body",
        SpatialInertia.MakeFromCentralInertia(b.mass, np.zeros(3), RotationalInertia(i1, i2, i3)),
    )
    r = SPHERE_RADIUS_FRACTION * b.radius
    k2 = 2.0 * settings.stiffness  # two geometries in series: k = k₂/2
    d, tau = settings.hc_dissipation, settings.relaxation_time
    sap = settings.time_step > 0  # SAP reads τ; the continuous plant must not get one
    on_body = _proximity(k2, d, tau if sap else None)
    on_ground = _proximity(k2, d, 0.0 if sap else None)
    contact_of = {}
    contacts = scene.contacts
    world = plant.world_body()
    _quiet_half_space_warning()
    rim_kind, floor_kind = [], []  # the geometries of each kind: (body side, ground side)
    if contacts.has_plane:  # rim vertices: spheres on the body over a half space
        for k, p in enumerate(contacts.rim_points):
            gid = plant.RegisterCollisionGeometry(
                body, RigidTransform(p), Sphere(r), f"vertex{k}", on_body
            )
            contact_of[gid] = k
            rim_kind.append(gid)
        ground = plant.RegisterCollisionGeometry(
            world, RigidTransform([0.0, 0.0, -r]), HalfSpace(), "ground", on_ground
        )
    if len(contacts.floor_points):  # floor points: spheres on the ground under a face
        hh = FACE_HALF_THICKNESS_FRACTION * b.radius
        side = 2.0 * b.radius
        face = plant.RegisterCollisionGeometry(
            body, RigidTransform([0.0, 0.0, r + hh]), Box(side, side, 2 * hh), "face", on_body
        )
        floor_kind.append(face)
        for j, p in enumerate(contacts.floor_points):
            gid = plant.RegisterCollisionGeometry(
                world, RigidTransform(p), Sphere(r), f"bump{j}", on_ground
            )
            contact_of[gid] = contacts.n_rim + j
            floor_kind.append(gid)
    if rim_kind and floor_kind:  # both kinds (bumpy): each body geometry meets its own
        # partner only: the face not the half space, a vertex not a bump (SceneGraph
        # filters pairs of geometries; the body's own pairs are filtered already)
        manager = scene_graph.collision_filter_manager()
        manager.Apply(
            CollisionFilterDeclaration()
            .ExcludeBetween(GeometrySet([face]), GeometrySet([ground]))
            .ExcludeBetween(GeometrySet(rim_kind), GeometrySet(floor_kind[1:]))
        )
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -scene.gravity])
    plant.Finalize()
    return DrakeModel(builder.Build(), plant, body, contact_of, settings)


# ----------------------------------------------------------------------------- states

# Drake's (qw, qx, qy, qz, x, y, z, ωx, ωy, ωz, vx, vy, vz) → reference order and back.
_FROM_DRAKE = np.array([4, 5, 6, 0, 1, 2, 3, 10, 11, 12, 7, 8, 9])
_TO_DRAKE = np.argsort(_FROM_DRAKE)


def from_drake_state(x: np.ndarray) -> np.ndarray:
    """Drake positions-and-velocities (..., 13) → reference states (..., 13), the
    quaternion scaled to unit norm: the rotation Drake itself uses.  Its discrete plant
    updates q_{n+1} = q_n + h N(q_n) v_{n+1} without projecting back, so |q| grows by
    (h|ω|/2)²/2 a step (1.25e-5 a step at ω = 100 rad/s, h = 1e-4), while its poses and
    contact geometry use q/|q| (math::RotationMatrix normalises a quaternion):
    `quaternion_norm_drift` below records the drift."""
    y = np.array(x, dtype=float)[..., _FROM_DRAKE]
    q = y[..., L.QUATERNION]
    y[..., L.QUATERNION] = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return y


def quaternion_norm_drift(x: np.ndarray) -> float:
    """max | |q| − 1 | over Drake positions-and-velocities rows (..., 13)."""
    x = np.asarray(x, dtype=float)
    return float(np.max(np.abs(np.linalg.norm(x[..., 0:4], axis=-1) - 1.0))) if x.size else 0.0


def to_drake_state(y: np.ndarray) -> np.ndarray:
    """Reference state (13) → Drake positions-and-velocities (13)."""
    return np.asarray(y, dtype=float)[..., _TO_DRAKE]


def state_from_kinematics(model: DrakeModel, plant_context) -> np.ndarray:
    """Reference state read from Drake's own world-frame kinematics (pose and spatial
    velocity of the body); independent of `from_drake_state`."""
    X = model.plant.EvalBodyPoseInWorld(plant_context, model.body)
    V = model.plant.EvalBodySpatialVelocityInWorld(plant_context, model.body)
    q = X.rotation().ToQuaternion()
    return np.concatenate(
        [X.translation(), [q.w(), q.x(), q.y(), q.z()], V.translational(), V.rotational()]
    )


def normal_forces(model: DrakeModel, plant_context, n_contacts: int) -> np.ndarray:
    """Normal force of every scene contact from the plant's contact results."""
    results = model.plant.get_contact_results_output_port().Eval(plant_context)
    f = np.zeros(n_contacts)
    for i in range(results.num_point_pair_contacts()):
        info = results.point_pair_contact_info(i)
        pair = info.point_pair()
        k = model.contact_of.get(pair.id_A, model.contact_of.get(pair.id_B))
        if k is not None:
            f[k] += abs(float(np.dot(info.contact_force(), pair.nhat_BA_W)))
    return f


# ----------------------------------------------------------------------------- running


def _simulator(model: DrakeModel, y0: np.ndarray):
    """A Simulator at the initial state; the continuous profile gets the error-controlled
    RK3 integrator with the settings' accuracy and maximum step."""
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator

    sim = Simulator(model.diagram)
    context = sim.get_mutable_context()
    plant_context = model.plant.GetMyMutableContextFromRoot(context)
    model.plant.SetPositionsAndVelocities(plant_context, to_drake_state(y0))
    s = model.settings
    if s.time_step == 0:
        integrator = ResetIntegratorFromFlags(sim, "runge_kutta3", s.max_step)
        integrator.set_target_accuracy(s.accuracy)
        integrator.set_maximum_step_size(s.max_step)
    return sim


def simulate_drake(
    scene: Scene, dt: float, t_end: float | None = None, profile: str = "sap"
) -> Trajectory:
    """Run the scene in Drake (profile `sap` at time step dt, or `continuous` with dt as
    the maximum step) until t_end (scene.run.t_end by default) and return its Trajectory:
    one row per step, impacts from contact onsets (engines.base).  Status `failed` (the
    run stops) on a non-finite state or when a contact point is FALL_THROUGH_DEPTH·a
    (engines.stepping)
    below its ground; stats: wall_time_s, steps, steps_per_s and the profile's parameters."""
    if profile not in PROFILES:
        raise ValueError(f"unknown Drake profile {profile!r}; choose from {', '.join(PROFILES)}")
    if not dt > 0:
        raise ValueError(f"dt must be > 0, got {dt}")
    return run_with_settings(scene, contact_settings(scene, dt, profile), t_end)


class _SimulatorStepper:
    """engines.stepping.Stepper over a Drake Simulator: its monitor records every step
    (time, state, normal forces) and ends the simulation at the first row that fails the
    run loop's checks (so that a broken run stops at once, not at the chunk's end)."""

    def __init__(self, scene: Scene, model: DrakeModel, t_end: float, dt: float) -> None:
        from pydrake.systems.framework import EventStatus

        self.t_end, self.dt = t_end, dt
        self.sim = _simulator(model, initial_state(scene.initial))
        self.times: list[float] = []
        self.rows: list[np.ndarray] = []
        self.forces: list[np.ndarray] = []
        self.first = 0
        self.started = False
        plant, n_contacts = model.plant, scene.n_contacts

        def monitor(root_context):
            pc = plant.GetMyContextFromRoot(root_context)
            x = plant.GetPositionsAndVelocities(pc)
            self.times.append(root_context.get_time())
            self.rows.append(x.copy())
            self.forces.append(normal_forces(model, pc, n_contacts))
            failure = first_failure(scene, from_drake_state(x)[None])
            if failure is not None:
                return EventStatus.ReachedTermination(model.diagram, failure[1])
            return EventStatus.Succeeded()

        self.sim.set_monitor(monitor)

    def advance(self, steps: int) -> Rows:
        self.first = len(self.times)
        target = self.sim.get_context().get_time() + steps * self.dt
        if target >= self.t_end - 0.5 * self.dt:  # the last chunk ends at t_end exactly
            target = self.t_end
        broken = None
        try:
            if not self.started:
                self.started = True
                self.sim.Initialize()
            self.sim.AdvanceTo(target)
        except RuntimeError as exc:  # e.g. the integrator cannot meet its accuracy
            broken = f"Drake stopped: {exc}"
        new = self.rows[self.first :]
        states = from_drake_state(np.array(new)) if new else np.zeros((0, 13))
        return Rows(np.array(self.times[self.first :]), states, broken)

    def cut(self, keep: int) -> None:
        end = self.first + keep
        del self.times[end:], self.rows[end:], self.forces[end:]

    def settle(self) -> float:
        kept = min(len(self.times), len(self.rows), len(self.forces))
        self.cut(kept - self.first)
        return self.times[-1] if self.times else 0.0

    def recording(self, loop) -> Recording:
        return _recording(self, loop)


def run_with_settings(scene: Scene, settings: DrakeSettings, t_end: float | None = None):
    """`simulate_drake` with explicit settings (the restitution study varies them).  One
    chunk of the driver (engines.stepping.simulate_fixed_step) to t_end: Drake's
    Simulator takes its own steps (error-controlled on the continuous plant), which a
    chunk boundary would cut."""
    dt = settings.time_step or settings.max_step

    def build(n_steps: int) -> _SimulatorStepper:
        t_run = scene.run.t_end if t_end is None else float(t_end)
        stepper = _SimulatorStepper(scene, build_model(scene, settings), t_run, dt)
        stepper.scene, stepper.settings = scene, settings
        return stepper

    return simulate_fixed_step(scene, ENGINE_NAMES[settings.profile], dt, t_end, build)


def _recording(stepper: _SimulatorStepper, loop) -> Recording:
    """Every monitored row (the finite ones after a failure), its impulses and the
    profile's parameters."""
    scene, settings = stepper.scene, stepper.settings
    n_contacts = scene.n_contacts
    t = np.array(stepper.times)
    states = from_drake_state(np.array(stepper.rows)) if stepper.rows else np.zeros((0, 13))
    F = np.array(stepper.forces) if stepper.forces else np.zeros((0, n_contacts))
    if loop.status is Status.FAILED:  # keep the finite rows only
        ok = np.all(np.isfinite(states), axis=1)
        t, states, F = t[ok], states[ok], F[ok]
    stats = {
        "profile": settings.profile,
        "stiffness": settings.stiffness,
        "hc_dissipation": settings.hc_dissipation,
        "relaxation_time": settings.relaxation_time,
        "contact_steps": settings.contact_steps,
        "max_step": settings.max_step,
        "accuracy": settings.accuracy,
        "restitution_model": settings.restitution_model,
        "quaternion_norm_drift": quaternion_norm_drift(np.array(stepper.rows)),
        "drake_version": _drake_version(),
    }
    return Recording(t, states, _impulses(t, F, settings), max(len(t) - 1, 0), stats)


def _impulses(t: np.ndarray, F: np.ndarray, settings: DrakeSettings) -> np.ndarray:
    """Per-row normal impulses: f h on the discrete plant (the force of the step that
    produced the row); the trapezoid over the step on the continuous plant."""
    if settings.time_step > 0 or len(t) == 0:
        return F * settings.time_step
    out = np.zeros_like(F)
    out[1:] = 0.5 * (F[1:] + F[:-1]) * np.diff(t)[:, None]
    return out


def _drake_version() -> str | None:
    from importlib import metadata

    try:
        return metadata.version("drake")
    except metadata.PackageNotFoundError:
        return None
