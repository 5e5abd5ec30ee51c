"""Where a result came from: the `provenance` object of every result document.

Every command that produces results (compare, bench, fidelity, stress, sweep) puts

    "provenance": {"command": "harness compare pentagon-bounce --engine mujoco",
                   "versions": {"python": "3.11.9", "euler-disk-harness": "0.1.0",
                                "mujoco": "3.3.0", ...},
                   "created": "2025-01-31T12:00:00+00:00",
                   "host": "Linux 6.1 x86_64, 2 CPUs (AMD EPYC ...), 23.4 GiB"}

in its JSON document, so that `harness report` can say exactly what made a result and
with which versions.  `command` is the argv as one shell-quoted string (`shlex.join`:
pasting it into a shell reruns it); `versions` come from the installed distributions'
metadata (`importlib.metadata`, nothing is imported): this package, the numerical
libraries it stands on, and every installed engine's registering package and the
physics library it wraps (the `library` attribute of its entry point, as `harness
engines` shows); `created` is the local time with its UTC offset (ISO 8601); `host` a
short description of the machine (no host name).
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Sequence
from typing import Any

PACKAGE = "euler-disk-harness"
PROGRAM = "harness"
# The libraries every result depends on (engines add theirs: `engine_versions`).
CORE_DISTRIBUTIONS = ("numpy", "scipy", "numba", "matplotlib")


@functools.cache
def distribution_version(distribution: str | None) -> str | None:
    """Installed version of a distribution from its metadata (nothing imported); None
    for no name, "not installed" when it is missing.  Read once per process: each read
    searches the path and parses the distribution's METADATA file again (~20 ms for a
    document's versions), and a process that runs several commands (the test suite
    does) would repeat it for each."""
    if distribution is None:
        return None
    from importlib import metadata  # here: its import costs the command's start-up

    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return "not installed"


def engine_versions() -> dict[str, str]:
    """{distribution: version} of every installed engine's registering package and of
    the physics library its entry point says it wraps.  An engine whose entry point does
    not load contributes its package only."""
    from engines.interface import attribute

    from .simulators import EngineLoadError, engine_infos, load_engine

    out: dict[str, str] = {}
    for info in engine_infos():
        if info.package and info.version:
            out[info.package] = info.version
        try:
            library = attribute(load_engine(info.name), "library")
        except EngineLoadError:
            continue
        version = distribution_version(library)
        if library and version:
            out[library] = version
    return out


def versions() -> dict[str, str]:
    """Python, this package, the core numerical libraries and every engine's versions."""
    import platform

    out = {"python": platform.python_version()}
    for dist in (PACKAGE, *CORE_DISTRIBUTIONS):
        out[dist] = distribution_version(dist) or "not installed"
    out.update(engine_versions())
    return out


def host_description() -> str:
    """'Linux 6.1.0 x86_64, 2 CPUs (model), 23.4 GiB' (what is known of it)."""
    import platform

    parts = [f"{platform.system()} {platform.release()} {platform.machine()}".strip()]
    cpus = f"{os.cpu_count()} CPUs"
    model = _cpu_model()
    parts.append(f"{cpus} ({model})" if model else cpus)
    memory = _memory_gib()
    if memory:
        parts.append(f"{memory:.1f} GiB")
    return ", ".join(parts)


def _cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    import platform

    return platform.processor() or None


def _memory_gib() -> float | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    except (ValueError, OSError, AttributeError):
        return None


def command_line(argv: Sequence[str] | None) -> str:
    """The command as one shell-quoted string: 'harness ' + the arguments (sys.argv[1:]
    when argv is None)."""
    import shlex

    args = list(sys.argv[1:] if argv is None else argv)
    return shlex.join([PROGRAM, *args])


def provenance(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """The `provenance` object (module docstring) for a run started with `argv`."""
    import datetime

    return {
        "command": command_line(argv),
        "versions": versions(),
        "created": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "host": host_description(),
    }


def attach(doc: dict[str, Any], args: Any) -> dict[str, Any]:
    """`doc` with its `kind` (the command's name, unless it has one: `harness report`
    recognises documents by it) and its provenance, for a command run with parsed
    `args` (the CLI keeps the argv it parsed in `args.argv`)."""
    command = getattr(args, "command", None)
    if command and "kind" not in doc:
        doc["kind"] = command
    doc["provenance"] = provenance(getattr(args, "argv", None))
    return doc
