"""Output files: checked before any work, written atomically, never over a user's file.

Every command that writes a file goes through this module (docs/inputs.md, "Never
destroy"):

- `check_writable` runs before the simulation: an output may not be one of the
  command's inputs (not even with --force); an existing file is replaced only with
  --force, a directory or a device (/dev/null, a pipe) never; and the place must be
  writable, which is tested by
  creating and removing a temporary file (or directory) in the nearest existing folder,
  so /proc, a read-only mount, a regular file used as a folder or a name longer than the
  file system allows fail at once, with one line, instead of after the run.
- `atomic_write` / `atomic_outputs` hand out a temporary file in the target's folder and
  move it into place only when the writer finished (os.link without --force, so that a
  file that appeared meanwhile is still not replaced; os.replace with it).  A run that
  fails or is interrupted leaves neither a half-written file nor a temporary one, nor
  folders it created for nothing.  Before the move each file is flushed to disk
  (fsync) and its size checked against what was written, so a full disk (ENOSPC at
  write, close or fsync) or a lost permission ends in `OutputError` naming the path and
  the cause, never in a short file under the final name.
- Temporary names carry the writer's process id (`.harness-tmp-<pid>-…`): the next
  write into a folder removes those of processes no longer running (a run killed with
  SIGKILL cannot clean up after itself), `remove_stale_temporaries`.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

from reference.scene import show_path as show

from . import signals

TEMP_PREFIX = ".harness-tmp-"
# A path component longer than this (bytes) is refused where os.pathconf cannot tell.
DEFAULT_NAME_MAX = 255
# A temporary name whose writer cannot be told (no process id in it) is stale after this.
STALE_AFTER_S = 3600.0


class OutputError(Exception):
    """An output that cannot or must not be written: one line, exit status 2."""


def check_writable(
    path: str | os.PathLike,
    force: bool = False,
    inputs: Sequence[str | os.PathLike] = (),
    what: str = "output",
    suffixes: Sequence[str] = (),
) -> Path:
    """Refuse now what atomic_write would refuse or fail at later (module docstring);
    with `suffixes`, also a name not ending in one of them.  Returns the path."""
    p = _as_path(path, what)
    for inp in inputs:
        if _same_file(p, Path(inp)):
            raise OutputError(f"{what} {show(p)} is an input of this command; choose another name")
    exists = os.path.lexists(p)
    if exists and p.is_dir():
        raise OutputError(f"{what} {show(p)} is a directory; give a file name")
    if exists and os.path.exists(p) and not p.is_file():
        raise OutputError(f"{what} {show(p)} is not a regular file (a device, a pipe, ...)")
    if suffixes and p.suffix.lower() not in suffixes:
        raise OutputError(f"{what} {show(p)}: the file name must end in {' or '.join(suffixes)}")
    if exists and not force:
        raise OutputError(f"{what} {show(p)} exists; use --force to replace it")
    _check_names(p, what)
    _probe_folder(p, what)
    return p


RECORDING_SUFFIXES = (".rrd",)


def check_recording_path(
    path: str | os.PathLike, force: bool = False, inputs: Sequence[str | os.PathLike] = ()
) -> Path:
    """`--record PATH`: a writable `.rrd` name (check_writable)."""
    return check_writable(path, force, inputs, what="--record", suffixes=RECORDING_SUFFIXES)


def check_directory(path: str | os.PathLike, what: str = "output directory") -> Path:
    """A folder that exists (and is one) or can be created, and where files can be
    written: tested like `check_writable`, with a temporary file inside it (or a temporary
    folder in its nearest existing ancestor)."""
    p = _as_path(path, what)
    if os.path.lexists(p) and not os.path.isdir(p):
        raise OutputError(f"{what} {show(p)} is not a directory")
    _check_names(p / "x", what)
    _probe_folder(p / "x", what)
    return p


def check_distinct(paths: Sequence[str | os.PathLike | None]) -> None:
    """Two outputs of one command must not be the same file."""
    seen: dict[Path, str] = {}
    for path in paths:
        if path is None:
            continue
        key = Path(os.path.abspath(path))
        if key in seen:
            raise OutputError(f"{show(path)} is given for two outputs; choose distinct names")
        seen[key] = str(path)


@contextlib.contextmanager
def atomic_outputs(paths: Sequence[str | os.PathLike], force: bool = False) -> Iterator[list[Path]]:
    """Temporary files (same folders, same suffixes) for `paths`; on success of the block
    every one is moved into place, on any exception (Ctrl-C included) all are removed."""
    targets = [Path(p) for p in paths]
    created: list[Path] = []
    tmps: list[Path] = []
    try:
        for target in targets:
            created += _make_folders(target.parent)
            remove_stale_temporaries(target.parent)
            with signals.deferred():  # created and listed, or neither (SIGTERM, Ctrl-C)
                fd, name = tempfile.mkstemp(
                    dir=target.parent, prefix=temp_prefix(), suffix=target.suffix or None
                )
                tmps.append(Path(name))
            os.fchmod(fd, _mode_for(target))  # mkstemp makes it private (0600)
            os.close(fd)
        yield list(tmps)
        signals.raise_if_received()  # a swallowed SIGTERM or Ctrl-C: nothing moves in place
        for tmp in tmps:
            _sync(tmp)
        for tmp, target in zip(tmps, targets, strict=True):
            _commit(tmp, target, force)
    except OSError as exc:
        _discard(tmps, created)
        raise OutputError(cannot_write(_failed_target(exc, tmps, targets), exc)) from None
    except BaseException:
        _discard(tmps, created)
        raise
    else:
        _discard(tmps, [])


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, force: bool = False) -> Iterator[Path]:
    """`atomic_outputs` for one file."""
    with atomic_outputs([path], force) as (tmp,):
        yield tmp


def write_text(path: str | os.PathLike, text: str, force: bool = False) -> Path:
    return write_bytes(path, text.encode("utf-8"), force)


def write_bytes(path: str | os.PathLike, data: bytes, force: bool = False) -> Path:
    """`data` under `path`, atomically; read back (size and tail) before the move."""
    with atomic_write(path, force) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
        _check_contents(tmp, data)
    return Path(path)


def temp_prefix() -> str:
    """`.harness-tmp-<pid>-`: whose temporary file this is (`remove_stale_temporaries`)."""
    return f"{TEMP_PREFIX}{os.getpid()}-"


def remove_stale_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove the temporary files a killed run left in `folder`: those whose process id
    names no running process, and those without one older than STALE_AFTER_S.  Returns
    what was removed; a file that cannot be removed is left alone."""
    removed = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if entry.name.startswith(TEMP_PREFIX) and entry.is_file(follow_symlinks=False):
                if _is_stale(entry) and _unlink(entry.path):
                    removed.append(Path(entry.path))
    return removed


def _is_stale(entry: os.DirEntry) -> bool:
    pid_text = entry.name[len(TEMP_PREFIX) :].split("-", 1)[0]
    if pid_text.isdigit():
        return not _process_alive(int(pid_text))
    try:
        return time.time() - entry.stat(follow_symlinks=False).st_mtime > STALE_AFTER_S
    except OSError:
        return False


def _process_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True  # exists, owned by someone else (or not a pid: leave it)
    return True


def _unlink(path: str) -> bool:
    try:
        os.unlink(path)
    except OSError:
        return False
    return True


def _sync(tmp: Path) -> None:
    """Flush a finished temporary file to disk: a full disk may only say so here."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _check_contents(tmp: Path, data: bytes) -> None:
    """The file holds `data`: its size, and its last bytes read back."""
    size = os.stat(tmp).st_size
    tail = data[-4096:]
    with open(tmp, "rb") as fh:
        fh.seek(max(size - len(tail), 0))
        back = fh.read()
    if size != len(data) or back != tail:
        raise OSError(errno.EIO, f"read back {size} bytes of {len(data)} written", str(tmp))


# ----------------------------------------------------------------------------- helpers


def _as_path(path: str | os.PathLike, what: str) -> Path:
    text = os.fspath(path)
    if not text or "\x00" in str(text):
        raise OutputError(f"{what} {show(text)} is not a usable file name")
    return Path(text)


def _same_file(a: Path, b: Path) -> bool:
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except (OSError, ValueError):
        pass
    return os.path.abspath(a) == os.path.abspath(b)


def _check_names(p: Path, what: str) -> None:
    """Each component within the file system's NAME_MAX (the temporary name is no longer
    than the target's), the whole within PATH_MAX."""
    anchor = _existing_ancestor(p.parent)
    try:
        name_max = os.pathconf(anchor, "PC_NAME_MAX")
        path_max = os.pathconf(anchor, "PC_PATH_MAX")
    except (OSError, ValueError):
        name_max, path_max = DEFAULT_NAME_MAX, 4096
    for part in p.parts:
        if len(os.fsencode(part)) > name_max:
            raise OutputError(
                f"{what} {show(p)}: the name {show(part, 40)} is longer than the "
                f"{name_max} bytes the file system allows"
            )
    if len(os.fsencode(os.path.abspath(p))) >= path_max:
        raise OutputError(f"{what} {show(p)} is longer than the {path_max} bytes allowed")


def _mode_for(target: Path) -> int:
    """Permissions of the file to write: those of the file it replaces, else what a
    plain open() would give (0666 less the umask)."""
    try:
        return stat.S_IMODE(os.stat(target).st_mode)
    except OSError:
        mask = os.umask(0)
        os.umask(mask)
        return 0o666 & ~mask


def _existing_ancestor(folder: Path) -> Path:
    folder = Path(os.path.abspath(folder))
    while not os.path.lexists(folder) and folder != folder.parent:
        folder = folder.parent
    return folder


def _probe_folder(p: Path, what: str) -> None:
    """Create and remove a temporary file in the target's folder (or a temporary folder
    in its nearest existing ancestor, which atomic_write would have to create)."""
    folder = Path(os.path.abspath(p.parent))
    anchor = _existing_ancestor(folder)
    if not anchor.is_dir():
        raise OutputError(f"{what} {show(p)}: {show(anchor)} is not a directory")
    try:
        if anchor == folder:
            fd, name = tempfile.mkstemp(dir=anchor, prefix=TEMP_PREFIX)
            os.close(fd)
            os.unlink(name)
        else:
            os.rmdir(tempfile.mkdtemp(dir=anchor, prefix=TEMP_PREFIX))
    except OSError as exc:
        raise OutputError(f"cannot write {what} {show(p)}: {_reason(exc)}") from None


def _make_folders(folder: Path) -> list[Path]:
    """mkdir -p, returning the folders it created (deepest last)."""
    missing = []
    f = Path(os.path.abspath(folder))
    while not os.path.lexists(f):
        missing.append(f)
        f = f.parent
    created = []
    for f in reversed(missing):
        f.mkdir()
        created.append(f)
    return created


def _commit(tmp: Path, target: Path, force: bool) -> None:
    if force:
        if os.path.exists(target) and not target.is_file():  # never replace a device
            raise OutputError(f"{show(target)} is not a regular file")
        os.replace(tmp, target)
        return
    try:
        os.link(tmp, target)  # fails if the target exists: never replaces a file
    except FileExistsError:
        raise OutputError(f"{show(target)} exists; use --force to replace it") from None
    except OSError as exc:  # no hard links here (e.g. some network or FAT mounts)
        if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        if os.path.lexists(target):
            raise OutputError(f"{show(target)} exists; use --force to replace it") from None
        os.replace(tmp, target)
        return
    os.unlink(tmp)


def _discard(tmps: list[Path], created: list[Path]) -> None:
    for tmp in tmps:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    for folder in reversed(created):
        with contextlib.suppress(OSError):
            folder.rmdir()  # only if still empty


def _failed_target(exc: OSError, tmps: list[Path], targets: list[Path]) -> Path:
    """The output a failure concerns: the target of a temporary file or of a folder
    named in the error, else the first."""
    failed = str(exc.filename)
    for tmp, target in zip(tmps, targets, strict=False):
        if failed == str(tmp):
            return target
    for target in targets:
        if failed in (str(target), str(target.parent), os.path.abspath(target.parent)):
            return target
    return targets[0]


def cannot_write(path, exc: OSError) -> str:
    """'cannot write PATH: CAUSE', the one line every write failure ends with."""
    return f"cannot write {show(path)}: {_reason(exc)}"


def _reason(exc: OSError) -> str:
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return "disk full (no space left on device)"
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return "permission denied" if exc.errno != errno.EROFS else "read-only file system"
    return exc.strerror or str(exc)
