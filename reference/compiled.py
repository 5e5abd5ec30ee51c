"""Access to the compiled event loop: ahead-of-time when it has been built, else numba's
just-in-time compilation with its on-disk cache.

`make setup` builds the loop ahead of time (`python -m reference.core.aot`, a C
compiler needed) into an extension module beside the sources; it imports in
milliseconds and needs no numba at run time.  A stamp of the core's source files is
stored with it: when the sources change, the stale module is ignored and the loop is
compiled just in time (cached in __pycache__ after the first run).
`reference.simulate.load_event_loop` does the one-time work (compilation, or loading the
cache) apart, so that run times never include it.  This module imports no other module of
the package (reference.geometry imports it)."""

from __future__ import annotations

import hashlib
import importlib
import os
from pathlib import Path

CORE_DIR = Path(__file__).with_name("core")
AOT_MODULE = "reference.core._aot"
STAMP_FILE = CORE_DIR / "_aot.stamp"
# the folders whose njit functions numba caches on disk (in their __pycache__)
JIT_CACHED = (CORE_DIR, CORE_DIR.parent / "linear")

# exported function → the core module that defines it
EXPORTS = {
    "run_events": "loop",
    "quaternion_product_rows": "arrays",
    "quaternion_exp_rows": "arrays",
    "quaternion_log_rows": "arrays",
    "rotate_rows": "arrays",
    "tilt_rows": "arrays",
    "axis_rows": "arrays",
    "contact_kinematics_rows": "arrays",
    "energy_rows": "arrays",
    "free_acceleration_rows": "arrays",
    "length_scale_rows": "arrays",
    "multi_impact": "multi_impact",
}

_aot = None
_aot_checked = False
_cache_checked = False


def _sources_stamp(folders) -> str:
    """SHA-256 of the source files of `folders`, file by file (name, then content)."""
    h = hashlib.sha256()
    for folder in folders:
        for path in sorted(folder.glob("*.py")):
            h.update(path.name.encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def source_stamp() -> str:
    """SHA-256 of the core's source files (what the ahead-of-time module was built from)."""
    return _sources_stamp((CORE_DIR,))


def _load_aot():
    """The ahead-of-time module if it exists and matches the sources (None when the
    environment variable EULER_DISK_NO_AOT is set)."""
    if os.environ.get("EULER_DISK_NO_AOT"):
        return None
    return fresh_aot_module()


def fresh_aot_module():
    """The ahead-of-time module beside the sources if its stamp matches them, else None."""
    try:
        stamp = STAMP_FILE.read_text().strip()
    except OSError:
        return None
    if stamp != source_stamp():
        return None
    try:
        return importlib.import_module(AOT_MODULE)
    except ImportError:
        return None


def numba_cache_folder(source_folder: Path) -> Path:
    """The folder where numba caches the compiled functions of `source_folder`'s modules,
    as numba's own cache locators choose it: under NUMBA_CACHE_DIR when that is set, else
    the folder's __pycache__ where it can be written, else numba's user-wide cache.  The
    folder's __pycache__ where this numba's locators are not the ones read here."""
    sources = sorted(source_folder.glob("*.py"))  # numba locates a cache for a source file
    try:
        from numba.core import caching

        impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
        for locator_class in getattr(impl, "_locator_classes", ()) if sources else ():
            locator = locator_class.from_function(_locator_probe, str(sources[0]))
            if locator is not None:
                return Path(locator.get_cache_path())
    except (ImportError, AttributeError, TypeError):
        pass
    return source_folder / "__pycache__"


def _locator_probe():
    """A function for numba's cache locators to read a first line from."""


def clear_stale_jit_cache() -> None:
    """numba's cache does not notice that a function called from another module has
    changed; after any change to the core's or the linear model's sources the cached
    machine code of both is dropped (the stamp of the sources it was compiled from is
    kept beside the core's cache).  Called before the first compiled call of either."""
    global _cache_checked
    if _cache_checked:
        return
    _cache_checked = True
    caches = [numba_cache_folder(folder) for folder in JIT_CACHED]
    stamp_file = caches[0] / "jit.stamp"
    stamp = _sources_stamp(JIT_CACHED)  # the linear kernel calls the core's functions
    try:
        if stamp_file.read_text().strip() == stamp:
            return
    except OSError:
        pass
    for cache in caches:
        for path in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
            path.unlink(missing_ok=True)
    try:
        stamp_file.parent.mkdir(exist_ok=True)
        stamp_file.write_text(stamp + "\n")
    except OSError:
        pass


def _aot_module():
    global _aot, _aot_checked
    if not _aot_checked:
        _aot, _aot_checked = _load_aot(), True
    return _aot


def jit_function(name: str):
    """The just-in-time (numba) version of an exported function."""
    clear_stale_jit_cache()
    module = importlib.import_module(f"reference.core.{EXPORTS[name]}")
    return getattr(module, name)


def function(name: str):
    """A compiled function of the core (EXPORTS): ahead-of-time if built and fresh,
    else just in time."""
    aot = _aot_module()
    if aot is not None:
        return getattr(aot, name)
    return jit_function(name)


def run_events():
    """The compiled event loop (reference.core.loop.run_events)."""
    return function("run_events")


def kernel_source() -> str:
    """'ahead-of-time' or 'just-in-time'."""
    return "ahead-of-time" if _aot_module() is not None else "just-in-time"


def jit_cached() -> bool:
    """Whether numba's cache holds the loop already (its index file exists)."""
    return any((CORE_DIR / "__pycache__").glob("loop.run_events-*.nbi"))
