"""The package's build step: the reference's compiled core (reference/core/_aot*.so and
its stamp) is an optional extension module built by `reference.core.aot.build`, so that
`pip install .`, `pip install -e .` and `pip wheel .` carry the same module as `make
setup`.  Without a C compiler (or without numba.pycc) the build says so in one line and
goes on: the core is then compiled just in time on first use (docs/development.md).
With the environment variable EULER_DISK_BUILD_CORE=0 the build leaves the core out:
`make setup` installs the dependencies that way and builds the core with `python -m
reference.core.aot` while pip installs the extras.  Everything else about the package
is in pyproject.toml."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
CORE_MODULE = "reference.core._aot"  # reference.compiled.AOT_MODULE


def reuse_fresh_core(target: Path) -> Path | None:
    """The module already beside the sources, copied to `target` with its stamp, when
    that stamp matches the sources (a second `pip install -e`, as `make test` after the
    core install, then skips compiling the same module again); None otherwise."""
    from reference.compiled import STAMP_FILE, source_stamp

    in_place = STAMP_FILE.parent / target.name
    try:
        fresh = in_place.is_file() and STAMP_FILE.read_text().strip() == source_stamp()
    except OSError:
        return None
    if not fresh:
        return None
    target.parent.mkdir(parents=True, exist_ok=True)
    if in_place.resolve() != target.resolve():
        shutil.copyfile(in_place, target)
        shutil.copyfile(STAMP_FILE, target.with_name(STAMP_FILE.name))
    print(f"the reference's compiled core beside the sources is up to date: {in_place.name}")
    return target


class BuildCompiledCore(build_ext):
    """build_ext for the one module numba.pycc compiles (it runs the C compiler itself)."""

    def build_extension(self, ext: Extension) -> None:
        self.built_core = None
        if os.environ.get("EULER_DISK_BUILD_CORE") == "0":
            print("EULER_DISK_BUILD_CORE=0: the reference's compiled core is not built here")
            return
        if str(ROOT) not in sys.path:
            sys.path.insert(0, str(ROOT))  # the sources being built, not an installed copy
        from reference.core import aot

        target = Path(self.get_ext_fullpath(ext.name))
        self.built_core = reuse_fresh_core(target) or aot.build_or_explain(target.parent)

    def copy_extensions_to_source(self) -> None:
        """An editable install (`pip install -e .`) uses the sources in place: setuptools
        copies the module there, and the stamp goes beside it (nothing to copy when the
        core was not built)."""
        built = getattr(self, "built_core", None)
        if built is None:
            return
        super().copy_extensions_to_source()
        from reference.compiled import STAMP_FILE

        stamp = built.with_name(STAMP_FILE.name)
        if stamp.resolve() != STAMP_FILE.resolve():
            shutil.copyfile(stamp, STAMP_FILE)


setup(
    ext_modules=[Extension(CORE_MODULE, sources=[], optional=True)],
    cmdclass={"build_ext": BuildCompiledCore},
)
