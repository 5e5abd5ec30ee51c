"""Files at the edge: Trajectory → Parquet (samples and impacts); JSON without NaN."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from reference.trajectory import ImpactLog, Trajectory

from .outputs import OutputError, atomic_outputs, atomic_write, check_writable, show


def json_safe(x: Any) -> Any:
    """JSON has no NaN/inf: map them to null (numpy scalars and arrays to Python)."""
    import numpy as np

    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return json_safe(x.tolist())
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def json_text(doc: Any, indent: int | None = None) -> str:
    """One strict JSON document (no NaN or Infinity tokens)."""
    return json.dumps(json_safe(doc), indent=indent, allow_nan=False, default=str)


def impacts_path(path: str | Path) -> Path:
    """The impacts file beside FILE: `.impacts` before the suffix."""
    path = Path(path)
    if not path.name or path.name in (".", ".."):
        raise OutputError(f"{show(path)} names a directory; give a file name")
    return path.with_name(path.stem + ".impacts" + (path.suffix or ".parquet"))


def trajectory_paths(path: str | Path) -> list[Path]:
    """Both files `write_trajectory_parquet` writes."""
    return [Path(path), impacts_path(path)]


def write_trajectory_parquet(traj: Trajectory, path: str | Path, force: bool = False) -> Path:
    """Samples in FILE, impacts in FILE with `.impacts` before the suffix, both written
    atomically (harness.outputs): complete, or not there at all.

    Both files carry the run's summary (status, message, ...) as schema metadata."""
    import pyarrow as pa  # here: the CLI imports this module for json_text alone
    import pyarrow.parquet as pq

    cols = {"t": traj.t}
    if traj.t_lo is not None:
        cols["t_lo"] = traj.t_lo
    for name, arr in (
        ("position", traj.position),
        ("quaternion", traj.quaternion),
        ("velocity", traj.velocity),
        ("angular_velocity", traj.angular_velocity),
    ):
        suffixes = "wxyz" if name == "quaternion" else "xyz"
        for i, s in enumerate(suffixes):
            cols[f"{name}_{s}"] = arr[:, i]
    cols["kinetic_energy"] = traj.kinetic_energy
    cols["potential_energy"] = traj.potential_energy
    cols["energy"] = traj.energy
    meta = {b"summary": json_text(traj.summary(with_impacts=False)).encode()}
    table = pa.table(cols).replace_schema_metadata(meta)
    imp = pa.table(
        {name: pa.array(traj.impact_column(name)) for name in ImpactLog.COLUMNS}
    ).replace_schema_metadata(meta)
    with atomic_outputs(trajectory_paths(path), force) as (samples_tmp, impacts_tmp):
        pq.write_table(table, samples_tmp)
        pq.write_table(imp, impacts_tmp)
    return Path(path)


TABLE_SUFFIXES = (".csv", ".parquet")


def check_table_path(
    path: str | Path, force: bool = False, inputs: tuple[str | Path, ...] = ()
) -> Path:
    """The path a table may be written to: a `.csv` or `.parquet` name that
    harness.outputs.check_writable accepts (not an existing file unless `force`, not an
    input).  Raises OutputError; meant to be called before any work is done."""
    return check_writable(path, force, inputs, what="table", suffixes=TABLE_SUFFIXES)


def write_table(table: Any, path: str | Path, force: bool = False) -> Path:
    """Write a pyarrow table as CSV or Parquet (by suffix), atomically
    (harness.outputs.atomic_write: complete or not there at all)."""
    p = check_table_path(path, force)
    with atomic_write(p, force) as tmp:
        if p.suffix.lower() == ".csv":
            import pyarrow.csv as pcsv

            pcsv.write_csv(table, tmp)
        else:
            import pyarrow.parquet as pq

            pq.write_table(table, tmp)
    return p
