"""`harness stress`: hard cases, every simulator, a verdict per case and simulator.

`study` runs the cases (what is judged and how: its docstring), `cases` builds them,
`budget` predicts and caps the runs, `judge` gives the verdicts, `text` the terminal
table and its legend."""

from .cases import StressCase, select_cases, stress_cases
from .judge import FAILED_ENERGY_GAIN, FAILED_PENETRATION, TOLERANCES, assess
from .study import DEFAULT_BUDGET_S, NOT_RUNNABLE, SKIPPED, stress
from .text import format_stress

__all__ = [
    "DEFAULT_BUDGET_S",
    "FAILED_ENERGY_GAIN",
    "FAILED_PENETRATION",
    "NOT_RUNNABLE",
    "SKIPPED",
    "TOLERANCES",
    "StressCase",
    "assess",
    "format_stress",
    "select_cases",
    "stress",
    "stress_cases",
]
