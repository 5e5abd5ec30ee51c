"""Files at the edge: Trajectory → Parquet (samples and impacts); tables → CSV or Parquet
without ever destroying a user's file."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from reference.trajectory import Trajectory


def write_trajectory_parquet(traj: Trajectory, path: str | Path) -> Path:
    """Samples in FILE, impacts in FILE with `.impacts` before the suffix.

    Both files carry the run's summary (status, message, ...) as schema metadata."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
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
    meta = {b"summary": json.dumps(traj.summary(with_impacts=False), default=str).encode()}
    table = pa.table(cols).replace_schema_metadata(meta)
    pq.write_table(table, path)
    imp = pa.table(
        {
            "t": [e.t for e in traj.impacts],
            "t_lo": [e.t_lo for e in traj.impacts],
            "contact": pa.array([e.contact for e in traj.impacts], type=pa.int64()),
            "impulse": [e.impulse for e in traj.impacts],
            "v_normal_pre": [e.v_normal_pre for e in traj.impacts],
            "v_normal_post": [e.v_normal_post for e in traj.impacts],
        }
    ).replace_schema_metadata(meta)
    ipath = path.with_name(path.stem + ".impacts" + (path.suffix or ".parquet"))
    pq.write_table(imp, ipath)
    return path


TABLE_SUFFIXES = (".csv", ".parquet")


def check_table_path(path: str | Path, force: bool = False) -> Path:
    """The path a table may be written to: a `.csv` or `.parquet` name, not an existing
    file unless `force`.  Raises ValueError (bad input) otherwise; meant to be called
    before any work is done."""
    p = Path(path)
    if p.suffix.lower() not in TABLE_SUFFIXES:
        raise ValueError(f"{p}: the file name must end in .csv or .parquet")
    if p.exists() and not force:
        raise ValueError(f"{p} exists; pass --force to replace it")
    if p.exists() and not p.is_file():
        raise ValueError(f"{p} exists and is not a file")
    return p


def write_table(table: pa.Table, path: str | Path, force: bool = False) -> Path:
    """Write `table` as CSV or Parquet (by suffix) atomically: into a temporary file in
    the same folder, then renamed over the name (os.replace), so a reader never sees a
    half-written file and an interrupted write leaves the old one.  An existing file is
    replaced only with `force` (`check_table_path`)."""
    p = check_table_path(path, force)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent)
    os.close(fd)
    try:
        if p.suffix.lower() == ".csv":
            import pyarrow.csv as pcsv

            pcsv.write_csv(table, tmp)
        else:
            pq.write_table(table, tmp)
        if p.exists() and not force:  # appeared while we wrote
            raise ValueError(f"{p} exists; pass --force to replace it")
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return p
