"""The fidelity study's defaults, apart so that building the command line (which shows
them in --help) imports nothing else of the study."""

DEFAULT_DTS = (1e-3, 1e-4, 1e-5)
DEFAULT_EPS_GRID = (1.0, 1e-4, 17)  # first, last, count: log-spaced, α half a decade apart
DEFAULT_BUDGET_S = 60.0  # per run
WINDOWS = ("leading", "whole")
