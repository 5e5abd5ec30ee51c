"""Faults while writing: a full disk, a lost permission, a writer thread that
never finishes, a run killed mid-write.  Each ends with exit 2 and one line naming the
path and the cause, and nothing under the final name."""

from __future__ import annotations

import contextlib
import errno
import os
import subprocess
import time
import uuid
from pathlib import Path

import pytest

from harness.cli import main
from harness.outputs import (
    TEMP_PREFIX,
    OutputError,
    atomic_write,
    remove_stale_temporaries,
    write_bytes,
)
from harness.recording import encoded_bytes


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@contextlib.contextmanager
def small_tmpfs(size: str):
    """A tmpfs of `size` (needs root and mount(8)); skips the test when impossible."""
    where = Path(f"/tmp/harness-tmpfs-{uuid.uuid4().hex[:8]}")
    where.mkdir()
    try:
        done = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)],
            capture_output=True,
            text=True,
        )
    except OSError as exc:
        where.rmdir()
        pytest.skip(f"cannot mount a tmpfs: {exc}")
    if done.returncode != 0:
        where.rmdir()
        pytest.skip(f"cannot mount a tmpfs (needs root): {done.stderr.strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=False)
        where.rmdir()


def test_a_writer_failing_with_a_full_disk_names_path_and_cause(tmp_path):
    target = tmp_path / "out.png"
    with pytest.raises(OutputError) as info, atomic_write(target) as tmp:
        tmp.write_bytes(b"half")
        raise OSError(errno.ENOSPC, "No space left on device")
    assert str(info.value) == f"cannot write {target}: disk full (no space left on device)"
    assert listing(tmp_path) == []


def test_a_short_write_is_caught_by_reading_back(tmp_path, monkeypatch):
    """A file system that accepts the write but keeps fewer bytes: refused at the check."""
    real_open = open

    def truncating_open(path, mode="r", *args, **kwargs):
        fh = real_open(path, mode, *args, **kwargs)
        if "w" in mode and TEMP_PREFIX in str(path):
            write = fh.write
            fh.write = lambda data: write(data[: len(data) // 2])
        return fh

    monkeypatch.setattr("builtins.open", truncating_open)
    with pytest.raises(OutputError, match="read back 5 bytes of 10"):
        write_bytes(tmp_path / "a.json", b"0123456789")
    assert listing(tmp_path) == []


def test_a_recording_onto_a_full_disk_exits_2_and_leaves_nothing(capsys):
    with small_tmpfs("400k") as where:
        out = where / "run.rrd"
        argv = ["compare", "triangle-chatter", "--engine", "linear", "--record", str(out)]
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"harness: error: cannot write {out}: disk full (no space left on device)"]
        assert listing(where) == []


def test_a_recording_whose_encoder_never_finishes_ends_within_its_bound(tmp_path):
    class StuckStream:
        def flush(self, timeout_sec):
            time.sleep(timeout_sec)
            raise RuntimeError("flush timed out")

    t0 = time.monotonic()
    with pytest.raises(OutputError, match="did not finish encoding the recording within 0.5 s"):
        encoded_bytes(StuckStream(), tmp_path / "x.rrd", timeout_s=0.5)
    assert time.monotonic() - t0 < 5.0


def test_a_recording_without_its_footer_is_not_written(tmp_path):
    class CutStream:
        def flush(self, timeout_sec):
            pass

        def read(self, flush):
            return b"RRF2" + b"\0" * 100

    with pytest.raises(OutputError, match="no RRD footer"):
        encoded_bytes(CutStream(), tmp_path / "x.rrd")


def test_temporaries_of_a_killed_run_are_removed_by_the_next_write(tmp_path):
    dead = subprocess.Popen(["true"])
    dead.wait()
    stale = tmp_path / f"{TEMP_PREFIX}{dead.pid}-abc.png"
    live = tmp_path / f"{TEMP_PREFIX}{os.getppid()}-abc.png"  # our parent: running
    old_unnamed = tmp_path / f"{TEMP_PREFIX}abcdef.png"  # written before pids were named
    for p in (stale, live, old_unnamed):
        p.write_bytes(b"")
    os.utime(old_unnamed, (time.time() - 7200, time.time() - 7200))
    write_bytes(tmp_path / "fig.png", b"png")
    assert listing(tmp_path) == sorted(["fig.png", live.name])
    assert remove_stale_temporaries(tmp_path) == []


def test_a_sweep_whose_folder_turns_unwritable_mid_run_ends_with_one_line(tmp_path, monkeypatch):
    """Injected: the third part cannot be created (EACCES, as in a folder made read-only
    mid-run; root would not see a chmod).  The parts written so far stay, complete."""
    import tempfile

    from tests.test_sweep_heal import sweep

    real = tempfile.mkstemp
    calls = []

    def mkstemp(*args, **kwargs):
        if str(kwargs.get("dir")).endswith("parts"):
            calls.append(kwargs["dir"])
        if len(calls) > 2:
            raise PermissionError(errno.EACCES, "Permission denied", str(kwargs.get("dir")))
        return real(*args, **kwargs)

    monkeypatch.setattr("harness.outputs.tempfile.mkstemp", mkstemp)
    with pytest.raises(OutputError, match=r"cannot write .*\.parquet: permission denied"):
        sweep(tmp_path)
    parts = sorted((tmp_path / "linear" / "parts").iterdir())
    assert [p.name.startswith("part-") for p in parts] == [True, True]


def test_sigterm_mid_sweep_exits_143_and_leaves_no_temporary(tmp_path):
    import signal
    import sys

    out = tmp_path / "sweep"
    argv = ["sweep", "exponent", "--gyration", "0.3:0.5:5", "--restitution", "0.3:0.6:5"]
    argv += ["--samples", "400", "--engine", "linear", "--workers", "1", "--out", str(out)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "harness", *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    parts = out / "linear" / "parts"
    deadline = time.monotonic() + 120
    while not (parts.is_dir() and any(parts.glob("part-*"))) and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert err.strip().splitlines()[-1] == "harness: terminated"
    assert not [p for p in out.rglob(f"{TEMP_PREFIX}*")]


def test_a_sweep_removes_the_temporaries_a_killed_sweep_left(tmp_path):
    from tests.test_sweep_heal import sweep

    sweep(tmp_path)
    dead = subprocess.Popen(["true"])
    dead.wait()
    left = [
        tmp_path / f"{TEMP_PREFIX}{dead.pid}-compare.png",
        tmp_path / "linear" / f"{TEMP_PREFIX}{dead.pid}-map.png",
        tmp_path / "linear" / "parts" / f"{TEMP_PREFIX}{dead.pid}-part.parquet",
    ]
    for p in left:
        p.write_bytes(b"")
    sweep(tmp_path)
    assert not [p for p in tmp_path.rglob(f"{TEMP_PREFIX}*")]
