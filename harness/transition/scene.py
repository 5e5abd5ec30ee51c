"""The transition study's scene, in the paper's units (Baranyai & Várkonyi, conclusion):
a disk of diameter d = 0.1 m under g = 9.81 m/s², a floor uneven by Δ = 1e-4 … 1e-5 m,
modelled as a large regular n-gon (ρ = 0.5) rolling on its rim over the bumpy ground
(reference.bumpy: three bumps of height Δ at half the radius, b = a/2).

The rolling start is the built-in `polygon25-rolling` state scaled by the paper's
invariance (section 2.6): tilt α about the y axis, the lowest vertex on the floor
(centre at height a α in the linear coordinates), and the tilt direction turning at
ω_x = ROLLING_RATE √(α g/a) (0.3 √(g/a) at α = 0.05, the rate at which the 25-gon rolls
from vertex to vertex in sustained contact).  The tilt must lie well above the takeover
tilt Δ/a so that the run starts on the rim alone.
"""

from __future__ import annotations

import math

from reference.scene import Body, Ground, InitialState, RunSettings, Scene, initial_from_linear

PAPER_DIAMETER = 0.1  # d [m]
PAPER_GRAVITY = 9.81  # g [m/s²]
PAPER_DELTAS = (1e-4, 1e-5)  # the floor's unevenness Δ [m], the paper's range
# Mass of the disk [kg]: it scales every energy and impulse and nothing else.
PAPER_MASS = 0.1
ROLLING_RATE = 0.3 / math.sqrt(0.05)  # ω_x / √(α g/a) of polygon25-rolling
BUMP_RADIUS = 0.5  # b/a, the default bumps' distance from the axis
# γ = 0.5: the reference follows it to the end in seconds (1,730 rim and 228 bump impacts
# at Δ = 1e-4 m).  At γ = 0 it crawls once the disk lies nearly flat on one bump with the
# other two 1e-9 … 1e-11 away (t ≈ 0.2969 s: 1e-17 s per 20,000 loop steps; reported).
DEFAULT_RESTITUTION = 0.5


def rolling_start(tilt: float, radius: float, gravity: float) -> InitialState:
    """The rim-rolling start at tilt α (module docstring)."""
    rate = ROLLING_RATE * math.sqrt(tilt * gravity / radius)
    return initial_from_linear([0.0, tilt, radius * tilt], [rate, 0.0, 0.0])


def transition_scene(
    delta: float = PAPER_DELTAS[0],
    tilt: float = 0.02,
    n: int = 100,
    restitution: float = DEFAULT_RESTITUTION,
    gyration: float = 0.5,
    diameter: float = PAPER_DIAMETER,
    gravity: float = PAPER_GRAVITY,
    t_end: float = 10.0,
    max_impacts: int = 1_000_000,
    name: str = "bumpy-transition",
) -> Scene:
    """The n-gon rolling at `tilt` over three bumps of height `delta` [m] at half its
    radius, in the paper's units."""
    a = 0.5 * diameter
    return Scene(
        name=name,
        body=Body(n=n, radius=a, mass=PAPER_MASS, gyration=gyration),
        ground=Ground(kind="bumpy", bump_radius=BUMP_RADIUS * a, bump_height=delta),
        initial=rolling_start(tilt, a, gravity),
        restitution=restitution,
        gravity=gravity,
        description=(
            f"{n}-gon rolling at tilt {tilt:g} rad over 3 bumps of {delta:g} m "
            f"(d = {diameter:g} m, g = {gravity:g})"
        ),
        run=RunSettings(t_end=t_end, max_impacts=max_impacts),
    )
