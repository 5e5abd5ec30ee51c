"""The full reference agrees with the linearised model as α → 0.

Derivation of the expected order (details in reference/linear/alpha.py).  Scale the
linear initial state by ε: φ = O(ε²) (so α = O(ε²)), ω, v = O(ε), and times are O(ε).
The linearisation drops:
- the second-order part of a vertex height, ½ (φ_z (φ·r) − |φ|² r_z): zero, because the
  body is thin (r_z = 0) and the rotation vector starts with φ_z = 0; the third-order
  part is O(|φ|³), i.e. O(ε⁴) relative to the O(φ) gap;
- the O(φ) off-diagonal (xz, yz) entries of the world inertia and, on three_point
  ground, the O(φ) tilt of the contact normal: both only excite yaw, ω_z = O(ε³), which
  reaches the gaps and (ωx, ωy) only through products such as φ_z (ω·r) and ω_z ω,
  O(ε⁴) relative;
- the gyroscopic term (I3 − I1)(e3·ω)(ω × e3) with e3·ω = O(ε³), the centripetal term
  (ω × (ω × Rr))_z and the O(φ ω) terms of φ̇ = ω + ½ φ × ω: O(ε⁴) relative.
The O(α) = O(ε²) terms all vanish by this symmetry, so scaled impact times, impulses,
normal velocities and states must agree with relative error ∝ ε⁴ = α² (order 4 in ε),
until the roundoff floor.

The test runs ε over four decades (1 … 1e-4; 0.3 … 3e-5 for three_point, whose ε = 1
state is too tilted for the same eight impacts), asserts the same contact sequence
throughout, that the smallest ε reach the roundoff floor (< 1e-13), and fits the order
over the points above 30 × that floor: with order 4 the error falls from ~1e-4..1e-6 to
the floor within 2-2.5 decades of ε, and the fit must give 4 ± 0.15 there.
Scenes: flat ground (pentagon, γ = 0.8) and three_point ground (γ = 0.5); eight impacts
each (the motion is chaotic: later impacts amplify every difference, roundoff
included, by ~1.3 per impact).
"""

import pytest

from harness.scenes import resolve_scene
from reference.linear.alpha import fit_order, scaled_agreement

simulate = pytest.importorskip("reference.simulate").simulate

DECADES_4 = [1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4]


@pytest.mark.parametrize(
    "scene_name, eps_list",
    [("pentagon-bounce", DECADES_4), ("three-point-disk", [e * 0.3 for e in DECADES_4])],
)
def test_reference_converges_to_the_linear_model_as_alpha_squared(scene_name, eps_list):
    scene = resolve_scene(scene_name)
    rows = [scaled_agreement(scene, eps, 8, simulate) for eps in eps_list]
    assert all(r["same_sequence"] for r in rows), [r["n_compared"] for r in rows]
    for key in ("time_error", "impulse_error", "velocity_error", "state_error"):
        err = [r[key] for r in rows]
        floor = min(err)
        assert floor < 1e-13, (key, err)  # the smallest ε reach roundoff
        fit = fit_order(eps_list, err, floor=30 * floor)
        assert fit["decades"] >= 1.9 and fit["n"] >= 5, (key, fit, err)
        assert fit["order"] == pytest.approx(4.0, abs=0.15), (key, fit, err)
