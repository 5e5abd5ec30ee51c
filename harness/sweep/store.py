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

Healing (`SweepStore.open`): damage from outside (a disk that filled up, a copy cut
short, an edit) never makes a directory unusable and never costs a finished result.  A
part that cannot be read is renamed `<part>.corrupt-<time>` (set aside, never deleted)
and its runs are recomputed; a manifest that cannot be read is set aside the same way
and rewritten, after checking that the stored rows belong to this sweep (engine, n,
seed, grid values, samples, dt); a manifest of other parameters over no stored rows
(e.g. left by a run stopped before its first part) is set aside as `.unused-<time>`.

--out must be a study directory: missing, empty, or holding only what a sweep writes
(`check_study_dir`); anything else is refused before anything is written.
"""

from __future__ import annotations

import fcntl
import fnmatch
import json
import os
import time
import uuid
from pathlib import Path

import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from ..outputs import OutputError, check_directory, show
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


_UNREADABLE = object()
# What a sweep writes: in the study directory, in an engine's directory, in its parts/.
ROOT_FILES = ("compare-*.png",)
ENGINE_FILES = ("manifest.json", "manifest.json.*", ".lock", "*.png")
PART_FILES = ("part-*.parquet", "part-*.parquet.corrupt-*", ".tmp-*")
TEMP_FILES = (".tmp-*", ".harness-tmp-*")


def _matches(name: str, patterns) -> bool:
    return any(fnmatch.fnmatchcase(name, pat) for pat in (*patterns, *TEMP_FILES))


def _foreign_in_engine_dir(d: Path) -> list[str]:
    """Entries of an engine directory that no sweep writes."""
    out = []
    for entry in d.iterdir():
        if entry.name == "parts" and entry.is_dir():
            out += [f"parts/{p.name}" for p in entry.iterdir() if not _matches(p.name, PART_FILES)]
        elif not (entry.is_file() and _matches(entry.name, ENGINE_FILES)):
            out.append(entry.name)
    return out


def check_study_dir(root: str | Path, engine: str) -> None:
    """--out is missing, or a writable directory holding only sweep output: engine
    directories (manifest, lock, parts, PNGs), compare-*.png, empty folders.  Anything
    else means it is not a sweep directory: refused before anything is written."""
    root = Path(root)
    try:
        check_directory(root, "--out")
    except OutputError as exc:
        raise StoreError(str(exc)) from None
    if not root.is_dir():
        return
    foreign = []
    for entry in root.iterdir():
        if entry.is_dir() and not entry.is_symlink():
            foreign += [f"{entry.name}/{x}" for x in _foreign_in_engine_dir(entry)]
        elif not (entry.is_file() and _matches(entry.name, ROOT_FILES)):
            foreign.append(entry.name)
    if foreign:
        shown = ", ".join(sorted(show(f, 40) for f in foreign)[:3])
        more = f" and {len(foreign) - 3} more" if len(foreign) > 3 else ""
        raise StoreError(
            f"--out {show(root)} is not a sweep directory (it holds {shown}{more}); give a "
            "new or empty directory, or one a sweep wrote"
        )


def set_aside(path: Path, why: str) -> Path:
    """Rename `path` to `<name>.<why>-<time>` beside it (never delete a user's data)."""
    stamp = time.strftime("%Y%m%dT%H%M%S")
    target = path.with_name(f"{path.name}.{why}-{stamp}")
    k = 1
    while target.exists():
        target = path.with_name(f"{path.name}.{why}-{stamp}-{k}")
        k += 1
    os.replace(path, target)
    return target


def _read_json(path: Path):
    """The parsed manifest, or _UNREADABLE (not UTF-8 JSON, not an object, not a config)."""
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
        SweepConfig.from_dict(d)
        return d
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        return _UNREADABLE


def rows_mismatch(df, config: SweepConfig) -> str:
    """Why stored rows cannot belong to `config` ('' when they all can): engine, n, seed,
    indices within the grid, the grid values at those indices, and dt."""
    if not len(df):
        return ""
    for col, want in (("engine", config.engine), ("n", config.n), ("seed", config.seed)):
        if not (df[col] == want).all():
            return f"{col} {sorted(set(df[col].tolist()))[:3]} (now {want!r})"
    rho, gam = config.rho_values, config.gamma_values
    ir, ig, s = df["i_gyration"], df["i_restitution"], df["sample"]
    if not (ir.between(0, len(rho) - 1).all() and ig.between(0, len(gam) - 1).all()):
        return "grid indices beyond this grid"
    if not s.between(0, config.samples - 1).all():
        return f"samples beyond {config.samples}"
    if not ((df["gyration"] == rho[ir]).all() and (df["restitution"] == gam[ig]).all()):
        return "other grid values"
    dt_ok = df["dt"].isna().all() if config.dt is None else (df["dt"] == config.dt).all()
    return "" if dt_ok else "another dt"


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
        """Create or reopen the directory: check it is a study directory, take the lock,
        remove temporary files left by a killed run, set aside damaged parts, check or
        write the manifest (module docstring).  `self.results` holds the stored rows
        (DataFrame, duplicates dropped) and `self.notes` what was set aside."""
        check_study_dir(self.root, self.config.engine)
        self.parts_dir.mkdir(parents=True, exist_ok=True)
        self._lock()
        try:
            for tmp in self.parts_dir.glob(".tmp-*"):
                tmp.unlink(missing_ok=True)
            table, bad = scan_parts(self.parts_dir)
            self.notes = [f"set aside unreadable part {set_aside(p, 'corrupt').name}" for p in bad]
            self.results = _frame(table)
            self._check_manifest()
        except BaseException:
            self.close()
            raise
        return self

    def _check_manifest(self) -> None:
        manifest = self.dir / "manifest.json"
        want = self.config.to_dict()
        have = _read_json(manifest) if manifest.exists() else None
        df = self.results[0]
        if have is _UNREADABLE:
            self.notes.append(f"set aside unreadable {set_aside(manifest, 'corrupt').name}")
            have = None
        if have is not None:
            diff = sorted(k for k in set(have) | set(want) if have.get(k) != want.get(k))
            if not diff:
                return
            if len(df):
                what = ", ".join(f"{k}={have.get(k)!r} (now {want.get(k)!r})" for k in diff)
                raise StoreError(
                    f"{self.dir} holds a sweep with other parameters: {what}; "
                    "rerun with the same parameters to resume, or use another --out"
                )
            self.notes.append(f"set aside {set_aside(manifest, 'unused').name} (no runs stored)")
        mismatch = rows_mismatch(df, self.config)
        if mismatch:
            raise StoreError(
                f"{self.dir} has no readable manifest and its stored runs belong to another "
                f"sweep ({mismatch}); use another --out"
            )
        text = json.dumps(want, indent=1, sort_keys=True).encode()
        _write_atomic(manifest, lambda fh: fh.write(text))

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


def scan_parts(parts_dir: str | Path) -> tuple[pa.Table, list[Path]]:
    """(all rows of the readable parts, the parts that cannot be read).  One dataset scan
    (threaded) when every part reads; else part by part, to find the damaged ones.
    Columns a part lacks (written before the column was added) come back as nulls."""
    paths = sorted(Path(parts_dir).glob("part-*.parquet"))
    if not paths:
        return SCHEMA.empty_table(), []
    try:
        return _dataset(paths).to_table(), []
    except (pa.ArrowException, OSError, ValueError):
        pass
    good, bad = [], []
    for p in paths:
        try:
            _dataset([p]).to_table()
            good.append(p)
        except (pa.ArrowException, OSError, ValueError):
            bad.append(p)
    return (_dataset(good).to_table() if good else SCHEMA.empty_table()), bad


def _dataset(paths: list[Path]):
    return ds.dataset([str(p) for p in paths], format="parquet", schema=SCHEMA)


def read_parts(parts_dir: str | Path) -> pa.Table:
    """All rows of a sweep directory's readable parts (empty table with the schema if
    none)."""
    return scan_parts(parts_dir)[0]


def _frame(table: pa.Table):
    """(DataFrame of unique rows sorted by key, number of duplicate rows dropped)."""
    df = table.to_pandas()
    n = len(df)
    df = df.drop_duplicates(subset=list(KEY), keep="first")
    df = df.sort_values(list(KEY)).reset_index(drop=True)
    return df, n - len(df)


def load_results(sweep_dir: str | Path):
    """(DataFrame of unique rows sorted by key, number of duplicate rows dropped).

    Duplicates cannot arise from one sweep (a rerun computes only missing keys and the
    lock forbids two writers); if parts were copied in by hand, the first part (by
    name) wins."""
    return _frame(read_parts(Path(sweep_dir) / "parts"))


def read_manifest(sweep_dir: str | Path) -> SweepConfig | None:
    """The sweep's config, None when there is no readable manifest."""
    path = Path(sweep_dir) / "manifest.json"
    d = _read_json(path) if path.is_file() else None
    return None if d is None or d is _UNREADABLE else SweepConfig.from_dict(d)


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
