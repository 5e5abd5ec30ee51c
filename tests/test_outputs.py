"""harness.outputs: outputs are checked before any work and written atomically; nothing a
user owns is ever replaced without --force, and an input never."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from harness.outputs import (
    TEMP_PREFIX,
    OutputError,
    atomic_outputs,
    atomic_write,
    check_directory,
    check_distinct,
    check_writable,
)


def listing(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_an_input_is_refused_even_with_force(tmp_path):
    scene = tmp_path / "keep.toml"
    scene.write_text("precious")
    for force in (False, True):
        with pytest.raises(OutputError, match="is an input"):
            check_writable(scene, force=force, inputs=[scene])
    # the same file by another name (relative path, symlink) is still the input
    (tmp_path / "alias.toml").symlink_to(scene)
    with pytest.raises(OutputError, match="is an input"):
        check_writable(tmp_path / "alias.toml", force=True, inputs=[scene])
    assert scene.read_text() == "precious"


def test_an_existing_file_needs_force_and_a_directory_is_never_a_file(tmp_path):
    out = tmp_path / "run.parquet"
    out.write_text("old")
    with pytest.raises(OutputError, match="use --force"):
        check_writable(out)
    assert check_writable(out, force=True) == out
    with pytest.raises(OutputError, match="is a directory"):
        check_writable(tmp_path, force=True)
    with pytest.raises(OutputError, match="not a regular file"):
        check_writable("/dev/null", force=True)
    assert out.read_text() == "old"


@pytest.mark.parametrize(
    "where",
    [
        lambda d: d / "file.txt" / "out.parquet",  # under a regular file
        lambda d: Path("/proc") / "harness-out.parquet",  # a place nobody may create files
        lambda d: d / ("y" * 300 + ".parquet"),  # a name longer than NAME_MAX
        lambda d: d / ("z" * 300) / "out.parquet",  # a folder name longer than NAME_MAX
    ],
    ids=["under-a-file", "proc", "long-name", "long-folder"],
)
def test_unwritable_places_are_refused_before_anything_is_written(tmp_path, where):
    (tmp_path / "file.txt").write_text("x")
    before = listing(tmp_path)
    with pytest.raises(OutputError):
        check_writable(where(tmp_path))
    assert listing(tmp_path) == before


def test_check_creates_nothing_and_missing_folders_are_fine(tmp_path):
    assert check_writable(tmp_path / "a" / "b" / "out.json") == tmp_path / "a/b/out.json"
    assert check_directory(tmp_path / "new" / "dir") == tmp_path / "new/dir"
    assert listing(tmp_path) == []
    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError, match="not a directory"):
        check_directory(tmp_path / "f")


def test_two_outputs_on_one_file_are_refused(tmp_path):
    check_distinct([tmp_path / "a", None, tmp_path / "b"])
    with pytest.raises(OutputError, match="two outputs"):
        check_distinct([tmp_path / "a", tmp_path / "x" / ".." / "a"])


def test_a_failed_writer_leaves_nothing_behind(tmp_path):
    target = tmp_path / "deep" / "er" / "out.json"
    with pytest.raises(RuntimeError), atomic_write(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the run broke")
    assert listing(tmp_path) == []  # no file, no temporary, no folder it created


def test_an_interrupted_writer_leaves_the_old_file_intact(tmp_path):
    target = tmp_path / "out.json"
    target.write_text("old")
    with pytest.raises(KeyboardInterrupt), atomic_write(target, force=True) as tmp:
        tmp.write_text("new, half")
        raise KeyboardInterrupt
    assert target.read_text() == "old" and listing(tmp_path) == ["out.json"]


def test_a_file_that_appears_meanwhile_is_not_replaced_without_force(tmp_path):
    target = tmp_path / "out.json"
    with pytest.raises(OutputError, match="use --force"), atomic_write(target) as tmp:
        tmp.write_text("ours")
        target.write_text("someone else's")
    assert target.read_text() == "someone else's" and listing(tmp_path) == ["out.json"]


def test_written_files_get_the_usual_permissions_or_keep_the_replaced_ones(tmp_path):
    mask = os.umask(0o022)
    try:
        with atomic_write(tmp_path / "new.json") as tmp:
            tmp.write_text("x")
        old = tmp_path / "old.json"
        old.write_text("old")
        old.chmod(0o640)
        with atomic_write(old, force=True) as tmp:
            tmp.write_text("new")
    finally:
        os.umask(mask)
    assert (tmp_path / "new.json").stat().st_mode & 0o777 == 0o644
    assert old.stat().st_mode & 0o777 == 0o640 and old.read_text() == "new"


def test_all_outputs_are_moved_into_place_with_their_suffixes(tmp_path):
    paths = [tmp_path / "a.parquet", tmp_path / "sub" / "a.impacts.parquet"]
    with atomic_outputs(paths) as tmps:
        assert [t.suffix for t in tmps] == [".parquet", ".parquet"]
        assert all(
            t.name.startswith(TEMP_PREFIX) and t.parent == p.parent
            for t, p in zip(tmps, paths, strict=True)
        )
        for t in tmps:
            t.write_text(t.name)
    assert listing(tmp_path) == ["a.parquet", "sub", "sub/a.impacts.parquet"]
    assert not any(name.startswith(TEMP_PREFIX) for name in os.listdir(tmp_path))
