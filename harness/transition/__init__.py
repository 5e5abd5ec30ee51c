"""The transition study (`harness transition`): a spinning polygon rolling on
its rim over a bumpy floor, followed to the end; its regimes (rim only, mixed, bumps
only), their exponents and the tilt at which the bumps take over, against the paper's
estimate α ≈ Δ/d.  Modules: `scene` (the study's scene in the paper's units),
`regimes` (classification from which contact kinds take impulses or are held), `study`
(run + JSON document), `text`, `plot`."""
