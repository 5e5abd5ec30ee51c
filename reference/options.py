"""Settings of the exact reference that a user may change: sampling, tolerances, the
search method and the impact law of simultaneous impacts.  Everything else is a named
tolerance of the model (reference.core.tolerances)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ReferenceOptions:
    """How `reference.simulate` runs.

    sample_dt: spacing of the regular samples (default t_end / 2000); events add their
      own pre- and post-event samples.
    chatter_tol: complete a chatter sequence once the separation speed u ≤ chatter_tol·V
      (V = |v| + a|ω|); the completion changes the state by O(chatter_tol²) relative.
    contact_rtol: relative tolerance of the DOP853 integration of contact phases.
    energy_floor: the motion ends (singularity) once the energy above the resting level
      is at most energy_floor × its initial value (18 decades by default; the exponent
      fit of E ≈ a (t_f − t)^c then has 13 after skipping its first 3 and last 2).
    max_samples: samples beyond this many are not recorded (the run goes on).
    window_search: large polygons (n > 19) examine only the vertices near the ground at
      each search step (False: every vertex; the same events, slower).
    work_budget: loop steps between returns to Python (progress display, Ctrl-C and
      SIGTERM); 50,000 steps take at most about 0.6 s (the costliest steps measured, a
      100-gon held on bumps, 12 µs each on a loaded 2-core machine), and the results do
      not depend on it.
    impact_law: how several contacts touching at an impact are resolved: a name of the
      law registry (reference.core.laws.LAW_NAMES: `paper`, the paper's rule, ends the
      run `simultaneous_impact`; `moreau`, `sequential`, ...; docs/architecture.md,
      "Impact laws"); None: the scene's `impact_law` (default `paper`).
    simultaneity_window: contacts reaching the ground within this time T of each other
      count as one simultaneous impact (T |u|/√(g a) after a contact reached at normal
      speed |u|: scene.window_speed_unit); None: the scene's, else the law's
      (scene.default_window: 1e-11 under moreau and sequential, 0 under paper; 0:
      strictly sequential).
    sequential_order: the `sequential` law's order of contacts (sweeps over it); None:
      the fastest approaching first.
    """

    sample_dt: float | None = None
    chatter_tol: float = 1e-6
    contact_rtol: float = 1e-12
    energy_floor: float = 1e-18
    max_samples: int = 500_000
    window_search: bool = True
    work_budget: int = 50_000
    impact_law: str | None = None
    simultaneity_window: float | None = None
    sequential_order: tuple[int, ...] | None = None
