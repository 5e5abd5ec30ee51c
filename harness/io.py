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


def check_output_path(path: str | Path, suffixes: tuple[str, ...], force: bool = False) -> Path:
    """The path an output may be written to: a name ending in one of `suffixes`, not an
    existing file unless `force`, never an existing directory.  Raises ValueError (bad
    input) otherwise; meant to be called before any work is done."""
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ValueError(f"{p}: the file name must end in {' or '.join(suffixes)}")
    if p.exists() and not p.is_file():
        raise ValueError(f"{p} exists and is not a file")
    if p.exists() and not force:
        raise ValueError(f"{p} exists; pass --force to replace it")
    return p


def check_table_path(path: str | Path, force: bool = False) -> Path:
    """`check_output_path` for a table: a `.csv` or `.parquet` name."""
    return check_output_path(path, TABLE_SUFFIXES, force)


def write_atomic(path: Path, write, force: bool = False) -> Path:
    """Call `write(tmp_path)` on a temporary file in the same folder, then rename it
    over `path` (os.replace), so a reader never sees a half-written file and an
    interrupted write leaves the old one.  An existing file is replaced only with
    `force` (also when it appeared while we wrote)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        if path.exists() and not force:
            raise ValueError(f"{path} exists; pass --force to replace it")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def write_table(table: pa.Table, path: str | Path, force: bool = False) -> Path:
    """Write `table` as CSV or Parquet (by suffix) atomically (`write_atomic`); an
    existing file is replaced only with `force` (`check_table_path`)."""
    p = check_table_path(path, force)

    def write(tmp: str) -> None:
        if p.suffix.lower() == ".csv":
            import pyarrow.csv as pcsv

            pcsv.write_csv(table, tmp)
        else:
            pq.write_table(table, tmp)

    return write_atomic(p, write, force)


def write_text(text: str, path: str | Path, suffixes: tuple[str, ...], force: bool = False) -> Path:
    """Write `text` (UTF-8) atomically to a `suffixes` file name (`check_output_path`,
    `write_atomic`)."""
    p = check_output_path(path, suffixes, force)
    return write_atomic(p, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), force)
