"""`harness engines`: every installed engine, its package and version, and whether it loads.

Each engine is loaded (its entry point imported) to read `fixed_step` and to show that it
works; the built-in entry points import their engines only when run, so this does not
import MuJoCo, PyBullet or Drake.  Exit status 2 when an engine fails to load (each one
named with the reason on stderr; the others are still listed).
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
    from ..simulators import EngineLoadError, engine_infos, is_fixed_step, load_engine

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
            "error": None,
        }
        try:
            row["fixed_step"] = is_fixed_step(info.name)
            row["library"] = attribute(load_engine(info.name), "library")
            row["library_version"] = distribution_version(row["library"])
        except EngineLoadError as exc:
            row["error"] = str(exc)
        rows.append(row)
    return rows


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
                f"{r['library']} {r['library_version']}" if r["library"] else "-",
                "ok" if r["error"] is None else "FAILS TO LOAD",
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
