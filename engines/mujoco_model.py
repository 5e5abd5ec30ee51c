"""MuJoCo model of a scene, built with `mujoco.MjSpec` (MuJoCo's model-editing API, no
formatted XML): the same body and ground as the reference, with the contact parameters
of a profile.

Geometry (docs/engines.md, "Geometry that is exactly a point contact"):

- body: one free body with explicit inertia (mass m at the origin, diagonal m(ρa)²(1, 1, 2)),
  so MuJoCo's body frame is the reference's principal body frame (no realignment);
- `flat`: a sphere of radius r at each vertex a(cos 2πk/n, sin 2πk/n, 0) and the ground
  plane at z = −r.  Sphere–plane contact has the plane's normal ẑ and distance
  z_vertex + r − r = the reference's gap exactly, and the force acts on the vertical line
  through the vertex, so it is an exact point contact for any r;
- `three_point`: a sphere of radius r centred at each bump b_k = b(cos 2πk/3, sin 2πk/3, 0)
  (fixed in the world) and, on the body, a cylinder whose bottom face lies at body
  height +r.  Sphere–face distance = (x + r e3 − b_k)·e3 − r = (x − b_k)·e3, the
  reference's gap, for every tilt; the normal is the face normal e3 and the force acts on
  the line through b_k along e3 (the reference's line of action) exactly.

Everything is frictionless (condim = 1: normal force only) and gravity is (0, 0, −g).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from reference.scene import Scene

from .stepping import SPHERE_RADIUS_FRACTION

PROFILES = ("tuned", "default")
# intprm[0] of a contact sensor: the bit set of its data fields; 2 = "force" (the MJCF
# attribute data="force" compiles to it, read back from MjSpec.from_string).
CONTACT_SENSOR_DATA_FORCE = 2

# Contact sphere radius as a fraction of the body radius: engines.stepping's
# SPHERE_RADIUS_FRACTION.  Any r gives the exact point contact (see the module docstring);
# 1e-3 keeps the geoms' bounding boxes tight without approaching the collision code's
# absolute tolerances.
# Half-thickness of the three_point contact face (a cylinder of the body's radius).  Only
# its bottom face is ever touched; its mass is ignored because <inertial> is explicit.  A
# bump deeper than the half-thickness would be pushed out through the top face; the run
# loop (engines.stepping.FALL_THROUGH_DEPTH) ends the run before that.
FACE_HALF_THICKNESS_FRACTION = 0.1
# Bumpy ground: (contype, conaffinity) of the geoms of each contact kind.  The world's
# geom (plane or bump) only receives (contype 0), the body's geom only reaches
# (conaffinity 0), and the two kinds use different bits, so the only pairs MuJoCo
# collides are vertex–plane (bit 1) and face–bump (bit 2).
RIM_COLLISION = {"world": (0, 1), "body": (1, 0)}
BUMP_COLLISION = {"world": (0, 2), "body": (2, 0)}

# MuJoCo's own defaults, written out where the default profile uses them.
MUJOCO_DEFAULT_TIMECONST = 0.02  # solref[0] default
# The Restitution section of MuJoCo's modelling guide: "a sphere bouncing on a plane with
# restitution coefficient of 1" uses solref="-1000 0" (stiffness 1000, damping 0).
MUJOCO_DOC_ELASTIC_SOLREF = (-1000.0, 0.0)

# Tuned contact: the constraint's stiffness in units of 1/h².  Zero: a pure damper (see
# `tuned_contact` for why any stiffness biases every bounce by a dt-independent amount).
TUNED_STIFFNESS_H2 = 0.0
# Constant impedance d = mjMAXIMP (0.9999): solimp = (d0, dwidth, width, mid, power) with
# d0 = dwidth makes d(r) independent of the penetration r (a linear spring-damper), and the
# largest allowed d makes the regulariser R = (1 − d)/d · A negligible (1e-4 relative).
TUNED_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


@dataclass(frozen=True)
class ContactSettings:
    """Everything a profile chooses: contact softness, integrator, solver options."""

    profile: str
    solref: tuple[float, float] | None  # None: MuJoCo's default (0.02, 1)
    solimp: tuple[float, ...] | None  # None: MuJoCo's default (0.9, 0.95, 0.001, 0.5, 2)
    integrator: str | None  # None: MuJoCo's default (Euler)
    diagexact: bool = False
    tolerance: float | None = None  # None: MuJoCo's default (1e-8)
    # read MuJoCo's semi-implicit Euler as leapfrog: velocities live at half steps
    # (engines/mujoco.py, `staggered_start` and `whole_step_velocities`)
    half_step_velocities: bool = False
    restitution_model: str = ""  # one line: how γ enters


def damping_ratio_for_restitution(gamma: float) -> float:
    """ζ of a linear damped oscillator whose half-period bounce has e = γ:
    e = exp(−πζ/√(1 − ζ²))  ⇔  ζ = −ln γ / √(π² + ln² γ)  (ζ = 1 for γ = 0)."""
    if gamma <= 0.0:
        return 1.0
    lg = -math.log(gamma)
    return lg / math.sqrt(math.pi**2 + lg * lg)


def tuned_contact(gamma: float, dt: float) -> ContactSettings:
    """Best fidelity we found: a damper that applies Newton's law within one step.

    MuJoCo's soft constraint (modelling guide, "Solver parameters") gives an active
    contact the acceleration a₁ = −d·(b̃ vₙ + k̃ r) + (1 − d)·a₀ with, in the direct solref
    format (−k, −b), b̃ = b/d_width and k̃ = k·d(r)/d_width².  With a constant impedance
    d = d(r) = d_width this is a₁ = −b vₙ − k r + (1 − d) a₀, exactly when the regulariser
    uses the exact diagonal of A = J M⁻¹ Jᵀ (diagexact).  The Euler velocity update
    vₙ⁺ = vₙ + h a₁ with b = (1 + γ)/h then gives vₙ⁺ = −γ vₙ − h k r + O((1 − d) h a₀):
    Newton's restitution law within one step, whatever the effective mass.  Once the
    contact separates the clamp f ≥ 0 switches it off; while it is held (resting,
    rolling) the same damper removes the normal velocity.

    Stiffness k = 0: a pure damper.  A spring would pull a penetrating contact back out,
    but at an onset the penetration r (|r| ≤ |vₙ| h, a random fraction of it) makes
    −h k r add up to k h²·|vₙ| to the bounce: a bias that does not shrink with h (with
    k = 1e-4/h², +1e-4 of the energy per impact on pentagon-bounce at every h from 1e-4
    to 2e-6, measured; 1e-3/h² is ten times worse; docs/engines.md compares them on six
    scenes).  Without it the
    penetration left by an onset stays (≤ |vₙ| h, the step's own error), and a resting
    contact sinks at (1 − d) g h/(1 + γ), i.e. 1e-4 g h² per step: 3e-8 over 3 s at
    h = 1e-4.  d = 1 − 1e-4 is MuJoCo's largest impedance (mjMAXIMP).  Measured with
    `harness restitution --engine mujoco` (single vertex drop, γ = 0.3…0.95,
    h = 1e-3…1e-5): see docs/engines.md, "The restitution contract".

    Integrator: Euler, MuJoCo's semi-implicit (symplectic) Euler, for which the one-step
    damper is exact and whose velocities we read at half steps (leapfrog; see
    engines/mujoco.py), which makes free flight second order.  RK4 cannot flip a
    velocity within one step (its stability polynomial at z = −(1 + γ) is positive);
    implicitfast/implicit add the gyroscopic derivative to the velocity update and lose
    energy in a spinning flight as fast as Euler gains it (−0.19 % vs +0.19 % over 3 s of a
    spinning pentagon at h = 1e-4, measured).
    """
    return ContactSettings(
        profile="tuned",
        solref=(-TUNED_STIFFNESS_H2 / (dt * dt), -(1.0 + gamma) / dt),
        solimp=TUNED_SOLIMP,
        integrator="Euler",
        # exact diagonal of A = J M⁻¹ Jᵀ in the regulariser R = (1 − d)/d·A instead of
        # MuJoCo's body-based approximation (which ignores the contact's lever arm), so that
        # the one-step law above holds exactly; the difference is O(1 − d) = 1e-4.
        diagexact=True,
        # Newton's solver stops on relative improvement; tighter than the default 1e-8 so
        # contact impulses are converged (changes states by ~5e-11; speed unchanged).
        tolerance=1e-12,
        half_step_velocities=True,
        restitution_model="one-step damper solref=(0, -(1+gamma)/h), constant solimp d=0.9999",
    )


def default_contact(gamma: float, dt: float) -> ContactSettings:
    """What a typical user writes: MuJoCo's defaults plus the documented way to make a
    contact bouncy.

    MuJoCo has no restitution parameter.  Its guide says solref = (timeconst, dampratio)
    with dampratio 1 "critical damping" and smaller values "under-damped or bouncy", so a
    user who wants restitution γ keeps the default timeconst 0.02 and sets dampratio to
    the damped-oscillator value ζ(γ) (`damping_ratio_for_restitution`); γ = 0 gives ζ = 1,
    i.e. exactly MuJoCo's default contact.  For γ = 1, ζ = 0 is not a valid positive
    solref (MuJoCo rejects it as a mixed format), and the user copies the guide's elastic
    example solref = "−1000 0" (Restitution section).  Everything else (solimp, Euler
    integrator, solver) stays at MuJoCo's defaults; refsafe keeps timeconst ≥ 2h.

    We chose this rather than leaving restitution unmodelled (pure defaults give e ≈ 0.13
    for every γ, measured) because it shows what the documented recipe gives: the clamped
    nonlinear spring-damper is biased (γ = 0.3 → e ≈ 0.39) and can go unstable when the
    oscillator's frequency 1/(timeconst·ζ) is too high for the step (γ = 0.95 at h = 1e-3).
    Another measured trait: on the three-point ground at h = 1e-3, a disk released a hair
    above the bumps never settles (vertical limit cycle of amplitude ~1e-6 a, loads ~10 %
    off), because the contact vanishes whenever dist > 0 while its force at dist = 0 is
    already d·m g; at h = 1e-4, or with diagexact, it settles.
    """
    if gamma >= 1.0:
        solref = MUJOCO_DOC_ELASTIC_SOLREF
        how = "guide's elastic example solref=(-1000, 0)"
    else:
        solref = (MUJOCO_DEFAULT_TIMECONST, damping_ratio_for_restitution(gamma))
        how = "solref=(0.02, zeta(gamma)) with the damped-oscillator zeta; default solimp"
    return ContactSettings(
        profile="default",
        solref=solref,
        solimp=None,
        integrator=None,
        restitution_model=how,
    )


def contact_settings(scene: Scene, dt: float, profile: str) -> ContactSettings:
    if profile == "tuned":
        return tuned_contact(scene.restitution, dt)
    if profile == "default":
        return default_contact(scene.restitution, dt)
    raise ValueError(f"unknown MuJoCo profile {profile!r}; choose from {', '.join(PROFILES)}")


def contact_geom_pairs(scene: Scene) -> list[tuple[str, str]]:
    """(geom1, geom2) names of contact k: vertex k/ground for a rim vertex, bump j/face
    for floor point j (the contact numbering of docs/contract.md)."""
    contacts = scene.contacts
    return [(f"vertex{k}", "ground") for k in range(contacts.n_rim)] + [
        (f"bump{j}", "face") for j in range(len(contacts.floor_points))
    ]


def _integrator(name: str | None) -> mujoco.mjtIntegrator:
    """MuJoCo's integrator enum from its MJCF name (None: MuJoCo's default, Euler)."""
    names = {
        None: mujoco.mjtIntegrator.mjINT_EULER,
        "Euler": mujoco.mjtIntegrator.mjINT_EULER,
        "RK4": mujoco.mjtIntegrator.mjINT_RK4,
        "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
        "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    }
    return names[name]


def build_spec(scene: Scene, dt: float, profile: str = "tuned") -> mujoco.MjSpec:
    """The scene's model as an `mujoco.MjSpec` (MuJoCo's model-editing API) under a
    profile, with one contact sensor per contact point (normal force of contact k, so a
    rollout reports every contact force per step).  `spec.to_xml()` shows it as MJCF."""
    s = contact_settings(scene, dt, profile)
    a = scene.body.radius
    r = SPHERE_RADIUS_FRACTION * a
    spec = mujoco.MjSpec()
    spec.modelname = scene.name
    spec.compiler.degree = False  # angles in radians (none are given)
    spec.option.timestep = dt
    spec.option.gravity = [0.0, 0.0, -scene.gravity]
    spec.option.integrator = _integrator(s.integrator)
    if s.tolerance is not None:
        spec.option.tolerance = s.tolerance
    if s.diagexact:
        spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_DIAGEXACT

    def contact_geom(parent, name, **attributes):
        geom = parent.add_geom(name=name, condim=1, **attributes)  # frictionless
        if s.solref is not None:
            geom.solref = list(s.solref)
        if s.solimp is not None:
            geom.solimp = list(s.solimp)
        return geom

    world = spec.worldbody
    body = world.add_body(name="body")
    body.add_freejoint(name="free")
    body.explicitinertial = True  # the inertia below, not the geoms' (principal frame)
    body.mass = scene.body.mass
    body.ipos = [0.0, 0.0, 0.0]
    body.inertia = list(scene.body.inertia_diag)
    contacts = scene.contacts
    # both kinds on one ground (bumpy): bit masks keep each body geom to its own partner
    both = contacts.has_plane and len(contacts.floor_points) > 0
    if len(contacts.floor_points):  # floor points: spheres on the ground under a face
        masks = BUMP_COLLISION if both else None
        _add_bumps(world, body, contact_geom, contacts.floor_points, a, r, masks)
    if contacts.has_plane:  # rim vertices: spheres on the body over a plane
        _add_rim(world, body, contact_geom, contacts.rim_points, r, RIM_COLLISION if both else None)
    for k, (g1, g2) in enumerate(contact_geom_pairs(scene)):
        spec.add_sensor(
            name=f"force{k}",
            type=mujoco.mjtSensor.mjSENS_CONTACT,
            objtype=mujoco.mjtObj.mjOBJ_GEOM,
            objname=g1,
            reftype=mujoco.mjtObj.mjOBJ_GEOM,
            refname=g2,
            # MJCF <contact data="force" num="1">: data bit 2 (force), no reduction, 1 slot
            intprm=[CONTACT_SENSOR_DATA_FORCE, 0, 1],
        )
    return spec


def _add_rim(world, body, contact_geom, vertices, r: float, collision=None) -> None:
    """The floor plane at z = −r and a sphere of radius r at each body-frame vertex."""
    masks = _masks(collision)
    plane, sphere = mujoco.mjtGeom.mjGEOM_PLANE, mujoco.mjtGeom.mjGEOM_SPHERE
    contact_geom(world, "ground", type=plane, size=[0, 0, 1], pos=[0, 0, -r], **masks["world"])
    for k, p in enumerate(vertices):
        contact_geom(body, f"vertex{k}", type=sphere, size=[r, 0, 0], pos=list(p), **masks["body"])


def _add_bumps(world, body, contact_geom, bumps, a: float, r: float, collision=None) -> None:
    """A sphere of radius r centred at each world bump and the face: a cylinder of the
    body's radius whose bottom lies at body height +r."""
    masks = _masks(collision)
    sphere = mujoco.mjtGeom.mjGEOM_SPHERE
    for k, p in enumerate(bumps):
        contact_geom(world, f"bump{k}", type=sphere, size=[r, 0, 0], pos=list(p), **masks["world"])
    hh = FACE_HALF_THICKNESS_FRACTION * a
    cylinder = mujoco.mjtGeom.mjGEOM_CYLINDER
    contact_geom(body, "face", type=cylinder, size=[a, hh, 0], pos=[0, 0, r + hh], **masks["body"])


def _masks(collision) -> dict[str, dict[str, int]]:
    """MjsGeom attributes for (contype, conaffinity) pairs; none: MuJoCo's defaults."""
    if collision is None:
        return {"world": {}, "body": {}}
    return {side: {"contype": ct, "conaffinity": ca} for side, (ct, ca) in collision.items()}


def load_model(scene: Scene, dt: float, profile: str = "tuned") -> mujoco.MjModel:
    return build_spec(scene, dt, profile).compile()
