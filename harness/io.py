"""Files at the edge: Trajectory → Parquet (samples and impacts)."""

from __future__ import annotations

import json
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
