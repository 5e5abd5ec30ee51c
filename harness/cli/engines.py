"""`harness engines`: every registered engine, its package and version, whether its
physics library is installed (and, when not, the pip extra that installs it), and whether
it loads.

Each engine is loaded (its entry point imported) to read `fixed_step`, `library` and
`extra` and to show that it works; the built-in entry points import their engines only
when run, so this does not import MuJoCo, PyBullet, Drake, DART or JAX.  An engine whose
library is missing is listed as "not installed" with its install command (exit status 0:
that is a choice of extras, not an error).  Exit status 2 when an engine fails to load
(each one named with the reason on stderr; the others are still listed).
"""

from __future__ import annotations

from .common import add_json, emit, note


def register(sub) -> None:
    e = sub.add_parser("engines", help="installed engines (entry points harness.engines)")
    add_json(e)
    e.set_defaults(func=run)


def engine_rows() -> list[dict]:
    """One row per installed engine: name, entry point, package and version (the
    distribution that registers it), fixed_step and library (the optional `library`
    attribute: the physics engine's distribution) with its version (None when it does not
    load), and the load error (None when it loads)."""
    from engines.interface import attribute

    from ..provenance import distribution_version
    from ..simulators import (
        EngineLoadError,
        EngineNotInstalled,
        engine_infos,
        entry_point,
        install_hint,
        load_engine,
    )

    rows = []
    for info in engine_infos():
        row = {
            "name": info.name,
            "entry_point": info.target,
            "package": info.package,
            "version": info.version,
            "fixed_step": None,
            "library": None,
            "library_version": None,
            "extra": None,
            "installed": False,
            "install": None,
            "error": None,
        }
        try:
            obj = entry_point(info.name)
            row["fixed_step"] = bool(attribute(obj, "fixed_step"))
            row["library"] = attribute(obj, "library")
            row["extra"] = attribute(obj, "extra")
            row["library_version"] = distribution_version(row["library"])
            load_engine(info.name)
            row["installed"] = True
        except EngineNotInstalled:
            row["library_version"] = None
            row["install"] = install_hint(row["extra"])
        except EngineLoadError as exc:
            row["error"] = str(exc)
        rows.append(row)
    return rows


def _status(row: dict) -> str:
    if row["error"] is not None:
        return "FAILS TO LOAD"
    if not row["installed"]:
        return f"not installed: {row['install']}"
    return "ok"


def run(args) -> int:
    from ..simulators import GROUP
    from ..text import table

    rows = engine_rows()
    text = table(
        [
            [
                r["name"],
                {True: "yes", False: "no (event-driven)", None: "-"}[r["fixed_step"]],
                r["package"] or "-",
                r["version"] or "-",
                f"{r['library']} {r['library_version'] or ''}".strip() if r["library"] else "-",
                _status(r),
            ]
            for r in rows
        ],
        ["engine", "--dt applies", "package", "version", "wraps", "status"],
    )
    if not rows:
        text = f"no engines installed (entry point group {GROUP!r})"
    emit({"group": GROUP, "engines": rows}, args.json, text)
    broken = [r for r in rows if r["error"] is not None]
    for r in broken:
        note(f"harness: error: {r['error']}")
    return 2 if broken else 0
