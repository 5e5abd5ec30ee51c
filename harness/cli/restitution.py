"""`harness restitution`: the effective restitution each engine gives for the γ asked for,
on single impacts (docs/engines.md, "The restitution contract")."""

from __future__ import annotations

from pathlib import Path

from .common import (
    BadInput,
    add_engine,
    add_force,
    add_json,
    emit,
    float_in,
    log,
    note,
)

# The ranges the command accepts (docs/inputs.md): γ > 0 (e_eff/γ), speeds in √(g a),
# and steps from 1e-6 (MAX_CONTACT_TIME / dt stays within the step budget) to 1e-2;
# the onset phase in a step, from 1e-3 (a start at the ground itself is refused).
requested_gamma = float_in(1e-6, 1.0, what="a restitution coefficient")
impact_speed = float_in(1e-6, 1e2, what="an impact speed [sqrt(g a)]")
study_timestep = float_in(1e-6, 1e-2, what="a timestep [sqrt(a/g)]")
onset_phase = float_in(1e-3, 1.0, what="an onset phase [steps]")
PLOT_NAME = "restitution-{engine}.png"


def register(sub) -> None:
    p = sub.add_parser(
        "restitution",
        help="effective restitution e_eff = -u+/u- of single impacts against gamma, per engine",
        description="Each engine's effective restitution on single impacts (a vertex, an edge "
        "landing flat-on, the face on a bump) over requested gamma, impact speeds and "
        "timesteps, with the energy change against the exact loss, penetration and contact "
        "time, and the range where |e_eff/gamma - 1| <= 1 %.",
    )
    from ..restitution.drops import GEOMETRIES
    from ..restitution.study import DEFAULT_DTS, DEFAULT_GAMMAS, DEFAULT_PHASES, DEFAULT_SPEEDS

    add_engine(p, many="default: reference and every installed fixed-step engine that loads")
    p.add_argument(
        "--gamma",
        type=requested_gamma,
        action="append",
        metavar="G",
        help=f"requested restitution in (0, 1]; repeat (default: {_list(DEFAULT_GAMMAS)})",
    )
    p.add_argument(
        "--speed",
        type=impact_speed,
        action="append",
        metavar="V",
        help="impact speed in sqrt(g a), in [1e-6, 100]; repeat "
        f"(default: {_list(DEFAULT_SPEEDS)})",
    )
    p.add_argument(
        "--dt",
        type=study_timestep,
        action="append",
        metavar="DT",
        help="timestep of fixed-step engines in [1e-6, 1e-2]; repeat "
        f"(default: {_list(DEFAULT_DTS)})",
    )
    p.add_argument(
        "--phase",
        type=onset_phase,
        action="append",
        metavar="F",
        help="onset phase in (0, 1]: the contact starts F*dt*speed above the ground, so it "
        f"begins at that fraction of a step; repeat (default: {_list(DEFAULT_PHASES)})",
    )
    p.add_argument(
        "--geometry",
        choices=GEOMETRIES,
        action="append",
        help="impact geometry; repeat (default: all)",
    )
    p.add_argument(
        "--plot",
        metavar="DIR",
        help=f"write one figure per engine into DIR ({PLOT_NAME.format(engine='ENGINE')})",
    )
    p.add_argument("--out", metavar="FILE.json", help="also write the JSON document here")
    add_force(p)
    add_json(p)
    p.set_defaults(func=run)


def _list(xs) -> str:
    return ", ".join(f"{x:g}" for x in xs)


def run(args) -> int:
    from ..progress import progress_bar
    from ..provenance import attach
    from ..restitution.study import run_study
    from ..restitution.text import format_restitution

    engines = study_engines(args.engine)
    grid = study_grid(args)
    plots = check_outputs(args, engines)
    total = sum(len(grid.cells(fixed)) for fixed in _fixed(engines))
    with progress_bar(total, "restitution", unit="impact") as bar:
        doc = run_study(engines, grid, progress=log, tick=bar.update, now=bar.set_postfix_str)
    attach(doc, args)
    write_outputs(args, doc, plots)
    emit(doc, args.json, format_restitution(doc))
    return 0


def study_engines(requested: list[str] | None) -> list[str]:
    """The engines to run, each checked to load: the ones asked for (in order, once), or
    the reference and every installed fixed-step engine that loads (one line on stderr
    for each that does not)."""
    from ..simulators import EngineLoadError, check_engine, engine_names, is_fixed_step

    if requested:
        return [check_engine(e) for e in dict.fromkeys(requested)]
    chosen = ["reference"]
    for name in engine_names():
        try:
            if name != "reference" and is_fixed_step(name):
                chosen.append(name)
        except EngineLoadError as exc:
            note(f"left out: {exc}")
    return chosen


def _fixed(engines: list[str]) -> list[bool]:
    from ..simulators import is_fixed_step

    return [is_fixed_step(e) for e in engines]


def study_grid(args):
    from ..restitution.study import Grid

    defaults = Grid()

    def values(given, default):
        return tuple(dict.fromkeys(given)) if given else default

    return Grid(
        gammas=values(args.gamma, defaults.gammas),
        speeds=values(args.speed, defaults.speeds),
        dts=values(args.dt, defaults.dts),
        geometries=values(args.geometry, defaults.geometries),
        phases=values(args.phase, defaults.phases),
    )


def check_outputs(args, engines: list[str]) -> dict[str, Path]:
    """Every output checked before any run; the plot of each engine's name."""
    from ..outputs import check_directory, check_distinct, check_writable

    plots: dict[str, Path] = {}
    if args.plot:
        folder = check_directory(args.plot, what="--plot")
        for e in engines:
            if "/" in e or e.startswith("."):
                raise BadInput(f"engine name {e!r} cannot name a file in --plot")
            plots[e] = folder / PLOT_NAME.format(engine=e)
    check_distinct([args.out, *plots.values()])
    for path in plots.values():
        check_writable(path, args.force, what="--plot", suffixes=(".png",))
    if args.out:
        check_writable(args.out, args.force, what="--out", suffixes=(".json",))
    return plots


def write_outputs(args, doc: dict, plots: dict[str, Path]) -> None:
    from ..io import json_text
    from ..outputs import atomic_write, write_text
    from ..restitution.plot import restitution_figure

    for e in doc["engines"]:
        path = plots.get(e["engine"])
        if path is None:
            continue
        fig = restitution_figure(e, doc["grid"], doc["faithful"])
        with atomic_write(path, args.force) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        e["plot"] = str(path)
        note(f"wrote {path}")
    if args.out:
        write_text(args.out, json_text(doc, indent=1), args.force)
        note(f"wrote {args.out}")
