"""Scenes: the problem statement, validated into immutable data.

A scene is a regular n-gon (or a disk on three ground bumps), its ground, its initial
state and how long to run.  The TOML layout is fixed by CONTRACT.md; this module turns
a parsed mapping into a frozen :class:`Scene` and rejects bad input with
:class:`SceneError` (one clear sentence, never a traceback at the CLI).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .geometry import initial_state, scene_contact_kinematics
from .quaternion import body_axis


class SceneError(ValueError):
    """A scene that cannot be simulated: the message says which field and why."""


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
    """`flat`: the plane z = 0.  `three_point`: bumps at (b cos 2πk/3, b sin 2πk/3, 0)."""

    kind: str = "flat"
    bump_radius: float = 0.5


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

    @property
    def n_contacts(self) -> int:
        return 3 if self.ground.kind == "three_point" else self.body.n

    def with_run(self, **changes: Any) -> Scene:
        return replace(self, run=replace(self.run, **changes))

    def scaled(self, eps: float) -> Scene:
        """Apply the paper's scaling invariance to the linear initial coordinates:
        q → ε² q, p → ε p (section 2.5).  Only defined for scenes given by (q, p)."""
        if self.initial.q is None or self.initial.p is None:
            raise SceneError("--scale needs a scene whose [initial] is given by q and p")
        _check_positive("scale", eps)
        q = tuple(eps * eps * x for x in self.initial.q)
        p = tuple(eps * x for x in self.initial.p)
        return replace(self, initial=initial_from_linear(q, p))


def initial_from_linear(q, p) -> InitialState:
    """Map linear coordinates to a full state (CONTRACT.md): attitude = rotation vector
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

_TOP_KEYS = {"name", "description", "gravity", "restitution", "body", "ground", "initial", "run"}
_BODY_KEYS = {"n", "radius", "mass", "gyration"}
_GROUND_KEYS = {"kind", "bump_radius"}
_INITIAL_LINEAR = {"q", "p", "scale"}
_INITIAL_FULL = {"position", "rotation_vector", "velocity", "angular_velocity"}
_RUN_KEYS = {"t_end", "max_impacts"}


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"scene file not found: {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: malformed TOML: {exc}") from None
    return scene_from_dict(data, default_name=path.stem)


def scene_from_dict(data: dict[str, Any], default_name: str = "scene") -> Scene:
    _check_keys("scene", data, _TOP_KEYS)
    name = str(data.get("name", default_name))
    gravity = _number("gravity", data.get("gravity", 1.0))
    if gravity < 0:
        raise SceneError(f"gravity must be >= 0, got {gravity}")
    gamma = _number("restitution", data.get("restitution", 0.5))
    if not 0.0 <= gamma <= 1.0:
        raise SceneError(f"restitution must be in [0, 1], got {gamma}")

    b = _table("body", data)
    _check_keys("[body]", b, _BODY_KEYS)
    if "n" not in b:
        raise SceneError("[body] needs n (number of vertices, >= 2)")
    n = b["n"]
    if isinstance(n, bool) or not isinstance(n, int):
        raise SceneError(f"body.n must be an integer, got {n!r}")
    if n < 2:
        raise SceneError(f"body.n must be >= 2 (2 is the rod), got {n}")
    body = Body(
        n=n,
        radius=_positive("body.radius", b.get("radius", 1.0)),
        mass=_positive("body.mass", b.get("mass", 1.0)),
        gyration=_positive("body.gyration", b.get("gyration", 0.5)),
    )

    gr = data.get("ground", {})
    if not isinstance(gr, dict):
        raise SceneError("[ground] must be a table")
    _check_keys("[ground]", gr, _GROUND_KEYS)
    kind = gr.get("kind", "flat")
    if kind not in ("flat", "three_point"):
        raise SceneError(f"ground.kind must be 'flat' or 'three_point', got {kind!r}")
    bump = _positive("ground.bump_radius", gr.get("bump_radius", 0.5 * body.radius))
    if kind == "three_point" and bump >= body.radius:
        raise SceneError(
            f"ground.bump_radius ({bump}) must be smaller than body.radius ({body.radius})"
        )
    ground = Ground(kind=kind, bump_radius=bump)

    ini = _table("initial", data)
    keys = set(ini)
    if keys & _INITIAL_LINEAR and keys & _INITIAL_FULL:
        raise SceneError("[initial] gives either q/p (linear) or position/... (full), not both")
    if keys & _INITIAL_LINEAR:
        _check_keys("[initial]", ini, _INITIAL_LINEAR)
        if "q" not in ini or "p" not in ini:
            raise SceneError("[initial] in linear coordinates needs both q and p")
        q = _vector("initial.q", ini["q"])
        p = _vector("initial.p", ini["p"])
        s = _positive("initial.scale", ini.get("scale", 1.0))
        initial = initial_from_linear([s * s * x for x in q], [s * x for x in p])
    else:
        _check_keys("[initial]", ini, _INITIAL_FULL)
        missing = _INITIAL_FULL - keys
        if missing:
            raise SceneError(f"[initial] is missing {', '.join(sorted(missing))}")
        initial = InitialState(
            position=_vector("initial.position", ini["position"]),
            rotation_vector=_vector("initial.rotation_vector", ini["rotation_vector"]),
            velocity=_vector("initial.velocity", ini["velocity"]),
            angular_velocity=_vector("initial.angular_velocity", ini["angular_velocity"]),
        )

    r = data.get("run", {})
    if not isinstance(r, dict):
        raise SceneError("[run] must be a table")
    _check_keys("[run]", r, _RUN_KEYS)
    mi = r.get("max_impacts", 100_000)
    if isinstance(mi, bool) or not isinstance(mi, int) or mi < 0:
        raise SceneError(f"run.max_impacts must be a non-negative integer, got {mi!r}")
    run = RunSettings(t_end=_positive("run.t_end", r.get("t_end", 5.0)), max_impacts=mi)

    scene = Scene(
        name=name,
        description=str(data.get("description", "")),
        gravity=gravity,
        restitution=gamma,
        body=body,
        ground=ground,
        initial=initial,
        run=run,
    )
    check_not_below_ground(scene)
    return scene


def check_not_below_ground(scene: Scene) -> None:
    """Reject a body that starts with a contact point below the ground."""
    y0 = initial_state(scene.initial)
    gaps = scene_contact_kinematics(scene, y0)[0][0]
    worst = int(np.argmin(gaps))
    if gaps[worst] < -1e-12 * scene.body.radius:
        raise SceneError(
            f"the body starts below the ground: contact {worst} is at gap {gaps[worst]:.3g}"
        )
    if scene.ground.kind == "three_point" and body_axis(y0[3:7])[2] <= 0.0:
        raise SceneError("three_point ground needs the body's face normal pointing up")


def _table(name: str, data: dict) -> dict:
    if name not in data:
        raise SceneError(f"scene has no [{name}] table")
    t = data[name]
    if not isinstance(t, dict):
        raise SceneError(f"[{name}] must be a table")
    return t


def _check_keys(where: str, data: dict, allowed: set[str]) -> None:
    unknown = set(data) - allowed
    if unknown:
        raise SceneError(
            f"{where}: unknown key(s) {', '.join(sorted(unknown))}; "
            f"allowed: {', '.join(sorted(allowed))}"
        )


def _number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(f"{name} must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise SceneError(f"{name} must be finite, got {value!r}")
    return x


def _positive(name: str, value: Any) -> float:
    x = _number(name, value)
    _check_positive(name, x)
    return x


def _check_positive(name: str, x: float) -> None:
    if not (math.isfinite(x) and x > 0):
        raise SceneError(f"{name} must be > 0, got {x!r}")


def _vector(name: str, value: Any) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise SceneError(f"{name} must be a list of 3 numbers, got {value!r}")
    return tuple(_number(f"{name}[{i}]", v) for i, v in enumerate(value))
