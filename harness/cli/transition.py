"""`harness transition`: a polygon rolling on its rim over a bumpy floor, followed to the
end: the regimes (rim only, mixed, bumps only), their exponents and the tilt at which the
bumps take over, against the paper's α ≈ Δ/d (harness.transition)."""

from __future__ import annotations

from .common import (
    BadInput,
    add_dt,
    add_engine,
    add_force,
    add_json,
    add_max_steps,
    add_t_end,
    emit,
    float_in,
    fraction,
    log,
    note,
    vertices,
)

# --delta within the paper's reach and below the disk: 1e-9 m … 1 cm on d = 0.1 m.
delta_m = float_in(1e-9, 1e-2, what="a bump height [m]")
# --tilt: a start on the rim (above 0) short of standing on edge.
tilt_rad = float_in(1e-9, 1.0, what="a tilt [rad]")


def register(sub) -> None:
    from ..transition.scene import PAPER_DELTAS

    t = sub.add_parser(
        "transition",
        help="rolling on the rim to bouncing on three bumps (bumpy ground)",
        description="A spinning n-gon (rho = 0.5) rolling on its rim over a floor with "
        "three bumps of height Delta, in the paper's units (d = 0.1 m, g = 9.81), followed "
        "to the end: energy against the time to the singularity with the regimes (rim "
        "only, mixed, bumps only), the local exponent c of each, the tilt at which the "
        "bumps take over against Delta/a, the time in each regime.  The reference run ends "
        "failed ('stalled at t = ...') when three returns of its loop in a row advance t by "
        "less than one roundoff unit of the motion's time scale sqrt(a/g) per step (the "
        "bumpy ground's contact phases can creep, e.g. at restitution 0).",
    )
    t.add_argument(
        "scene",
        nargs="?",
        help="a scene file or built-in name with a bumpy ground (default: the study's "
        "scene built from --delta, --tilt, --n, --restitution)",
    )
    t.add_argument(
        "--delta",
        type=delta_m,
        metavar="M",
        help=f"bump height Delta [m] (default {PAPER_DELTAS[0]:g}; the paper: "
        f"{PAPER_DELTAS[0]:g} ... {PAPER_DELTAS[1]:g})",
    )
    t.add_argument("--tilt", type=tilt_rad, metavar="RAD", help="start tilt [rad] (default 0.02)")
    t.add_argument("--n", type=vertices, metavar="N", help="vertices of the polygon (default 100)")
    t.add_argument(
        "--restitution", type=fraction, metavar="GAMMA", help="restitution (default 0.5)"
    )
    add_engine(t)
    add_dt(t)
    add_t_end(t)
    add_max_steps(t)
    t.add_argument("--plot", metavar="FILE.png", help="energy against time to the singularity")
    add_force(t)
    add_json(t)
    t.set_defaults(func=run)


STUDY_OPTIONS = ("delta", "tilt", "n", "restitution")


def study_scene(args):
    """The SCENE argument, or the study's scene from the options."""
    given = {k: getattr(args, k) for k in STUDY_OPTIONS if getattr(args, k) is not None}
    if args.scene is not None:
        if given:
            raise BadInput(
                "transition: --" + ", --".join(given) + " build the study's scene; "
                "give them or a SCENE, not both"
            )
        from ..scenes import resolve_scene

        return resolve_scene(args.scene)
    from ..transition.scene import transition_scene

    return transition_scene(**given)


def run(args) -> int:
    from ..outputs import atomic_write, check_writable
    from ..provenance import attach
    from ..scenes import scene_file
    from ..simulators import check_engine, check_run, run_simulator
    from ..transition.study import check_bumpy, run_transition
    from ..transition.text import format_transition

    check_engine(args.engine)
    scene = study_scene(args)
    check_bumpy(scene)
    check_run(args.engine, scene, args.dt, args.t_end, args.max_steps)
    if args.plot:
        inputs = [p for p in [scene_file(args.scene)] if p is not None] if args.scene else []
        check_writable(args.plot, args.force, inputs, what="--plot", suffixes=(".png",))

    def simulate(engine, scene, dt, t_end, progress=None):
        if engine == "reference":
            return bounded_reference(scene, t_end)
        return run_simulator(engine, scene, dt, t_end, max_steps=args.max_steps, progress=progress)

    _, doc = run_transition(scene, args.engine, args.dt, args.t_end, simulate, progress=None)
    if args.plot:
        from ..transition.plot import save_figure, transition_figure

        with atomic_write(args.plot, args.force) as tmp:
            save_figure(transition_figure(doc), tmp)
        doc["plot"] = str(args.plot)
        note(f"wrote {args.plot}")
    log(f"transition: {len(doc['regimes'])} regimes")
    emit(attach(doc, args), args.json, format_transition(doc))
    return 0


def bounded_reference(scene, t_end):
    """The reference run under a StallGuard (harness.stall): a run that stops advancing
    (the bumpy ground's contact phases can creep once the disk lies nearly flat on a
    bump) ends `failed` with the guard's sentence instead of running for ever."""
    from reference import simulate
    from reference.trajectory import Trajectory

    from ..guard import guard_trajectory
    from ..stall import Stalled, StallGuard

    try:
        traj = simulate(scene, t_end=t_end, progress=StallGuard(scene))
    except Stalled as exc:
        traj = Trajectory.failed("reference", scene.name, None, str(exc))
    return guard_trajectory(scene, traj)
