"""`harness fidelity`: down to which inclination α an engine follows the exact motion.

The paper's scaling invariance (Baranyai & Várkonyi, section 2.6) maps a motion of the
linear model onto the same motion at any smaller inclination: q → ε²q, p → εp, t → εt.
`Scene.scaled(ε)` applies it to a scene given in (q, p), and the study scales the
scene's t_end by ε too.  At a smaller ε the same impacts come ε times closer together in
time and ε² closer in energy, so a fixed-step engine sees fewer steps per flight and
contact heights far below its contact geometry: at some ε it stops following.

Definitions (all stated in the JSON document and the text output):

- **scale ε**: `--eps-grid A:B:K`, K values from A down to B evenly spaced in log ε
  (default 1:1e-4:17, α half a decade apart).  **α** of a scale: the reference's largest
  inclination up to its last leading impact (leading.inclination_scale), ≈ ε² α(1).
- **leading impacts**: the reference's first N impacts (`--leading`, default 10) that
  are not chatter tails (leading.py: why, and how chaotic divergence stays out).
- **window**: `--window leading` (default) runs every engine just past the last leading
  impact (leading.run_end), so the cost of a scale does not include the chaotic end
  that no engine follows; `--window whole` runs it to the reference's end (the whole
  motion), which the exponent criterion needs.
- **metrics of a run** (harness.metrics.evaluate against the reference at the same
  scale): leading impacts matched (same contact, time within 3·dt + 1 %·t capped by
  the gaps, in order), impact-time error (max |t − t_ref| over them, in seconds and
  relative to the scaled time, i.e. divided by ε), energy error before the first
  divergence (max |E − E_ref| / E_ref(0)), and the energy exponent c (exponent.py).
- **pass / α* / k**: criteria.py (≥ 90 % of the leading impacts matched, c within 10 %
  of the reference's where both have one; α* the smallest α passed with every larger
  one passed; k of α* ∝ dt^k by least squares in log-log with its standard error).
- **budget**: study.py (`--budget` seconds per run: predicted from pilot runs, skipped
  above it, stopped at twice it; larger scales of the same engine and dt skipped too).
"""

from __future__ import annotations

from .settings import DEFAULT_BUDGET_S, DEFAULT_DTS, DEFAULT_EPS_GRID, WINDOWS  # noqa: F401

# The study's functions load on first use (the CLI builds its parser from the settings
# alone, without importing the bench, stress and metrics packages the study uses).
_LAZY = {
    "FidelityCriteria": "criteria",
    "alpha_star": "criteria",
    "power_law_fit": "criteria",
    "alpha_star_figure": "plot",
    "matched_figure": "plot",
    "save_figure": "plot",
    "default_engines": "study",
    "eps_values": "study",
    "fidelity": "study",
    "format_fidelity": "text",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
