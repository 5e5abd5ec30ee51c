"""The energy exponent c under each impact law on the three-point ground:
the sweep's random numbers χ (harness.sweep.grid.chi) in the three-point-disk scene's
scale, q = (0.01 χ3, 0.01 χ4, 0.02), p = (0.05 χ1, 0.05 χ2, −0.05) (the sweep's own
states, dropped from h = 1, bounce off the bumps: `left_model`), a disk on three bumps
(b = 0.5 a by default, `--bump-radius`), run by the exact reference to the singularity
under `paper`, `moreau` and `sequential`; per γ the fraction of runs that reach the
singularity, how many of them have a c, and c's mean ± standard deviation.
(`harness sweep exponent` covers the flat n-gon; its scenes have no ground option.)

On three bumps at radius b the disk is the paper's triangle (section 4.3) with
circumradius b, so its gyration in the paper's units is ρ a/b: b = 0.5 a makes the
homogeneous disk's ρ = 0.5 a triangle with ρ = 1; b = 0.99 a comes closest to ρ = 0.5.

    python benchmarks/law_exponents.py --gyration 0.5 --restitution 0.2:0.8:4 --samples 20
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

from harness.sweep.grid import chi
from reference import ReferenceOptions, simulate
from reference.exponent import excess_energy_of, trajectory_exponent
from reference.scene import Body, Ground, RunSettings, Scene, initial_from_linear


def three_point_scene(rho: float, gamma: float, q0, p0, bump_radius: float = 0.5) -> Scene:
    return Scene(
        name=f"three-point-rho{rho:g}-gamma{gamma:g}",
        body=Body(n=3, gyration=rho),
        ground=Ground(kind="three_point", bump_radius=bump_radius),
        initial=initial_from_linear(q0, p0),
        restitution=gamma,
        run=RunSettings(t_end=200.0, max_impacts=20000),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gyration", type=float, default=0.5)
    ap.add_argument("--restitution", default="0.2:0.8:4")
    ap.add_argument("--samples", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--laws", default="paper,moreau,sequential")
    ap.add_argument("--bump-radius", type=float, default=0.5)
    args = ap.parse_args()
    a, b, k = args.restitution.split(":")
    gammas = np.linspace(float(a), float(b), int(k))
    for law in args.laws.split(","):
        all_c, n_all, n_singular = [], 0, 0
        for ig, gamma in enumerate(gammas):
            cs, statuses = [], []
            for s in range(args.samples):
                x = chi(args.seed, ig, 0, s)
                q0 = (0.01 * x[2], 0.01 * x[3], 0.02)
                p0 = (0.05 * x[0], 0.05 * x[1], -0.05)
                scene = three_point_scene(args.gyration, float(gamma), q0, p0, args.bump_radius)
                opts = ReferenceOptions(sample_dt=scene.run.t_end, impact_law=law)
                traj = simulate(scene, options=opts)
                statuses.append(traj.status.value)
                if traj.status.value == "singularity":
                    fit = trajectory_exponent(traj, energy=excess_energy_of(traj, scene))
                    if fit.c is not None:
                        cs.append(fit.c)
            n_sing = statuses.count("singularity")
            all_c, n_all, n_singular = all_c + cs, n_all + len(statuses), n_singular + n_sing
            mean = f"{statistics.mean(cs):.3f}" if cs else "-"
            std = f"{statistics.stdev(cs):.3f}" if len(cs) > 1 else "-"
            print(f"{law:10s} gamma={gamma:.2f} singularity {n_sing}/{len(statuses)} "
                  f"with c {len(cs)}/{n_sing}  c = {mean} ± {std}  "
                  f"statuses={sorted(set(statuses))}", flush=True)  # fmt: skip
        mean = f"{statistics.mean(all_c):.3f}" if all_c else "-"
        print(f"{law:10s} all        singularity {n_singular}/{n_all} "
              f"with c {len(all_c)}/{n_singular}  mean c = {mean}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
