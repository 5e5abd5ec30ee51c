"""numba's on-disk cache is dropped when a source it depends on changes: a change in the
core's or the linear model's sources drops the cached machine code of both (numba itself
only notices a change in the file that defines the cached function)."""

from __future__ import annotations

import importlib.util
import sys

import pytest

from reference import compiled


@pytest.fixture
def sources(tmp_path, monkeypatch):
    """Two source folders, core/ and linear/, each with a module and a numba cache."""
    core, linear = tmp_path / "core", tmp_path / "linear"
    for folder in (core, linear):
        (folder / "__pycache__").mkdir(parents=True)
        (folder / "m.py").write_text("x = 1\n")
    monkeypatch.setattr(compiled, "CORE_DIR", core)
    monkeypatch.setattr(compiled, "JIT_CACHED", (core, linear))
    return core, linear


def cache_files(folder):
    return sorted(p.name for p in compiled.numba_cache_folder(folder).glob("*.nb[ic]"))


def fill(folder):
    cache = compiled.numba_cache_folder(folder)
    cache.mkdir(parents=True, exist_ok=True)
    for name in ("m.f-1.py311.nbi", "m.f-1.py311.1.nbc"):
        (cache / name).write_bytes(b"machine code")


def check(monkeypatch):
    monkeypatch.setattr(compiled, "_cache_checked", False)
    compiled.clear_stale_jit_cache()


def test_a_cache_of_the_same_sources_is_kept(sources, monkeypatch):
    core, linear = sources
    check(monkeypatch)  # no stamp yet: writes it
    fill(core), fill(linear)
    check(monkeypatch)
    assert len(cache_files(core)) == 2 and len(cache_files(linear)) == 2


def test_a_changed_core_source_drops_the_linear_models_cache_too(sources, monkeypatch):
    core, linear = sources
    check(monkeypatch)
    fill(core), fill(linear)
    (core / "m.py").write_text("x = 2\n")
    check(monkeypatch)
    assert cache_files(core) == [] and cache_files(linear) == []


def test_a_changed_linear_source_drops_both_caches(sources, monkeypatch):
    core, linear = sources
    check(monkeypatch)
    fill(core), fill(linear)
    (linear / "m.py").write_text("x = 2\n")
    check(monkeypatch)
    assert cache_files(core) == [] and cache_files(linear) == []


def _where_numba_caches(folder, monkeypatch):
    """The folder in which numba itself writes the cache of a function of a module in
    `folder` (compiled and cached here)."""
    (folder / "cubed.py").write_text(
        "from numba import njit\n\n@njit(cache=True)\ndef cube(x):\n    return x * x * x\n"
    )
    spec = importlib.util.spec_from_file_location("cubed", folder / "cubed.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "cubed", module)
    spec.loader.exec_module(module)
    assert module.cube(2.0) == 8.0
    (index,) = folder.parent.rglob("cubed.cube-*.nbi")
    return index.parent


def test_under_numba_cache_dir_a_changed_source_drops_the_cache_numba_reads(
    sources, tmp_path, monkeypatch
):
    import numba.core.config

    core, linear = sources
    monkeypatch.setattr(numba.core.config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    cache = compiled.numba_cache_folder(core)
    assert _where_numba_caches(core, monkeypatch) == cache
    check(monkeypatch)
    fill(core), fill(linear)
    (core / "m.py").write_text("x = 2\n")
    check(monkeypatch)
    assert cache_files(core) == [] and cache_files(linear) == []
    assert (cache / "jit.stamp").exists() and not (core / "__pycache__" / "jit.stamp").exists()
