"""A sweep's Parquet parts and what proves that a part belongs to a sweep.

A part is written whole in memory, hashed, and moved into place under a name that ends
in its content hash: `part-<label>-<sha256[:32]>.parquet` (`part_bytes`, `part_name`).
The sweep's parameters (its manifest, `SweepConfig.to_dict()`: t_end, seed, grid,
engine, dt, ...) are stored in the part's own Parquet metadata (`PART_CONFIG`).  A part
is accepted (`verify_parts`) only when

- its name carries a hash and its bytes still have that hash (a flipped bit, a copy cut
  short, an edit: `corrupt`);
- it reads as Parquet with the sweep's columns, and its own parameters are the sweep's
  (a part of another seed, t_end or grid, a Parquet file of other columns: `foreign`);
- its rows lie on the grid: engine, n, seed, indices within the grid, the grid values
  at those indices, dt (`rows_mismatch`, `foreign`);
- none of its runs is held by another part, or twice by itself (`duplicate`: every
  part involved, since which one is right cannot be told).

Parts refused are returned with the reason; the store sets them aside and recomputes
their runs.  Parts written before this check (no hash in the name) are refused as
`unverified` and recomputed.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .grid import SweepConfig

KEY = ("i_restitution", "i_gyration", "sample")
PART_CONFIG = b"harness.sweep.config"
HASH_CHARS = 32
_NAME = re.compile(rf"^part-.*-([0-9a-f]{{{HASH_CHARS}}})\.parquet$")

SCHEMA = pa.schema(
    [
        ("engine", pa.string()),
        ("n", pa.int32()),
        ("seed", pa.int64()),
        ("i_restitution", pa.int32()),
        ("i_gyration", pa.int32()),
        ("sample", pa.int32()),
        ("gyration", pa.float64()),
        ("restitution", pa.float64()),
        ("status", pa.string()),
        ("c", pa.float64()),
        ("c_stderr", pa.float64()),
        ("t_singularity", pa.float64()),
        ("n_impacts", pa.int64()),
        ("fit_decades", pa.float64()),
        ("c_decades", pa.float64()),
        ("c_period", pa.float64()),
        ("message", pa.string()),
        ("error", pa.string()),
        ("q0", pa.list_(pa.float64())),
        ("p0", pa.list_(pa.float64())),
        ("dt", pa.float64()),
        ("wall_time_s", pa.float64()),
        ("cpu_time_s", pa.float64()),
    ]
)


@dataclass(frozen=True)
class Refused:
    """A part that does not belong: `kind` is corrupt, foreign, duplicate or unverified
    (the suffix it is set aside with), `why` says what failed."""

    path: Path
    kind: str
    why: str

    def line(self) -> str:
        return f"{self.path.name}: {self.kind} ({self.why})"


def config_text(config: SweepConfig) -> str:
    return json.dumps(config.to_dict(), sort_keys=True)


def part_bytes(rows: list[dict], config: SweepConfig) -> bytes:
    """The Parquet file of one chunk's rows, the sweep's parameters in its metadata."""
    table = pa.Table.from_pylist(rows, schema=SCHEMA)
    table = table.replace_schema_metadata({PART_CONFIG: config_text(config).encode()})
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    return sink.getvalue().to_pybytes()


def part_name(label: str, data: bytes) -> str:
    return f"part-{label}-{content_hash(data)}.parquet"


def content_hash(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:HASH_CHARS]


def read_part(path: Path) -> tuple[pa.Table | None, dict | None, Refused | None]:
    """(rows, the part's own parameters, None) or (None, None, why it is refused) from the
    hash, the Parquet structure and the columns alone."""
    match = _NAME.match(path.name)
    if match is None:
        return None, None, Refused(path, "unverified", "no content hash in its name")
    try:
        data = path.read_bytes()
    except OSError as exc:
        return None, None, Refused(path, "corrupt", exc.strerror or str(exc))
    if content_hash(data) != match.group(1):
        return None, None, Refused(path, "corrupt", "its bytes do not match its hash")
    try:
        table = pq.ParquetFile(pa.BufferReader(data)).read()  # one file: no dataset layer
    except (pa.ArrowException, OSError, ValueError) as exc:
        return None, None, Refused(path, "corrupt", f"not Parquet: {exc}"[:120])
    if table.schema.remove_metadata() != SCHEMA:
        return None, None, Refused(path, "foreign", "other columns than a sweep's")
    meta = (table.schema.metadata or {}).get(PART_CONFIG)
    try:
        own = json.loads(meta)
        SweepConfig.from_dict(own)
    except (TypeError, ValueError, KeyError, AttributeError):
        return None, None, Refused(path, "foreign", "no sweep parameters of its own")
    return table, own, None


def config_difference(have: dict, want: dict) -> str:
    """'key=value (now value), ...' for the parameters that differ ('' when none)."""
    diff = sorted(k for k in set(have) | set(want) if have.get(k) != want.get(k))
    return ", ".join(f"{k}={have.get(k)!r} (now {want.get(k)!r})" for k in diff)


def stored_config(parts_dir: Path) -> dict | None:
    """The parameters most of the intact parts carry (None without any): what a sweep
    directory whose manifest is lost was run with."""
    counts: Counter = Counter()
    for path in sorted(parts_dir.glob("part-*.parquet")):
        _, own, refused = read_part(path)
        if refused is None:
            counts[json.dumps(own, sort_keys=True)] += 1
    return json.loads(counts.most_common(1)[0][0]) if counts else None


def verify_parts(parts_dir: Path, config: SweepConfig) -> tuple[pa.Table, list[Refused]]:
    """(the rows of every part that belongs to `config`, the parts refused): module
    docstring.  A part's runs are all kept or all refused; parts that hold the same run
    are all refused (which one is right cannot be told) and recomputed."""
    want = config.to_dict()
    kept: list[tuple[Path, pa.Table, list[tuple]]] = []
    refused: list[Refused] = []
    for path in sorted(parts_dir.glob("part-*.parquet")):
        table, own, bad = read_part(path)
        if bad is None and own != want:
            bad = Refused(path, "foreign", "parameters " + config_difference(own, want))
        if bad is None:
            columns = checked_columns(table)
            mismatch = rows_mismatch(columns, config)
            if mismatch:
                bad = Refused(path, "foreign", f"rows off this sweep's grid: {mismatch}")
        if bad is not None:
            refused.append(bad)
            continue
        keys = list(zip(*(columns[k].tolist() for k in KEY), strict=True))
        kept.append((path, table.replace_schema_metadata(None), keys))
    counts = Counter(k for _, _, keys in kept for k in keys)
    tables = []
    for path, table, keys in kept:
        if any(counts[k] > 1 for k in keys):
            refused.append(Refused(path, "duplicate", "holds runs another part holds too"))
        else:
            tables.append(table)
    rows = pa.concat_tables(tables) if tables else SCHEMA.empty_table()
    return rows, refused


# the columns `rows_mismatch` checks (KEY among them)
CHECKED = ("engine", "n", "seed", *KEY, "gyration", "restitution", "dt")


def checked_columns(table: pa.Table) -> dict[str, np.ndarray]:
    """The CHECKED columns of a part's rows as numpy arrays (a null: None in `engine`,
    NaN in the numbers), read without converting the part to a DataFrame."""
    return {name: table.column(name).to_numpy(zero_copy_only=False) for name in CHECKED}


def rows_mismatch(rows: dict[str, np.ndarray], config: SweepConfig) -> str:
    """Why stored rows (`checked_columns`) cannot belong to `config` ('' when they all
    can): engine, n, seed, indices within the grid, the grid values at those indices,
    and dt."""
    if not len(rows["engine"]):
        return ""
    for col, want in (("engine", config.engine), ("n", config.n), ("seed", config.seed)):
        if not (rows[col] == want).all():
            return f"{col} {sorted(set(rows[col].tolist()))[:3]} (now {want!r})"
    rho, gam = config.rho_values, config.gamma_values
    ir, ig, s = rows["i_gyration"], rows["i_restitution"], rows["sample"]
    if not (_within(ir, len(rho)) and _within(ig, len(gam))):
        return "grid indices beyond this grid"
    if not _within(s, config.samples):
        return f"samples beyond {config.samples}"
    if not ((rows["gyration"] == rho[ir]).all() and (rows["restitution"] == gam[ig]).all()):
        return "other grid values"
    dt = rows["dt"]
    dt_ok = np.isnan(dt).all() if config.dt is None else (dt == config.dt).all()
    return "" if dt_ok else "another dt"


def _within(index: np.ndarray, size: int) -> bool:
    """Every index in 0 … size − 1 (a NaN, a null, is not)."""
    return bool(((index >= 0) & (index <= size - 1)).all())
