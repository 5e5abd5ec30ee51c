"""The paper's figures from our own computations (`harness figures --out DIR`).

Each figure is recomputed from the linearised model (reference.linear) and saved as a
PNG; alongside it we state what the paper states about it, what we measured, and
whether the two agree.  Figures (paper labels in brackets):

- beta_vs_rho        [fig:plasticbeta]  β against ρ, γ = 0, n = 3 and 25
- feasibility_border [fig:c0_feas]      smallest ρ with a feasible solution, γ = 0
- beta_vs_gamma      [fig:feas]         β against γ, (n, ρ) ∈ {3, 25} × {0.25, 0.5}
- boundaries         [fig:boundaries]   existence / feasibility / stability in (γ, ρ)
- energy_precession  [fig:precession]   E against t_f − t, perturbed self-similar motion
- rod_clin           [fig:rodcoeff]     the rod's c_lin over (ψ, γ)
- triangle_c_vs_clin [fig:numsimsec]    triangle: simulated c against c_lin

Modules: `plotting` (labels, save, the β scatter), `selfsimilar` (§3 figures), `decay`
(energy and exponent figures), `make` (the catalogue, the run, the summary).
"""

from .make import FIGURES, figure_paths, format_figures, make_figures, verdict

__all__ = ["FIGURES", "figure_paths", "format_figures", "make_figures", "verdict"]
