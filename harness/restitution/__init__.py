"""`harness restitution`: what each engine gives for the restitution asked for.

Single impacts of a body dropped onto the ground (`drops`: a vertex, an edge landing
flat-on, the face on a bump of the three_point ground), measured from the run's own rows
(`impact`: e_eff = −u⁺/u⁻, the energy change against the exact loss (1 − γ²)·½ u⁻²/w,
penetration and contact duration), over a grid of γ, impact speeds and timesteps
(`study`), summarised as each engine's range of faithful restitution, printed (`text`)
and drawn (`plot`).  docs/engines.md, "The restitution contract"."""
