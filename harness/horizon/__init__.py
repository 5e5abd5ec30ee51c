"""The reference's own predictability horizon, and each engine's verdict against it
(docs/fidelity.md, "Horizon"): `state` (state differences, perturbations, restarts),
`grid` (level (a): impacts on a step grid), `ensemble` (perturbed and grid ensembles,
matched by compare's rule), `lyapunov` (growth per impact), `verdict` (the `horizon`
object of a compare row), `settings` (defaults)."""
