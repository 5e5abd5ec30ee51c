"""`harness bench`: speed against error (work-precision) on one scene.

`study` runs it (what is measured and how: its docstring), `settings` holds the
timesteps, the reference's settings and the metrics, `derive` the Pareto fronts and cost
ratios, `plot` the figure, `table` the terminal text and its legend."""

from .derive import derive, loglog_interp, pareto_front
from .plot import plot_work_precision, work_precision_figure
from .settings import (
    DEFAULT_BUDGET_S,
    DEFAULT_DTS,
    ERROR_FLOOR,
    METRIC_LABELS,
    METRICS,
    REFERENCE_SETTINGS,
    TRUTH,
    Setting,
    reference_setting,
)
from .study import bench, predict_time, score, timed
from .table import format_bench

__all__ = [
    "DEFAULT_BUDGET_S",
    "DEFAULT_DTS",
    "ERROR_FLOOR",
    "METRICS",
    "METRIC_LABELS",
    "REFERENCE_SETTINGS",
    "TRUTH",
    "Setting",
    "bench",
    "derive",
    "format_bench",
    "loglog_interp",
    "pareto_front",
    "plot_work_precision",
    "predict_time",
    "reference_setting",
    "score",
    "timed",
    "work_precision_figure",
]
