"""Terminal text of `harness transition`."""

from __future__ import annotations

from typing import Any

NAMES = {"rim_only": "rim only", "mixed": "mixed", "bumps_only": "bumps only"}


def _g(x, fmt: str = ".3g") -> str:
    return "-" if x is None else format(x, fmt)


def format_transition(doc: dict[str, Any]) -> str:
    tk = doc["takeover"]
    lines = [
        f"transition: {doc['scene']} on {doc['engine']}: {doc['status']} ({doc['message']})",
        f"  n = {doc['n']}, rho = {doc['gyration']:g}, gamma = {doc['restitution']:g}, "
        f"a = {doc['radius']:g}, g = {doc['gravity']:g}; bumps Delta = {_g(tk['delta'])} "
        f"(Delta/a = {_g(tk['delta_over_a'])}, Delta/d = {_g(tk['delta_over_d'])})",
        f"  start tilt {_g(doc['initial_tilt'])} rad; end t_f = {_g(doc['t_f'], '.10g')} "
        f"({doc['t_f_source']})",
        "",
        f"  {'regime':<11} {'from [s]':>11} {'duration':>10} {'t_f - t':>10} {'rim':>7} "
        f"{'bump':>7} {'tilt start':>10} {'tilt end':>10} {'c':>14}",
    ]
    for r in doc["regimes"]:
        c = "-" if r["c"] is None else f"{r['c']:.3f}±{_g(r['c_stderr'], '.2g')}"
        lines.append(
            f"  {NAMES[r['regime']]:<11} {r['t_start']:>11.6g} {r['duration']:>10.3g} "
            f"{r['time_to_singularity_at_start']:>10.3g} {r['impacts']['rim']:>7} "
            f"{r['impacts']['bump']:>7} {_g(r['tilt_start']):>10} {_g(r['tilt_end']):>10} {c:>14}"
        )
    lines += [
        "",
        f"  bumps first act at t = {_g(tk['first_bump_t'], '.6g')}, "
        f"tilt {_g(tk['first_bump_tilt'])}"
        f" = {_g(tk['first_bump_tilt_over_delta_a'])} Delta/a "
        f"(face reaches a bump at Delta/(a - b) = {_g(tk['face_reach_tilt'])})",
        f"  rim last acts at t = {_g(tk['last_rim_t'], '.6g')}, tilt {_g(tk['last_rim_tilt'])}"
        f" = {_g(tk['last_rim_tilt_over_delta_a'])} Delta/a",
        f"  from the first bump to the end: {_g(tk['time_from_first_bump_to_end'])} s "
        "(paper: tilt ~ Delta/d, during the last 0.1 ... 1 s)",
    ]
    return "\n".join(lines)
