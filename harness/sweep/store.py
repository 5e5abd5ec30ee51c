"""The sweep's result store: a directory that loses nothing.

Layout (one study directory ROOT = --out, one subdirectory per simulator):

    ROOT/<engine>/manifest.json     the SweepConfig (parameters that determine results)
    ROOT/<engine>/.lock             held (flock) while a sweep writes here
    ROOT/<engine>/parts/part-*.parquet   one part per finished chunk, one row per run
    ROOT/<engine>/*.png             the map, its simultaneous-impact fraction, sections
    ROOT/compare-<engine>-vs-<base>.png   side by side, when several engines exist

Every part is written to a hidden temporary file in the same directory, flushed to disk
and renamed into place (atomic on POSIX), so a part is either complete or absent, and
a kill at any moment loses at most the chunks in flight.  The set of finished tasks is
whatever the parts hold: a rerun computes only the keys missing from it.
"""

from __future__ import annotations

import fcntl
import json
import os
import uuid
from pathlib import Path

import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from .grid import SweepConfig

KEY = ("i_restitution", "i_gyration", "sample")

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


class StoreError(Exception):
    """The directory cannot be used for this sweep (message says why)."""


def engine_dir(root: str | Path, engine: str) -> Path:
    return Path(root) / engine


def _write_atomic(path: Path, write) -> None:
    tmp = path.with_name(f".tmp-{uuid.uuid4().hex}-{path.name}")
    try:
        with open(tmp, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


class SweepStore:
    """One engine's sweep directory: manifest, lock, Parquet parts."""

    def __init__(self, root: str | Path, config: SweepConfig):
        self.root = Path(root)
        self.config = config
        self.dir = engine_dir(root, config.engine)
        self.parts_dir = self.dir / "parts"
        self._lock_fh = None

    # -- opening -------------------------------------------------------------------
    def open(self) -> SweepStore:
        """Create or reopen the directory: take the lock, check or write the manifest,
        remove temporary files left by a killed run."""
        self.parts_dir.mkdir(parents=True, exist_ok=True)
        self._lock()
        manifest = self.dir / "manifest.json"
        want = self.config.to_dict()
        if manifest.exists():
            have = json.loads(manifest.read_text())
            diff = sorted(k for k in set(have) | set(want) if have.get(k) != want.get(k))
            if diff:
                self.close()
                what = ", ".join(f"{k}={have.get(k)!r} (now {want.get(k)!r})" for k in diff)
                raise StoreError(
                    f"{self.dir} holds a sweep with other parameters: {what}; "
                    "rerun with the same parameters to resume, or use another --out"
                )
        else:
            if any(self.parts_dir.glob("part-*.parquet")):
                self.close()
                raise StoreError(f"{self.dir} has result parts but no manifest.json")
            text = json.dumps(want, indent=1, sort_keys=True).encode()
            _write_atomic(manifest, lambda fh: fh.write(text))
        for tmp in self.parts_dir.glob(".tmp-*"):
            tmp.unlink(missing_ok=True)
        return self

    def _lock(self) -> None:
        fh = open(self.dir / ".lock", "a+")
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.close()
            raise StoreError(f"another sweep is writing to {self.dir}") from None
        self._lock_fh = fh

    def close(self) -> None:
        if self._lock_fh is not None:
            fcntl.flock(self._lock_fh, fcntl.LOCK_UN)
            self._lock_fh.close()
            self._lock_fh = None

    def __enter__(self) -> SweepStore:
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    # -- writing -------------------------------------------------------------------
    def write_part(self, rows: list[dict], label: str) -> Path:
        """Persist the rows of one finished chunk as a new part (atomic)."""
        table = pa.Table.from_pylist(rows, schema=SCHEMA)
        path = self.parts_dir / f"part-{label}-{uuid.uuid4().hex[:8]}.parquet"
        _write_atomic(path, lambda fh: pq.write_table(table, fh))
        return path

    # -- reading -------------------------------------------------------------------
    def part_paths(self) -> list[Path]:
        return sorted(self.parts_dir.glob("part-*.parquet"))


def read_parts(parts_dir: str | Path) -> pa.Table:
    """All rows of a sweep directory's parts (empty table with the schema if none)."""
    paths = sorted(Path(parts_dir).glob("part-*.parquet"))
    if not paths:
        return SCHEMA.empty_table()
    # one dataset scan (threaded); columns a part lacks (written before the column was
    # added) come back as nulls
    return ds.dataset([str(p) for p in paths], format="parquet", schema=SCHEMA).to_table()


def load_results(sweep_dir: str | Path):
    """(DataFrame of unique rows sorted by key, number of duplicate rows dropped).

    Duplicates cannot arise from one sweep (a rerun computes only missing keys and the
    lock forbids two writers); if parts were copied in by hand, the first part (by
    name) wins."""
    df = read_parts(Path(sweep_dir) / "parts").to_pandas()
    n = len(df)
    df = df.drop_duplicates(subset=list(KEY), keep="first")
    df = df.sort_values(list(KEY)).reset_index(drop=True)
    return df, n - len(df)


def read_manifest(sweep_dir: str | Path) -> SweepConfig | None:
    path = Path(sweep_dir) / "manifest.json"
    if not path.exists():
        return None
    return SweepConfig.from_dict(json.loads(path.read_text()))


def engines_in(root: str | Path) -> dict[str, SweepConfig]:
    """The sweeps stored under a study directory: engine → its config."""
    out = {}
    root = Path(root)
    if not root.is_dir():
        return out
    for sub in sorted(root.iterdir()):
        cfg = read_manifest(sub) if sub.is_dir() else None
        if cfg is not None:
            out[cfg.engine] = cfg
    return out
