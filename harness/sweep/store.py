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
from pathlib import Path

import pyarrow as pa

from ..outputs import (
    OutputError,
    cannot_write,
    check_directory,
    remove_stale_temporaries,
    show,
    write_bytes,
)
from .grid import SweepConfig
from .parts import (
    KEY,
    SCHEMA,
    Refused,
    config_difference,
    part_bytes,
    part_name,
    rows_mismatch,
    stored_config,
    verify_parts,
)

__all__ = ["KEY", "SCHEMA", "StoreError", "SweepStore", "load_results", "rows_mismatch"]


class StoreError(Exception):
    """The directory cannot be used for this sweep (message says why)."""


_UNREADABLE = object()
# What a sweep writes: in the study directory, in an engine's directory, in its parts/.
ROOT_FILES = ("compare-*.png",)
ENGINE_FILES = ("manifest.json", "manifest.json.*", ".lock", "*.png")
PART_FILES = ("part-*.parquet", "part-*.parquet.*-*", ".tmp-*")
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
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RecursionError):
        return _UNREADABLE


def engine_dir(root: str | Path, engine: str) -> Path:
    return Path(root) / engine


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
        remove temporary files left by a killed run, check or write the manifest, set
        aside the parts that do not belong (harness.sweep.parts; module docstring).
        `self.results` holds the stored rows (DataFrame sorted by key, 0 duplicates:
        duplicated parts are refused) and `self.notes` what was set aside and why.
        A file system error ends as StoreError naming the path and the cause."""
        check_study_dir(self.root, self.config.engine)
        try:
            self.parts_dir.mkdir(parents=True, exist_ok=True)
            self._lock()
        except OSError as exc:
            raise StoreError(cannot_write(exc.filename or self.dir, exc)) from None
        try:
            self._open_locked()
        except OSError as exc:
            self.close()
            raise StoreError(cannot_write(exc.filename or self.dir, exc)) from None
        except BaseException:
            self.close()
            raise
        return self

    def _open_locked(self) -> None:
        for tmp in self.parts_dir.glob(".tmp-*"):  # .tmp-*: an unfinished part, never read
            tmp.unlink(missing_ok=True)
        for folder in (self.root, self.dir, self.parts_dir):  # a run killed mid-write
            remove_stale_temporaries(folder)
        self.notes: list[str] = []
        self._check_manifest()
        table, refused = verify_parts(self.parts_dir, self.config)
        self.refused = refused
        for r in refused:
            aside = set_aside(r.path, r.kind)
            self.notes.append(f"set aside {r.kind} part {aside.name}: {r.why}")
        self.results = _frame(table)

    def _check_manifest(self) -> None:
        """The manifest, else the parameters the intact parts carry, must be this
        sweep's while runs are stored (StoreError otherwise); a manifest over no runs is
        set aside; a missing or unreadable one is rewritten."""
        manifest = self.dir / "manifest.json"
        want = self.config.to_dict()
        have = _read_json(manifest) if manifest.exists() else None
        if have is _UNREADABLE:
            self.notes.append(f"set aside unreadable {set_aside(manifest, 'corrupt').name}")
            have = None
        if have == want:
            return
        stored = stored_config(self.parts_dir)
        if have is not None:
            if stored is not None:
                raise StoreError(
                    f"{self.dir} holds a sweep with other parameters: "
                    f"{config_difference(have, want)}; "
                    "rerun with the same parameters to resume, or use another --out"
                )
            self.notes.append(f"set aside {set_aside(manifest, 'unused').name} (no runs stored)")
        elif stored is not None and stored != want:
            raise StoreError(
                f"{self.dir} has no readable manifest and its stored runs belong to another "
                f"sweep ({config_difference(stored, want)}); use another --out"
            )
        text = json.dumps(want, indent=1, sort_keys=True).encode()
        write_bytes(manifest, text, force=True)

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
        """Persist the rows of one finished chunk as a new part: atomic, fsynced, read
        back, named by its content hash (harness.sweep.parts); OutputError naming the
        path and the cause when it cannot be written."""
        data = part_bytes(rows, self.config)
        return write_bytes(self.parts_dir / part_name(label, data), data)

    # -- reading -------------------------------------------------------------------
    def part_paths(self) -> list[Path]:
        return sorted(self.parts_dir.glob("part-*.parquet"))


def _frame(table: pa.Table):
    """(DataFrame of unique rows sorted by key, number of duplicate rows dropped)."""
    df = table.to_pandas()
    n = len(df)
    df = df.drop_duplicates(subset=list(KEY), keep="first")
    df = df.sort_values(list(KEY)).reset_index(drop=True)
    return df, n - len(df)


def load_results(sweep_dir: str | Path):
    """(DataFrame of the rows of the parts that belong to the directory's manifest,
    sorted by key; number of parts refused: harness.sweep.parts).  Nothing is renamed
    here (SweepStore.open does that).  Without a readable manifest, the parameters most
    intact parts carry stand for it."""
    config = _config_of(sweep_dir)
    if config is None:
        return _frame(SCHEMA.empty_table())[0], 0
    table, refused = verify_parts(Path(sweep_dir) / "parts", config)
    return _frame(table)[0], len(refused)


def refused_parts(sweep_dir: str | Path) -> list[Refused]:
    config = _config_of(sweep_dir)
    return [] if config is None else verify_parts(Path(sweep_dir) / "parts", config)[1]


def _config_of(sweep_dir: str | Path) -> SweepConfig | None:
    config = read_manifest(sweep_dir)
    if config is None:
        stored = stored_config(Path(sweep_dir) / "parts")
        config = None if stored is None else SweepConfig.from_dict(stored)
    return config


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
