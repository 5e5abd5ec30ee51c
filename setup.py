"""The package's build step: the reference's compiled core (reference/core/_aot*.so and
_aot_rows*.so, each with its stamp) is two optional extension modules built by
`reference.core.aot.build`, so that `pip install .`, `pip install -e .` and `pip wheel .`
carry the same modules as `make setup`.  Without a C compiler (or without numba.pycc)
the build says so in one line and goes on: the core is then compiled just in time on
first use (docs/development.md).  With the environment variable EULER_DISK_BUILD_CORE=0
the build leaves the core out: `make setup` installs the dependencies that way and builds
the two modules with `python -m reference.core.aot --part ...`, one beside pip's install.
Everything else about the package is in pyproject.toml."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
CORE_PARTS = ("_aot", "_aot_rows")  # reference.compiled.AOT_PARTS


def reuse_fresh_core(part: str, target: Path) -> Path | None:
    """The module `part` already beside the sources, copied to `target` with its stamp,
    when that stamp matches the sources (a second `pip install -e`, as `make test` after
    the core install, then skips compiling the same module again); None otherwise."""
    from reference.compiled import source_stamp, stamp_file

    stamp = stamp_file(part)
    in_place = stamp.parent / target.name
    try:
        fresh = in_place.is_file() and stamp.read_text().strip() == source_stamp()
    except OSError:
        return None
    if not fresh:
        return None
    target.parent.mkdir(parents=True, exist_ok=True)
    if in_place.resolve() != target.resolve():
        shutil.copyfile(in_place, target)
        shutil.copyfile(stamp, target.with_name(stamp.name))
    print(f"the reference's compiled core beside the sources is up to date: {in_place.name}")
    return target


class BuildCompiledCore(build_ext):
    """build_ext for the modules numba.pycc compiles (it runs the C compiler itself)."""

    def build_extension(self, ext: Extension) -> None:
        self.built_core = getattr(self, "built_core", {})
        if os.environ.get("EULER_DISK_BUILD_CORE") == "0":
            print("EULER_DISK_BUILD_CORE=0: the reference's compiled core is not built here")
            return
        if str(ROOT) not in sys.path:
            sys.path.insert(0, str(ROOT))  # the sources being built, not an installed copy
        from reference.core import aot

        part = ext.name.rsplit(".", 1)[1]
        target = Path(self.get_ext_fullpath(ext.name))
        built = reuse_fresh_core(part, target) or aot.build_or_explain(part, target.parent)
        if built is not None:
            self.built_core[part] = built

    def copy_extensions_to_source(self) -> None:
        """An editable install (`pip install -e .`) uses the sources in place: setuptools
        copies the modules there, and each stamp goes beside its module (nothing to copy
        when the core was not built)."""
        built = getattr(self, "built_core", {})
        if len(built) < len(CORE_PARTS):
            return
        super().copy_extensions_to_source()
        from reference.compiled import stamp_file

        for part, path in built.items():
            stamp = path.with_name(stamp_file(part).name)
            if stamp.resolve() != stamp_file(part).resolve():
                shutil.copyfile(stamp, stamp_file(part))


setup(
    ext_modules=[
        Extension(f"reference.core.{part}", sources=[], optional=True) for part in CORE_PARTS
    ],
    cmdclass={"build_ext": BuildCompiledCore},
)
