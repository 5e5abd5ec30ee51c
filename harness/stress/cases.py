"""The hard-case catalogue of `harness stress`: Scenes built in code."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from reference.scene import (
    Body,
    Ground,
    InitialState,
    RunSettings,
    Scene,
    SceneError,
    initial_from_linear,
)

from ..scenes import resolve_scene


@dataclass(frozen=True)
class StressCase:
    name: str
    description: str
    scene: Scene


# ----------------------------------------------------------------------------- cases

# One pentagon (γ = 0.5) in linear coordinates; |φ| = 0.01166 at scale 1, and its
# reference run ends (undecidable) at t ≈ 0.84 ε.
_ALPHA_Q = (0.01, -0.006, 0.05)
_ALPHA_P = (0.05, 0.02, -0.1)
ALPHAS = (1e-3, 1e-6, 1e-9, 1e-12)
# elastic-hexagon scaled by ε: its linear model reaches 100,000 impacts at
# t = 13037.9 ε (measured: `simulate_linear` of elastic-hexagon, max_impacts 1e5).
LONG_ELASTIC_EPS = 0.02
LONG_ELASTIC_IMPACTS = 100_000
LONG_ELASTIC_T_PER_EPS = 13040.0


def _polygon(
    name: str, n: int, gamma: float, initial: InitialState, t_end: float, rho: float = 0.5
) -> Scene:
    return Scene(
        name=name,
        body=Body(n=n, gyration=rho),
        ground=Ground(),
        initial=initial,
        restitution=gamma,
        gravity=1.0,
        run=RunSettings(t_end=t_end, max_impacts=100_000),
    )


def alpha_scene(alpha: float) -> Scene:
    """The pentagon scaled so that its initial inclination is α: ε = √(α / |φ0|),
    t_end = ε (the motion's time scale is ε)."""
    base = _polygon("stress-alpha", 5, 0.5, initial_from_linear(_ALPHA_Q, _ALPHA_P), 1.0)
    eps = math.sqrt(alpha / math.hypot(_ALPHA_Q[0], _ALPHA_Q[1]))
    s = base.scaled(eps).with_run(t_end=eps)
    return _renamed(s, f"stress-alpha-{alpha:.0e}".replace("e-0", "e-"))


def fast_spin_scene(n: int = 16, alpha: float = 1e-3, spin: float = 100.0) -> Scene:
    """A 16-gon tilted by α = 1e-3 (rotation about x), its lowest vertex 1e-4 above the
    ground, spinning at 100 rad/s about the vertical: each vertex passes the low point
    every 2π/(n·spin) ≈ 4 ms, the inclination is 1e-3."""
    a = 1.0
    initial = InitialState(
        position=(0.0, 0.0, a * math.sin(alpha) + 1e-4),
        rotation_vector=(alpha, 0.0, 0.0),
        velocity=(0.0, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, spin),
    )
    return _polygon("stress-fast-spin", n, 0.5, initial, 0.3)


def _renamed(scene: Scene, name: str) -> Scene:
    return replace(scene, name=name)


def stress_cases() -> list[StressCase]:
    """The hard cases, in order (names are what `--case` selects)."""
    cases = [
        StressCase(
            f"alpha-{a:.0e}".replace("e-0", "e-"),
            f"pentagon gamma=0.5 scaled to inclination {a:g} (t_end = time scale)",
            alpha_scene(a),
        )
        for a in ALPHAS
    ]
    grazing = resolve_scene("grazing-contact")
    near = resolve_scene("near-simultaneous")
    chatter = resolve_scene("triangle-chatter").with_run(t_end=1.0)
    elastic_unit = resolve_scene("elastic-hexagon")
    elastic = elastic_unit.scaled(LONG_ELASTIC_EPS)
    elastic = _renamed(elastic, "stress-long-elastic").with_run(
        t_end=LONG_ELASTIC_T_PER_EPS * LONG_ELASTIC_EPS, max_impacts=LONG_ELASTIC_IMPACTS
    )
    pentagon = resolve_scene("pentagon-bounce")
    n1000 = replace(pentagon, name="stress-n1000", body=replace(pentagon.body, n=1000))
    n1000 = n1000.with_run(t_end=1.0)
    rolling = resolve_scene("polygon25-rolling").with_run(t_end=1.0)
    three = resolve_scene("three-point-disk").with_run(t_end=1.0)
    bumpy = resolve_scene("bumpy-rolling")
    cases += [
        StressCase("grazing", grazing.description, grazing),
        StressCase("near-simultaneous", near.description, near),
        StressCase("chatter", chatter.description + " (t_end 1)", chatter),
        StressCase(
            "elastic",
            elastic_unit.description + " (t_end 20, unit scale)",
            _renamed(elastic_unit, "stress-elastic"),
        ),
        StressCase(
            "long-elastic",
            f"hexagon gamma=1 scaled by {LONG_ELASTIC_EPS:g}: "
            f"{LONG_ELASTIC_IMPACTS:,} impacts for the reference, engines the same time",
            elastic,
        ),
        StressCase(
            "fast-spin",
            "16-gon at inclination 1e-3 spinning at 100 rad/s about the vertical",
            fast_spin_scene(),
        ),
        StressCase("n1000", "pentagon-bounce's state with n = 1000 (t_end 1)", n1000),
        StressCase("rolling-gamma0", rolling.description + " (t_end 1)", rolling),
        StressCase("three-point", three.description + " (t_end 1)", three),
        StressCase("bumpy", bumpy.description, bumpy),
    ]
    return cases


def select_cases(names: Sequence[str] | None) -> list[StressCase]:
    """Cases by exact name or name prefix (`alpha` selects every alpha case)."""
    cases = stress_cases()
    if not names:
        return cases
    out: list[StressCase] = []
    for name in names:
        hit = [c for c in cases if c.name == name] or [c for c in cases if c.name.startswith(name)]
        if not hit:
            raise SceneError(
                f"unknown stress case {name!r}; choose from {', '.join(c.name for c in cases)}"
            )
        out += [c for c in hit if c not in out]
    return out
