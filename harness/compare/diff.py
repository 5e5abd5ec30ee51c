"""The impact-by-impact diff of `harness compare --out FILE` (.csv or .parquet).

One row per run and reference impact, in order: the reference impact (time, contact,
impulse, normal velocity before and after), the run impact matched to it
(harness.metrics.match_impacts), and their differences (run − reference).  `status`
says what happened to the reference impact:

- `matched`: the run has it (same contact, time inside `window`);
- `tail_skipped`: a slow chatter-tail bounce one of the two sequences lists and the
  other merged or truncated (not compared one by one);
- `mismatch`: the first disagreement; `mismatch_kind` is `time` (same contact, outside
  the window), `contact` (another contact hit), `missed` (no run impact) or `spurious`
  (the run hit where the reference has no impact: the run columns hold that impact);
- `after_divergence`: after the first mismatch, where the two motions differ and
  impacts are no longer paired;
- `outside_window`: after the end of the run (or of the common time window).

docs/output.md lists every column with its unit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from reference.trajectory import Trajectory

from ..metrics import impact_windows

if TYPE_CHECKING:
    from . import CompareResult, EngineRun

FIELDS = ("t", "contact", "impulse", "v_normal_pre", "v_normal_post")


def impact_columns(traj: Trajectory) -> dict[str, np.ndarray]:
    """The impacts of a run as columns: t (s), contact, impulse (N·s), v_normal_pre and
    v_normal_post (m/s, normal velocity of the contact point before and after)."""
    return {name: traj.impact_column(name) for name in FIELDS}


def _statuses(run: EngineRun, n_ref: int) -> tuple[list[str], np.ndarray, str | None]:
    """status per reference impact, the run impact paired with each (−1: none) and the
    mismatch kind."""
    m = run.metrics
    status = ["outside_window"] * n_ref
    paired = np.full(n_ref, -1, dtype=np.int64)
    match = m.match
    if match is None:
        return status, paired, None
    for i, j in match.pairs:
        status[i], paired[i] = "matched", j
    for i in match.skipped_reference_indices:
        status[i] = "tail_skipped"
    x = match.mismatch
    if x is None:
        return status, paired, None
    first = x.ref_index
    if first is None:  # spurious: the next reference impact is where the walk stopped
        done = [i for i, s in enumerate(status) if s in ("matched", "tail_skipped")]
        first = (max(done) + 1) if done else 0
    if first < n_ref:
        status[first] = "mismatch"
        if x.run_index is not None:
            paired[first] = x.run_index
    for i in range(first + 1, min(match.n_reference, n_ref)):
        status[i] = "after_divergence"
    return status, paired, x.kind


def run_diff(result: CompareResult, run: EngineRun) -> dict[str, list]:
    """The diff rows of one run (module docstring), as columns."""
    ref = impact_columns(result.reference)
    out = impact_columns(run.trajectory)
    n = len(ref["t"])
    status, paired, kind = _statuses(run, n)
    window = impact_windows(result.reference, run.metrics.tolerance) if n else np.zeros(0)
    has = paired >= 0
    j = np.where(has, paired, 0)
    cols: dict[str, list] = {
        "run": [run.label] * n,
        "engine": [run.engine] * n,
        "dt": [run.dt] * n,
        "reference_impact": list(range(n)),
        "status": status,
        "mismatch_kind": [kind if s == "mismatch" else None for s in status],
        "window": window.tolist(),
        "run_impact": [int(x) if h else None for x, h in zip(paired, has, strict=True)],
    }
    for f in FIELDS:
        cols[f"reference_{f}"] = ref[f].tolist()
        if len(out["t"]):
            vals = out[f][j]
            cols[f"run_{f}"] = [v.item() if h else None for v, h in zip(vals, has, strict=True)]
        else:
            cols[f"run_{f}"] = [None] * n
    for f in ("t", "impulse", "v_normal_pre", "v_normal_post"):
        cols[f"d_{f}"] = [
            None if r is None else r - s
            for r, s in zip(cols[f"run_{f}"], cols[f"reference_{f}"], strict=True)
        ]
    return cols


SCHEMA = pa.schema(
    [
        ("run", pa.string()),
        ("engine", pa.string()),
        ("dt", pa.float64()),
        ("reference_impact", pa.int64()),
        ("status", pa.string()),
        ("mismatch_kind", pa.string()),
        ("window", pa.float64()),
        ("run_impact", pa.int64()),
        *[
            (f"{who}_{f}", pa.int64() if f == "contact" else pa.float64())
            for f in FIELDS
            for who in ("reference", "run")
        ],
        *[(f"d_{f}", pa.float64()) for f in ("t", "impulse", "v_normal_pre", "v_normal_post")],
    ]
)


def impact_diff(result: CompareResult) -> pa.Table:
    """Every run's diff, one after the other (SCHEMA's column order)."""
    cols: dict[str, list] = {name: [] for name in SCHEMA.names}
    for run in result.runs:
        for name, values in run_diff(result, run).items():
            cols[name].extend(values)
    return pa.table(cols, schema=SCHEMA)
