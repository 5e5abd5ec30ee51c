"""Scenes: the problem statement, validated into immutable data.

A scene is a regular n-gon (or a disk on three ground bumps), its ground, its initial
state and how long to run.  The TOML layout is public (docs/contract.md); this module turns
a parsed mapping into a frozen :class:`Scene` and rejects bad input with
:class:`SceneError` (one clear sentence, never a traceback at the CLI).

Accepted ranges (docs/inputs.md gives the reasons and the measurements behind them).
Units: the body's radius a, its mass m, and the time unit τ = min(√(a/g), t_end) (t_end
alone when g = 0), with the velocity unit U = a/τ = max(√(g a), a/t_end):

- a, m, g (when > 0), t_end in DIMENSION_RANGE: the code forms products of up to six
  such numbers (e.g. the rotational energy ½ m ρ² a² ω²), which stay within 1e±300,
  inside double precision's 1e±308;
- ρ in GYRATION_RANGE: the impact law adds 1/m and a²/(m ρ² a²); with ρ² within
  1e±12 of 1 the smaller keeps four of its sixteen digits;
- 2 ≤ n ≤ MAX_VERTICES: beyond, the polygon differs from its circle by
  a (1 − cos π/n) < 5e-12 a; the per-vertex arrays cost O(n) memory;
- bump_radius / a in [MIN_BUMP_RADIUS, 1); listed bumps at least MIN_BUMP_SPACING a
  apart in the plane (coincident bumps make a singular impact problem);
- simultaneity_window at most MAX_WINDOW_TIME_UNITS time units a/V = √(a/g)
  (check_window_bound: a wider window merges a contact's later bounces);
- speed group (|v| + |ω| a) / U ≤ MAX_SPEED, i.e. v²/(g a) and ω² a/g ≤ 1e6: the
  reference's tolerances follow the body's velocity scale V (velocity noise 64 ε V,
  chatter completed below 1e-6 V), and on flat ground the horizontal velocity and the
  spin about the vertical never decay, so V stays large while the vertical motion it
  must resolve dies out (measured with an added horizontal velocity: the end time
  agrees to 11 digits up to V/U = 1e3, moves by 5 % at 3e3, and one run takes 45 s at
  1e8);
- |position| / a ≤ MAX_POSITION (contact gaps keep ≥ 10 digits of a), |rotation
  vector| ≤ MAX_ROTATION_VECTOR rad (the attitude's roundoff ε |φ| stays below 2e-13);
  the tilt α itself needs no limit (the geometry keeps tilts of 1e-15 exactly);
- the linear scale ε (`initial.scale`, `--scale`) in SCALE_RANGE (ε² q underflows or
  overflows beyond), and the scaled scene passes the same checks;
- run.max_impacts ≤ MAX_IMPACTS (about 0.25 kB of memory per impact: 296 MB measured
  for 1e6 impacts).
"""

from __future__ import annotations

import math
import os
import stat
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .contact_kinds import GroundContacts, ground_contacts, listed_contacts
from .core.laws import DEFAULT_LAW, LAW_NAMES, LAW_PAPER, law_code
from .core.layout import QUATERNION
from .geometry import initial_state, scene_contact_kinematics
from .quaternion import body_axis


class SceneError(ValueError):
    """A scene that cannot be simulated: the message says which field and why."""


DIMENSION_RANGE = (1e-50, 1e50)
GYRATION_RANGE = (1e-6, 1e6)
MAX_VERTICES = 1_000_000
MIN_BUMP_RADIUS = 1e-6
# Least distance in the plane between two bumps, in body radii: the resolution of
# MIN_BUMP_RADIUS (closer bumps make nearly equal contact rows, whose complementarity
# problem loses more digits than the 1e-12 relative the impact law keeps).
MIN_BUMP_SPACING = MIN_BUMP_RADIUS
# three_point ground: the floor plane lies this far below the bumps' tops, in body radii,
# unless [ground] floor_depth says (a model limit, not a contact: reference.core.floor).
# A tenth of the radius: a disk held on a bump at b = a/2 reaches it at a tilt of about
# 0.2 rad, where the linear model leaves its domain (reference.linear.domain).
DEFAULT_FLOOR_DEPTH = 0.1
MAX_SPEED = 1e3
MAX_POSITION = 1e6
MAX_ROTATION_VECTOR = 1e3
# the impact laws of simultaneous impacts: the registry's (reference.core.laws)
IMPACT_LAWS = LAW_NAMES
DEFAULT_IMPACT_LAW = DEFAULT_LAW
# the exact reference's simultaneity window [time unit of the scene] under `moreau` and
# `sequential` when neither the scene nor the options set one (under `paper`: 0,
# default_window): contacts whose zeros are this close (× |u|/√(g a)) are reached
# together; 0 = strictly sequential (the core orders contacts down to its time
# resolution).  1e-11: far above the event times' certified error (~1e-16 t), far below
# the steps engines resolve (1e-4), and the largest decade that leaves the check scenes'
# cascades alone (docs/laws.md, "The simultaneity window", measured).  The linear model's
# default is 0 (reference.linear.simulate.LINEAR_DEFAULT_WINDOW)
DEFAULT_SIMULTANEITY_WINDOW = 1e-11
SCALE_RANGE = (1e-50, 1e50)
MAX_IMPACTS = 10_000_000
# The widest simultaneity window, in time units a/V (check_window_bound)
MAX_WINDOW_TIME_UNITS = 1.0
MAX_SCENE_FILE_BYTES = 1 << 20
MAX_NAME_LENGTH = 200


@dataclass(frozen=True)
class Body:
    """Thin regular n-gon: vertices a(cos 2πi/n, sin 2πi/n, 0), inertia m(ρa)² diag(1,1,2)."""

    n: int
    radius: float = 1.0
    mass: float = 1.0
    gyration: float = 0.5

    @property
    def inertia_diag(self) -> tuple[float, float, float]:
        i1 = self.mass * (self.gyration * self.radius) ** 2
        return (i1, i1, 2.0 * i1)


@dataclass(frozen=True)
class Ground:
    """The scene file's [ground]: `flat`, the plane z = 0 that the body's rim vertices
    touch; `three_point`, floor points (bumps) at (b cos 2πk/3, b sin 2πk/3, 0) that
    touch the body's face; `bumpy`, both: the plane under the rim and bumps
    above it under the face, `bumps` (x, y, height) or three at (b cos 2πk/3,
    b sin 2πk/3, bump_height).  Lengths in the scene's units, like the body's radius.
    On `three_point` ground the floor plane lies `floor_depth` below the bumps' tops
    (None: DEFAULT_FLOOR_DEPTH body radii; inf: no floor): not a contact, a model limit
    (`floor_below`).
    `contacts` turns it into the list of contacts of kinds (reference.contact_kinds)
    that everything else reads."""

    kind: str = "flat"
    bump_radius: float = 0.5
    bump_height: float = 0.0
    bumps: tuple[tuple[float, float, float], ...] | None = None
    floor_depth: float | None = None

    def floor_below(self, body: Body) -> float:
        """d of the floor plane z = −d under the `three_point` ground's bumps (tops at
        z = 0), which that ground does not model: its rim reaching the plane ends a run
        `left_model` (reference.core.floor).  inf on the grounds whose rim vertices have
        the plane z = 0 as contacts (`flat`, `bumpy`), and on request."""
        if self.kind != "three_point":
            return math.inf
        if self.floor_depth is None:
            return DEFAULT_FLOOR_DEPTH * body.radius
        return self.floor_depth

    def bump_table(self) -> tuple[tuple[float, float, float], ...]:
        """(x, y, height) of every bump of a bumpy ground (module docstring)."""
        if self.bumps is not None:
            return self.bumps
        b, ang = self.bump_radius, [2.0 * math.pi * k / 3 for k in range(3)]
        return tuple((b * math.cos(t), b * math.sin(t), self.bump_height) for t in ang)

    def contacts(self, body: Body) -> GroundContacts:
        """The ground's contacts for this body: `flat`, its n rim vertices on the plane;
        `three_point`, three floor points on its face; `bumpy`, the n rim vertices then
        the bumps."""
        if self.kind == "three_point":
            return ground_contacts(0, body.radius, 3, self.bump_radius)
        if self.kind == "bumpy":
            return listed_contacts(body.n, body.radius, self.bump_table())
        return ground_contacts(body.n, body.radius, 0, self.bump_radius)

    @property
    def name(self) -> str:
        """The ground's name in text: 'flat', 'three-point'."""
        return self.kind.replace("_", "-")


@dataclass(frozen=True)
class InitialState:
    """Full initial state in the world frame (rotation vector for the attitude)."""

    position: tuple[float, float, float]
    rotation_vector: tuple[float, float, float]
    velocity: tuple[float, float, float]
    angular_velocity: tuple[float, float, float]
    # The paper's linear coordinates, when the scene was given in them (after scaling).
    q: tuple[float, float, float] | None = None
    p: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class RunSettings:
    t_end: float = 5.0
    max_impacts: int = 100_000


@dataclass(frozen=True)
class Scene:
    name: str
    body: Body
    ground: Ground
    initial: InitialState
    restitution: float = 0.5
    gravity: float = 1.0
    description: str = ""
    run: RunSettings = field(default_factory=RunSettings)
    impact_law: str = DEFAULT_IMPACT_LAW
    simultaneity_window: float | None = None  # None: the simulator's default

    @property
    def contacts(self) -> GroundContacts:
        """The ground's contacts for the scene's body (`Ground.contacts`)."""
        return self.ground.contacts(self.body)

    @property
    def n_contacts(self) -> int:
        return self.contacts.n

    def with_run(self, **changes: Any) -> Scene:
        """The scene with other run settings, checked like a scene file's [run]
        (a longer t_end lowers the velocity unit U of the speed check)."""
        if "t_end" in changes:
            check_t_end(changes["t_end"])
        if "max_impacts" in changes:
            _check_max_impacts(changes["max_impacts"])
        scene = replace(self, run=replace(self.run, **changes))
        check_scene(scene)
        return scene

    def with_impact_law(self, law: str | None = None, window: float | None = None) -> Scene:
        """The scene with another impact law and/or simultaneity window (None: keep),
        checked like a scene file's keys."""
        return replace(
            self,
            impact_law=self.impact_law if law is None else check_impact_law(law),
            simultaneity_window=(
                self.simultaneity_window if window is None else check_window(window)
            ),
        )

    def scaled(self, eps: float, name: str = "--scale") -> Scene:
        """Apply the paper's scaling invariance to the linear initial coordinates:
        q → ε² q, p → ε p (section 2.6).  Only defined for scenes given by (q, p).
        The result passes the same checks as a scene file (check_scene), the
        below-ground check included."""
        if self.initial.q is None or self.initial.p is None:
            raise SceneError(
                f"{name} needs a scene whose [initial] is given by q and p (the scaling "
                f"q -> eps^2 q, p -> eps p acts on linear coordinates); {self.name}'s is "
                "given by position, rotation_vector, ..."
            )
        scene = replace(self, initial=scaled_initial(self.initial.q, self.initial.p, eps, name))
        check_scene(scene)
        return scene


def scaled_initial(q, p, eps: float, name: str = "scale") -> InitialState:
    """The full state of linear coordinates scaled by ε: (ε² q, ε p)."""
    _check_in_range(name, eps, SCALE_RANGE)
    return initial_from_linear([eps * eps * x for x in q], [eps * x for x in p])


def initial_from_linear(q, p) -> InitialState:
    """Map linear coordinates to a full state (docs/contract.md): attitude = rotation vector
    (φx, φy, 0), centre of mass (0, 0, h), velocity (0, 0, v), ω = (ωx, ωy, 0)."""
    q = tuple(float(x) for x in q)
    p = tuple(float(x) for x in p)
    return InitialState(
        position=(0.0, 0.0, q[2]),
        rotation_vector=(q[0], q[1], 0.0),
        velocity=(0.0, 0.0, p[2]),
        angular_velocity=(p[0], p[1], 0.0),
        q=q,
        p=p,
    )


# --------------------------------------------------------------------------- parsing

_TOP_KEYS = {
    "name", "description", "gravity", "restitution", "impact_law", "simultaneity_window",
    "body", "ground", "initial", "run",
}  # fmt: skip
_BODY_KEYS = {"n", "radius", "mass", "gyration"}
_GROUND_KEYS = {"kind", "bump_radius", "bump_height", "bumps", "floor_depth"}
GROUND_KINDS = ("flat", "three_point", "bumpy")
# Most bumps a bumpy ground may list (each is a contact the search examines one by one).
MAX_BUMPS = 64
_INITIAL_LINEAR = {"q", "p", "scale"}
_INITIAL_FULL = {"position", "rotation_vector", "velocity", "angular_velocity"}
_RUN_KEYS = {"t_end", "max_impacts"}


def load_scene_file(path: str | Path) -> Scene:
    """Read and validate a scene file (a regular UTF-8 TOML file of at most
    MAX_SCENE_FILE_BYTES)."""
    path = Path(path)
    shown = show_path(path)
    try:
        if not path.exists():
            raise SceneError(f"scene file not found: {shown}")
        problem = input_file_problem(path)
        if problem:
            raise SceneError(f"{shown}: {problem} (a scene is a TOML file)")
        with open(path, "rb") as fh:
            raw = fh.read(MAX_SCENE_FILE_BYTES + 1)
    except SceneError:
        raise
    except OSError as exc:
        raise SceneError(f"cannot read scene file {shown}: {exc.strerror or exc}") from None
    except ValueError as exc:  # e.g. a NUL character in the path
        raise SceneError(f"cannot read scene file {shown}: {exc}") from None
    if len(raw) > MAX_SCENE_FILE_BYTES:
        raise SceneError(f"{shown} is larger than {MAX_SCENE_FILE_BYTES} bytes: not a scene file")
    try:
        data = tomllib.loads(raw.decode("utf-8-sig"))  # a byte-order mark is accepted
    except UnicodeDecodeError:
        raise SceneError(f"{shown} is not UTF-8 text (scene files are TOML)") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{shown}: malformed TOML: {exc}") from None
    except RecursionError:
        raise SceneError(f"{shown}: TOML nested too deeply to be a scene") from None
    return scene_from_dict(data, default_name=path.stem)


def input_file_problem(path: str | Path) -> str:
    """Why `path` cannot be read as an input file ('' for a regular file, or a link to
    one): missing, or which kind of non-regular file it is (a FIFO would block the read)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file or directory"
    except (OSError, ValueError) as exc:
        return f"cannot be read ({getattr(exc, 'strerror', None) or exc})"
    for test, what in (
        (stat.S_ISREG, ""),
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
    ):
        if test(mode):
            return f"{what}, not a regular file" if what else ""
    return "not a regular file"


def show_path(path: str | Path, limit: int = 80) -> str:
    """A path for a one-line message: long ones shortened in the middle."""
    text = repr(str(path))[1:-1]
    if len(text) <= limit:
        return text
    return f"{text[: limit // 2 - 2]}...{text[-(limit // 2 - 1) :]}"


def scene_from_dict(data: dict[str, Any], default_name: str = "scene") -> Scene:
    """Validate a parsed scene mapping (the TOML layout of docs/contract.md) into a Scene:
    every field's type and range, then the checks of `check_scene`."""
    if not isinstance(data, dict):
        raise SceneError(f"a scene is a TOML table, got {type(data).__name__}")
    _check_keys("scene", data, _TOP_KEYS)
    gravity = _number("gravity", data.get("gravity", 1.0))
    _check_gravity(gravity)
    gamma = _number("restitution", data.get("restitution", 0.5))
    _check_restitution(gamma)
    body = _parse_body(_table("body", data))
    scene = Scene(
        name=_text("name", data.get("name", default_name)),
        description=_text("description", data.get("description", "")),
        gravity=gravity,
        restitution=gamma,
        body=body,
        ground=_parse_ground(_optional_table("ground", data), body),
        initial=_parse_initial(_table("initial", data)),
        run=_parse_run(_optional_table("run", data)),
        impact_law=check_impact_law(data.get("impact_law", DEFAULT_IMPACT_LAW)),
        simultaneity_window=(
            None
            if data.get("simultaneity_window") is None
            else check_window(_number("simultaneity_window", data["simultaneity_window"]))
        ),
    )
    check_scene(scene)
    return scene


def check_impact_law(law: Any) -> str:
    """One of IMPACT_LAWS."""
    if law not in IMPACT_LAWS:
        raise SceneError(f"impact_law must be one of {', '.join(IMPACT_LAWS)}, got {law!r}")
    return law


def check_window(window: Any) -> float:
    """A simultaneity window: a finite time >= 0 (0: strictly sequential)."""
    w = _number("simultaneity_window", window)
    if not 0.0 <= w <= DIMENSION_RANGE[1]:
        raise SceneError(f"simultaneity_window must be a finite time >= 0, got {window!r}")
    return w


def _parse_body(b: dict) -> Body:
    _check_keys("[body]", b, _BODY_KEYS)
    if "n" not in b:
        raise SceneError("[body] needs n (number of vertices, >= 2)")
    n = b["n"]
    _check_vertices(n)
    return Body(
        n=n,
        radius=_in_range("body.radius", b.get("radius", 1.0), DIMENSION_RANGE),
        mass=_in_range("body.mass", b.get("mass", 1.0), DIMENSION_RANGE),
        gyration=_in_range("body.gyration", b.get("gyration", 0.5), GYRATION_RANGE),
    )


def _parse_ground(gr: dict, body: Body) -> Ground:
    _check_keys("[ground]", gr, _GROUND_KEYS)
    kind = gr.get("kind", "flat")
    if kind not in GROUND_KINDS:
        raise SceneError(f"ground.kind must be 'flat', 'three_point' or 'bumpy', got {kind!r}")
    if kind != "bumpy" and ("bump_height" in gr or "bumps" in gr):
        raise SceneError("ground.bump_height and ground.bumps belong to kind = 'bumpy'")
    if kind != "three_point" and "floor_depth" in gr:
        raise SceneError(
            "ground.floor_depth belongs to kind = 'three_point' (the other grounds have the "
            "plane z = 0 as the rim's contacts)"
        )
    if kind == "bumpy" and "bumps" in gr:
        if "bump_radius" in gr or "bump_height" in gr:
            raise SceneError(
                "[ground] gives either bumps = [[x, y, height], ...] or bump_radius and "
                "bump_height, not both"
            )
        return Ground(kind=kind, bumps=_parse_bumps(gr["bumps"], body.radius))
    bump = _number("ground.bump_radius", gr.get("bump_radius", 0.5 * body.radius))
    _check_bump_radius(bump, kind, body.radius)
    if kind == "bumpy":
        height = _number("ground.bump_height", gr.get("bump_height", 0.0))
        _check_bump_height("ground.bump_height", height, body.radius)
        return Ground(kind=kind, bump_radius=bump, bump_height=height)
    if kind == "three_point" and "floor_depth" in gr:
        depth = _floor_depth(gr["floor_depth"], body.radius)
        return Ground(kind=kind, bump_radius=bump, floor_depth=depth)
    return Ground(kind=kind, bump_radius=bump)


def _floor_depth(value: Any, radius: float) -> float:
    """ground.floor_depth: how far below the bumps' tops the floor plane lies, in
    (0, MAX_POSITION] × body.radius, or inf (no floor)."""
    if isinstance(value, float) and value == math.inf:
        return value
    d = _number("ground.floor_depth", value)
    if not 0.0 < d <= MAX_POSITION * radius:
        raise SceneError(
            f"ground.floor_depth must be in (0, {MAX_POSITION:g}] x body.radius "
            f"({radius:g}) or inf, got {d:g}"
        )
    return d


def _parse_bumps(value: Any, radius: float) -> tuple[tuple[float, float, float], ...]:
    """ground.bumps: 1 … MAX_BUMPS triples (x, y, height), each under the disk lying
    centred (less than a radius from the axis) and below a radius high."""
    if not isinstance(value, list) or not 1 <= len(value) <= MAX_BUMPS:
        raise SceneError(f"ground.bumps must be a list of 1 to {MAX_BUMPS} [x, y, height]")
    out = []
    for j, item in enumerate(value):
        if not isinstance(item, list) or len(item) != 3:
            raise SceneError(f"ground.bumps[{j}] must be [x, y, height]")
        x, y, h = (_number(f"ground.bumps[{j}]", v) for v in item)
        if not math.hypot(x, y) < radius:
            raise SceneError(
                f"ground.bumps[{j}] lies {math.hypot(x, y):g} from the axis: a bump must lie "
                f"under the disk, less than body.radius ({radius:g})"
            )
        _check_bump_height(f"ground.bumps[{j}] height", h, radius)
        out.append((x, y, h))
    _check_distinct_bumps(out, radius)
    return tuple(out)


def _check_distinct_bumps(bumps, radius: float) -> None:
    """No two bumps closer than MIN_BUMP_SPACING × body.radius in the plane: the face
    touches both at one point of its own, so their contact rows coincide (a singular
    complementarity problem: every impact law fails there), and the lower of two
    coincident bumps can never be reached."""
    for j, (xj, yj, _) in enumerate(bumps):
        for k in range(j):
            xk, yk, _ = bumps[k]
            if math.hypot(xj - xk, yj - yk) < MIN_BUMP_SPACING * radius:
                raise SceneError(
                    f"ground.bumps[{j}] coincides with ground.bumps[{k}] (closer than "
                    f"{MIN_BUMP_SPACING:g} x body.radius in the plane): each bump must "
                    "stand at its own place under the face"
                )


def _check_bump_height(name: str, h: float, radius: float) -> None:
    """A bump is an imperfection of the floor: 0 ≤ height < the body's radius."""
    if not 0.0 <= h < radius:
        raise SceneError(f"{name} must be in [0, body.radius) = [0, {radius:g}), got {h:g}")


def _parse_initial(ini: dict) -> InitialState:
    keys = set(ini)
    if keys & _INITIAL_LINEAR and keys & _INITIAL_FULL:
        raise SceneError("[initial] gives either q/p (linear) or position/... (full), not both")
    if keys & _INITIAL_LINEAR:
        _check_keys("[initial]", ini, _INITIAL_LINEAR)
        if "q" not in ini or "p" not in ini:
            raise SceneError("[initial] in linear coordinates needs both q and p")
        q = _vector("initial.q", ini["q"])
        p = _vector("initial.p", ini["p"])
        eps = _number("initial.scale", ini.get("scale", 1.0))
        return scaled_initial(q, p, eps, "initial.scale")
    _check_keys("[initial]", ini, _INITIAL_FULL)
    missing = _INITIAL_FULL - keys
    if missing:
        raise SceneError(f"[initial] is missing {', '.join(sorted(missing))}")
    return InitialState(
        position=_vector("initial.position", ini["position"]),
        rotation_vector=_vector("initial.rotation_vector", ini["rotation_vector"]),
        velocity=_vector("initial.velocity", ini["velocity"]),
        angular_velocity=_vector("initial.angular_velocity", ini["angular_velocity"]),
    )


def _parse_run(r: dict) -> RunSettings:
    _check_keys("[run]", r, _RUN_KEYS)
    mi = r.get("max_impacts", 100_000)
    _check_max_impacts(mi)
    return RunSettings(
        t_end=_in_range("run.t_end", r.get("t_end", 5.0), DIMENSION_RANGE), max_impacts=mi
    )


# --------------------------------------------------------------------------- checks


def check_scene(scene: Scene) -> None:
    """The one check of a scene, however it was built (a file, `scene_from_dict`,
    `dataclasses.replace`, the constructors): every field's type and range
    (`check_fields`, the ranges of the module docstring), then the checks that involve
    several fields: the initial state within what the method resolves (position,
    attitude, the speed group) and not below the ground."""
    check_fields(scene)
    check_initial_state(scene)
    check_not_below_ground(scene)


def check_fields(scene: Any) -> None:
    """SceneError unless `scene` is a Scene whose every field has the type and range a
    scene file's key must have (the same rules and messages as the file's keys)."""
    if not isinstance(scene, Scene):
        raise SceneError(f"a Scene is needed (reference.scene), got {type(scene).__name__}")
    _text("name", scene.name)
    _text("description", scene.description)
    _check_gravity(_number("gravity", scene.gravity))
    _check_restitution(_number("restitution", scene.restitution))
    _check_body(scene.body)
    _check_ground(scene.ground, scene.body)
    _check_initial_fields(scene.initial)
    if not isinstance(scene.run, RunSettings):
        raise SceneError(f"run must be a RunSettings, got {type(scene.run).__name__}")
    check_t_end(scene.run.t_end)
    _check_max_impacts(scene.run.max_impacts)
    check_impact_law(scene.impact_law)
    if scene.simultaneity_window is not None:
        check_window_bound(scene, check_window(scene.simultaneity_window))


def _check_gravity(g: float) -> None:
    """g = 0 (no gravity) or in DIMENSION_RANGE: a negative g would pull the body up
    through the plane it stands on."""
    if g != 0.0:
        _check_in_range("gravity", g, DIMENSION_RANGE, zero_ok=True)


def _check_restitution(gamma: float) -> None:
    """0 ≤ γ ≤ 1: γ > 1 would create energy at every impact."""
    if not 0.0 <= gamma <= 1.0:
        raise SceneError(f"restitution must be in [0, 1], got {gamma}")


def _check_vertices(n: Any) -> None:
    if isinstance(n, bool) or not isinstance(n, int):
        raise SceneError(f"body.n must be an integer, got {n!r}")
    if not 2 <= n <= MAX_VERTICES:
        raise SceneError(f"body.n must be in [2, {MAX_VERTICES}] (2 is the rod), got {n}")


def _check_body(body: Any) -> None:
    if not isinstance(body, Body):
        raise SceneError(f"body must be a Body, got {type(body).__name__}")
    _check_vertices(body.n)
    _in_range("body.radius", body.radius, DIMENSION_RANGE)
    _in_range("body.mass", body.mass, DIMENSION_RANGE)
    _in_range("body.gyration", body.gyration, GYRATION_RANGE)


def _check_ground(ground: Any, body: Body) -> None:
    """The [ground] keys' rules (`_parse_ground`) on a Ground value."""
    if not isinstance(ground, Ground):
        raise SceneError(f"ground must be a Ground, got {type(ground).__name__}")
    kind = ground.kind
    if kind not in GROUND_KINDS:
        raise SceneError(f"ground.kind must be 'flat', 'three_point' or 'bumpy', got {kind!r}")
    a = body.radius
    if kind != "bumpy" and (ground.bump_height != 0.0 or ground.bumps is not None):
        raise SceneError("ground.bump_height and ground.bumps belong to kind = 'bumpy'")
    if kind != "three_point" and ground.floor_depth is not None:
        raise SceneError("ground.floor_depth belongs to kind = 'three_point'")
    if ground.bumps is not None:
        _parse_bumps(
            [list(b) if isinstance(b, (list, tuple)) else b for b in _seq(ground.bumps)], a
        )
        return
    _check_bump_radius(_number("ground.bump_radius", ground.bump_radius), kind, a)
    _check_bump_height("ground.bump_height", _number("ground.bump_height", ground.bump_height), a)
    if ground.floor_depth is not None:
        _floor_depth(ground.floor_depth, a)


def _seq(value: Any) -> list:
    if not isinstance(value, (list, tuple)):
        raise SceneError(f"ground.bumps must be a list of 1 to {MAX_BUMPS} [x, y, height]")
    return list(value)


def _check_bump_radius(bump: float, kind: str, radius: float) -> None:
    """b / a in [MIN_BUMP_RADIUS, 1) for the grounds with bumps; > 0 (unused) on flat."""
    if kind != "flat" and not MIN_BUMP_RADIUS <= bump / radius < 1.0:
        raise SceneError(
            f"ground.bump_radius must be in [{MIN_BUMP_RADIUS:g}, 1) x body.radius "
            f"({radius:g}), got {bump:g}"
        )
    if kind == "flat" and not bump > 0:
        raise SceneError(f"ground.bump_radius must be > 0, got {bump!r}")


def _check_initial_fields(ini: Any) -> None:
    if not isinstance(ini, InitialState):
        raise SceneError(f"initial must be an InitialState, got {type(ini).__name__}")
    for name in ("position", "rotation_vector", "velocity", "angular_velocity", "q", "p"):
        value = getattr(ini, name)
        if value is not None or name not in ("q", "p"):
            _vector(f"initial.{name}", list(value) if isinstance(value, tuple) else value)


def check_window_bound(scene: Scene, window: float) -> float:
    """A simultaneity window of at most MAX_WINDOW_TIME_UNITS time units a/V
    (V = window_speed_unit: √(a/g) with gravity, t_end without).  A contact reached at
    speed |u| merges the zeros within T |u|/V; with T ≤ a/V that is at most |u| a/V² =
    |u|/g, the time of its own bounce.  A wider window merges zeros of later bounces
    into one impact, which is no longer simultaneity, and the law's sequential work
    grows without bound (measured on triangle-chatter under `sequential`: 3e9 ends in
    0.3 s, 1e10 does not end)."""
    limit = MAX_WINDOW_TIME_UNITS * time_unit(scene)
    if window > limit:
        raise SceneError(
            f"simultaneity_window must be at most the motion's time unit a/V = {limit:.3g} "
            f"(V = sqrt(g a), or a/t_end without gravity), got {window:g}: a wider window "
            "merges a contact's later bounces into one impact"
        )
    return window


def reference_window(scene: Scene, law: str | None = None) -> float:
    """The exact reference's simultaneity window T for the scene under `law` (None: the
    scene's): its own, else default_window(law) (zeros within T |u|/V of a contact
    reached at speed |u| are reached together, V = window_speed_unit)."""
    w = scene.simultaneity_window
    return default_window(law or scene.impact_law) if w is None else w


def default_window(law: str) -> float:
    """The reference's default window under `law`: 0 under `paper` (the paper's rule
    and its results as they are: a window there ends more runs `simultaneous_impact`,
    measured in docs/laws.md), DEFAULT_SIMULTANEITY_WINDOW under the laws that
    resolve a simultaneous impact."""
    return 0.0 if law_code(law) == LAW_PAPER else DEFAULT_SIMULTANEITY_WINDOW


def window_speed_unit(scene: Scene) -> float:
    """V = √(g a), the speed whose contacts the simultaneity window T is stated for: a
    contact reached at normal speed |u| takes those whose zeros lie within T |u|/V
    (T |u|/V = (T √(g/a)) · |u|/g, a fixed fraction of the time |u|/g of its own bounce:
    the window scales with the motion, so a cascade's late impacts, whose intervals
    shrink with the speeds, are never merged).  Without gravity: velocity_unit."""
    g, a = scene.gravity, scene.body.radius
    return math.sqrt(g * a) if g > 0 else velocity_unit(scene)


def time_unit(scene: Scene) -> float:
    """a/V (V = window_speed_unit): √(a/g), or t_end without gravity; the time of a
    bounce at the speed unit, the scale on which the window and a run's progress are
    judged."""
    return scene.body.radius / window_speed_unit(scene)


def velocity_unit(scene: Scene) -> float:
    """U = a/τ = max(√(g a), a/t_end): the speed unit of the speed group."""
    a = scene.body.radius
    return max(math.sqrt(scene.gravity * a), a / scene.run.t_end)


def check_initial_state(scene: Scene) -> None:
    """Reject initial states that double precision or the reference cannot resolve
    (module docstring): |x_i| ≤ MAX_POSITION a, |φ| ≤ MAX_ROTATION_VECTOR, and the
    speed group (|v| + |ω| a) / U ≤ MAX_SPEED."""
    ini = scene.initial
    a = scene.body.radius
    for name, vec in (
        ("position", ini.position),
        ("rotation_vector", ini.rotation_vector),
        ("velocity", ini.velocity),
        ("angular_velocity", ini.angular_velocity),
    ):
        if not all(math.isfinite(x) for x in vec):
            raise SceneError(f"initial {name} must be finite, got {list(vec)}")
    far = max(abs(x) for x in ini.position) / a
    if far > MAX_POSITION:
        raise SceneError(
            f"initial position is {far:.3g} body radii from the origin; at most "
            f"{MAX_POSITION:g} (contact gaps would lose the body's own size to roundoff)"
        )
    angle = math.hypot(*ini.rotation_vector)
    if angle > MAX_ROTATION_VECTOR:
        raise SceneError(
            f"initial rotation vector has angle {angle:.3g} rad; at most "
            f"{MAX_ROTATION_VECTOR:g} (give the same attitude with an angle below 2 pi)"
        )
    speed = math.hypot(*ini.velocity) + math.hypot(*ini.angular_velocity) * a
    group = speed / velocity_unit(scene)
    if group > MAX_SPEED:
        raise SceneError(
            f"initial speed (|v| + |omega| a = {speed:.3g}) is {group:.3g} times the "
            f"velocity unit max(sqrt(g a), a / t_end) = {velocity_unit(scene):.3g}; at most "
            f"{MAX_SPEED:g} (v^2/(g a) and omega^2 a/g <= {MAX_SPEED**2:g}), beyond which "
            "the reference cannot resolve the motion"
        )


def check_not_below_ground(scene: Scene) -> None:
    """Reject a body that starts with a contact point below the ground."""
    y0 = initial_state(scene.initial)
    gaps = scene_contact_kinematics(scene, y0)[0][0]
    worst = int(np.argmin(gaps))
    if gaps[worst] < -1e-12 * scene.body.radius:
        raise SceneError(
            f"the body starts below the ground: contact {worst} is at gap {gaps[worst]:.3g}"
        )
    if len(scene.contacts.floor_points) and body_axis(y0[QUATERNION])[2] <= 0.0:
        raise SceneError(f"{scene.ground.kind} ground needs the body's face normal pointing up")
    depth = scene.ground.floor_below(scene.body)
    e3 = body_axis(y0[QUATERNION])
    rim = y0[2] + depth - scene.body.radius * math.hypot(e3[0], e3[1])
    if rim < -1e-12 * scene.body.radius:
        raise SceneError(
            f"the body starts below the floor plane z = {-depth:g} (ground.floor_depth under "
            f"the bumps): its rim is {-rim:.3g} below it"
        )


# What a missing required table must give (a message says what to write, docs/contract.md).
_TABLE_KEYS = {
    "body": "n (vertices, >= 2) and optionally radius, mass, gyration",
    "initial": "either q and p (linear coordinates, 3 numbers each) or position, "
    "rotation_vector, velocity and angular_velocity (3 numbers each)",
}


def _table(name: str, data: dict) -> dict:
    if name not in data:
        raise SceneError(f"scene has no [{name}] table; give {_TABLE_KEYS[name]}")
    return _optional_table(name, data)


def _optional_table(name: str, data: dict) -> dict:
    t = data.get(name, {})
    if not isinstance(t, dict):
        raise SceneError(f"[{name}] must be a table")
    return t


def _check_keys(where: str, data: dict, allowed: set[str]) -> None:
    unknown = set(data) - allowed
    if unknown:
        shown = ", ".join(sorted(show_path(k, 40) for k in unknown)[:5])
        raise SceneError(f"{where}: unknown key(s) {shown}; allowed: {', '.join(sorted(allowed))}")


def _text(name: str, value: Any) -> str:
    if not isinstance(value, str):
        raise SceneError(f"{name} must be a string, got {type(value).__name__}")
    if len(value) > MAX_NAME_LENGTH or any(c in value for c in "\n\r\x00"):
        raise SceneError(f"{name} must be one line of at most {MAX_NAME_LENGTH} characters")
    return value


def _number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(f"{name} must be a number, got {show_path(repr(value), 40)}")
    try:
        x = float(value)
    except OverflowError:  # an integer beyond double precision's range
        raise SceneError(f"{name} must be finite, got {show_path(repr(value), 40)}") from None
    if not math.isfinite(x):
        raise SceneError(f"{name} must be finite, got {value!r}")
    return x


def _in_range(name: str, value: Any, bounds: tuple[float, float]) -> float:
    x = _number(name, value)
    _check_in_range(name, x, bounds)
    return x


def _check_in_range(name: str, x: Any, bounds: tuple[float, float], zero_ok=False) -> None:
    lo, hi = bounds
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not lo <= x <= hi:
        zero = "0 or " if zero_ok else ""
        raise SceneError(f"{name} must be {zero}in [{lo:g}, {hi:g}], got {x!r}")


def check_t_end(x: Any) -> None:
    """A run's end time: a number in DIMENSION_RANGE (NaN, 0, negative, inf refused)."""
    _check_in_range("t_end", x, DIMENSION_RANGE)


def _check_max_impacts(mi: Any) -> None:
    if isinstance(mi, bool) or not isinstance(mi, int) or not 0 <= mi <= MAX_IMPACTS:
        raise SceneError(
            f"run.max_impacts must be an integer in [0, {MAX_IMPACTS}], "
            f"got {show_path(repr(mi), 40)}"
        )


def _vector(name: str, value: Any) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise SceneError(f"{name} must be a list of 3 numbers, got {show_path(repr(value), 60)}")
    return tuple(_number(f"{name}[{i}]", v) for i, v in enumerate(value))
