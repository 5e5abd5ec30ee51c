"""Writing the result files of `harness fidelity` and `harness report` (JSON, PNG, HTML):
checked before any work, written atomically, never over an existing file without --force.

A small local writer for these two commands; the project's general output module
(never-destroy rules for every command) is expected to take its place when the branches
are merged.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path


def check_result_path(path: str | Path, suffixes: tuple[str, ...], force: bool = False) -> Path:
    """The path a result may be written to: a name ending in one of `suffixes`, not an
    existing file unless `force`, never an existing directory or device.  Raises
    ValueError (bad input) otherwise; meant to be called before any work is done."""
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ValueError(f"{p}: the file name must end in {' or '.join(suffixes)}")
    if p.exists() and not p.is_file():
        raise ValueError(f"{p} exists and is not a file")
    if p.exists() and not force:
        raise ValueError(f"{p} exists; pass --force to replace it")
    return p


def write_result_atomic(path: Path, write: Callable[[str], None], force: bool = False) -> Path:
    """Call `write(tmp_path)` on a temporary file in the same folder, then rename it over
    `path` (os.replace), so a reader never sees a half-written file and an interrupted
    write leaves the old one.  An existing file is replaced only with `force` (also when
    it appeared while we wrote)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        if path.exists() and not force:
            raise ValueError(f"{path} exists; pass --force to replace it")
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600: give the usual permissions
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def write_result_text(
    text: str, path: str | Path, suffixes: tuple[str, ...], force: bool = False
) -> Path:
    """Write `text` (UTF-8) atomically to a `suffixes` file name (`check_result_path`,
    `write_result_atomic`)."""
    p = check_result_path(path, suffixes, force)
    return write_result_atomic(p, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), force)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
