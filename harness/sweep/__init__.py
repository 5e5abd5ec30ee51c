"""`harness sweep exponent`: the energy-exponent map over (γ, ρ) (paper section 4.3).

For every grid point and sample: the paper's random initial state (grid), a run of
the chosen simulator and its exponent c (run), persisted at once as a Parquet part
(store), on a local process pool or a Dask cluster (executors); then the map, the
simultaneous-impact fraction and the sections as PNGs (plots).

Directory layout (design): --out is a study directory holding one subdirectory per
simulator, ROOT/<engine>/ with its manifest, parts and PNGs.  Running the same command
again resumes (only missing runs are computed); the same ROOT with another engine adds
that engine's sweep beside the first (its grid may differ, e.g. a subgrid for the slow
simulators), and ROOT/compare-<engine>-vs-<base>.png then shows it beside the base
map (`linear`, else `reference`).  Reusing ROOT/<engine> with other parameters is
refused.
"""

from .command import (
    SweepError,
    check_config,
    config_from_args,
    exponent_sweep,
    run_exponent_sweep,
)
from .summary import format_summary, summarise

__all__ = [
    "SweepError",
    "check_config",
    "config_from_args",
    "exponent_sweep",
    "format_summary",
    "run_exponent_sweep",
    "summarise",
]
