"""The product (the compiled core) against the oracle (tests/oracle: the pure-Python
specification it was written from), impact by impact, on every built-in scene and on
generated ones: flights, impacts beside held contacts, chatter completion, contact
phases with lift-offs, both grounds.

Chaotic runs separate after enough impacts (roundoff grows ~1.2–1.5× per impact), so
each case compares the leading impacts it is known to keep: same contact, times within
1e-9 (most agree to 1e-12) plus, for an impact that ends a contact phase, the phase's
time resolution: such an impact is detected once its gap is within
gap_res = 16 rtol L of zero (reference.core.tolerances.CONTACT_GAP_RES), i.e. to
gap_res/|u⁻| in time, and the two implementations chunk the phase differently.
Impulses agree within 1e-9 of the largest, plus what the time resolution allows: a
time shift δt changes the approach speed by |a_n| δt and the impulse by
(1 + γ) m_eff |a_n| δt (|a_n| ≤ 2g near the end of the motion).  Where a run is compared
in full, the status and the final time must agree too."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.scenes import resolve_scene
from reference import simulate
from reference.core.tolerances import CONTACT_GAP_RES
from tests.conftest import make_scene
from tests.oracle.simulate import simulate as oracle_simulate

# (built-in scene, t_end override, leading impacts compared; None = the whole run)
BUILTIN_CASES = [
    ("triangle-chatter", None, None),
    ("rod", None, None),
    ("grazing-contact", None, None),
    ("near-simultaneous", None, None),
    ("tiny-alpha", None, 130),
    ("three-point-disk", None, 200),
    ("elastic-hexagon", None, 60),
    ("pentagon-bounce", None, 100),
    ("polygon25-rolling", 0.4, None),
]


def generated_scenes():
    """Scenes not shipped with the package: γ = 0 (contact phases and lift-offs; on the
    three-point ground also to its end), small γ three-point ground, a heptagon to the
    energy floor, a spinning square.  The oracle models the three-point ground's bumps,
    not the floor plane under them (tests/test_reference_floor.py): that floor is put
    infinitely far down (n25 tips through the default one after 3 impacts)."""
    three = {"ground": "three_point", "floor_depth": math.inf}
    yield (
        "n3-g0-three-point",
        make_scene(n=3, gamma=0.0, rho=0.62, q=(0.012, -0.004, 0.05), p=(0.1, -0.2, -0.5), **three),
        120,
    )
    # rocking over the bumps to the singularity; at impacts beside two held contacts
    # the disk passes flat over all three (L = 0) while moving: long chunks there
    yield (
        "n3-g0-three-point-to-the-end",
        make_scene(
            n=3,
            gamma=0.0,
            rho=0.45,
            q=(0.012, -0.007, 0.05),
            p=(0.2, -0.15, -0.5),
            t_end=1e4,
            **three,
        ),
        None,
    )
    yield (
        "n7-g0-flat",
        make_scene(n=7, gamma=0.0, rho=0.35, q=(0.01, 0.015, 0.05), p=(-0.2, 0.1, -0.5)),
        None,
    )
    yield (
        "n5-g0.3-flat",
        make_scene(n=5, gamma=0.3, rho=0.4, q=(0.015, -0.01, 0.05), p=(0.25, 0.05, -0.5)),
        90,
    )
    yield (
        "n25-g0.5-three-point",
        make_scene(n=25, gamma=0.5, rho=0.7, q=(-0.01, 0.02, 0.05), p=(0.2, 0.1, -0.5), **three),
        80,  # its last few impacts are a chatter whose completion point is decided at roundoff
    )
    y = np.zeros(13)
    y[3:7] = [np.cos(0.01), np.sin(0.01), 0.0, 0.0]
    y[2] = np.sin(0.02) + 0.01
    y[9:13] = [-0.1, 0.0, 0.3, 20.0]
    yield "n4-spin", make_scene(n=4, gamma=0.5, state=y, t_end=2.0), None
    # elastic bouncing with flights long enough that the circle through the vertices
    # bounds the steps far from the ground (`rim.far_from_ground`)
    yield "n16-spin-elastic", make_scene(n=16, gamma=1.0, rho=0.5, state=y, t_end=3.0), None
    # a large polygon spinning fast: its flights leave the ground and come back by the
    # rim descent (`rim.rim_descent`) and end with the vertex window.  Chaotic: the
    # last-bit differences of the first impacts grow ×3 per impact (measured 3e-13 at
    # impact 18, 1e-11 at 24, 1e-9 at 26; the code before the descent as well, 1e-10
    # at 27), so the first 22 are compared
    yield "n100-spin-elastic", make_scene(n=100, gamma=1.0, rho=0.5, state=y, t_end=6.0), 22


def time_tolerance(impact, radius=1.0, rtol=1e-12):
    """1e-9 relative, plus the contact-phase resolution gap_res/|u⁻| (module doc)."""
    gap_res = CONTACT_GAP_RES * rtol * radius
    return 1e-9 * max(1.0, abs(impact.t)) + 4.0 * gap_res / max(abs(impact.v_normal_pre), 1e-300)


def assert_same_impacts(product, oracle, n_compare, scene):
    n = len(oracle.impacts) if n_compare is None else n_compare
    assert len(product.impacts) >= n and len(oracle.impacts) >= n
    scale = max((abs(e.impulse) for e in oracle.impacts[:n]), default=0.0)
    per_second = (1.0 + scene.restitution) * scene.body.mass * 2.0 * scene.gravity
    for i, (a, b) in enumerate(zip(product.impacts[:n], oracle.impacts[:n], strict=True)):
        assert a.contact == b.contact, f"impact {i}: contact {a.contact} vs {b.contact}"
        dt = (a.t - b.t) + (a.t_lo - b.t_lo)
        tol = time_tolerance(b)
        assert abs(dt) <= tol, f"impact {i}: Δt = {dt:.3g}"
        impulse_tol = 1e-9 * scale + per_second * (tol - 1e-9 * max(1.0, abs(b.t)))
        assert abs(a.impulse - b.impulse) <= impulse_tol, f"impact {i}: impulse"
    if n_compare is None:
        assert len(product.impacts) == len(oracle.impacts)
        assert product.status == oracle.status
        assert abs(product.t_final - oracle.t_final) <= 1e-9 * max(1.0, oracle.t_final)


def up_to(scene, n_compare):
    """The scene run only as far as its compared impacts (None: the whole run): both
    simulators stop at max_impacts = n_compare, the leading impacts unchanged."""
    return scene if n_compare is None else scene.with_run(max_impacts=n_compare)


@pytest.mark.parametrize("name,t_end,n_compare", BUILTIN_CASES)
def test_product_gives_the_oracles_impacts_on_builtin_scenes(name, t_end, n_compare):
    scene = up_to(resolve_scene(name), n_compare)
    product, oracle = simulate(scene, t_end=t_end), oracle_simulate(scene, t_end=t_end)
    assert_same_impacts(product, oracle, n_compare, scene)


@pytest.mark.parametrize(
    "name,scene,n_compare", list(generated_scenes()), ids=lambda x: x if isinstance(x, str) else ""
)
def test_product_gives_the_oracles_impacts_on_generated_scenes(name, scene, n_compare):
    scene = up_to(scene, n_compare)
    assert_same_impacts(simulate(scene), oracle_simulate(scene), n_compare, scene)


@pytest.mark.slow
def test_product_gives_the_oracles_impacts_on_the_whole_rolling_polygon():
    """polygon25-rolling to its end (1,928 impacts in sustained rolling; the oracle takes
    ~9 s)."""
    scene = resolve_scene("polygon25-rolling")
    assert_same_impacts(simulate(scene), oracle_simulate(scene), None, scene)


def random_contact_scene(seed: int):
    """A polygon (n from 3 to 25) dropped with a random tilt and wobble, mostly γ = 0
    (contact phases, landings, lift-offs), flat or three-point ground, for 1 s."""
    rng = np.random.default_rng(seed)
    n = int(rng.choice([3, 4, 5, 6, 8, 12, 25]))
    gamma = float(rng.choice([0.0, 0.0, 0.2, 0.5]))
    ground = str(rng.choice(["flat", "flat", "three_point"]))
    q = (rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02), rng.uniform(0.02, 0.08))
    p = (rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-0.6, 0.0))
    rho = float(rng.uniform(0.3, 0.65))
    return make_scene(n=n, gamma=gamma, rho=rho, q=q, p=p, ground=ground, t_end=1.0)


@pytest.mark.parametrize("seed", range(16))
def test_product_gives_the_oracles_impacts_on_random_contact_scenes(seed):
    """Seeded random drops (`random_contact_scene`): the leading 60 impacts, whatever
    mix of flights, contact phases and their last approaches (one Heun–Euler step when
    far shorter than the integrator's step) each run takes."""
    scene = up_to(random_contact_scene(7_000 + seed), 60)
    product, oracle = simulate(scene), oracle_simulate(scene)
    n = min(len(product.impacts), len(oracle.impacts), 60)
    assert_same_impacts(product, oracle, n, scene)
