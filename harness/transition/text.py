"""Terminal text of `harness transition`."""

from __future__ import annotations

import textwrap
from typing import Any

from ..text import WIDTH, table

NAMES = {"rim_only": "rim only", "mixed": "mixed", "bumps_only": "bumps only"}


def _g(x, fmt: str = ".3g") -> str:
    return "-" if x is None else format(x, fmt)


def format_transition(doc: dict[str, Any]) -> str:
    """The scene, one row per regime (when, how long, how many impacts of each kind), the
    tilt and energy exponent of each regime, and when the bumps take over; within 100
    columns (statuses wrapped)."""
    tk = doc["takeover"]
    head = f"transition: {doc['scene']} on {doc['engine']}: {doc['status']} ({doc['message']})"
    lines = [
        *textwrap.wrap(head, WIDTH, subsequent_indent="  "),
        f"  n = {doc['n']}, ρ = {doc['gyration']:g}, γ = {doc['restitution']:g}, "
        f"a = {doc['radius']:g} m, g = {doc['gravity']:g} m/s²; bumps of height "
        f"Δ = {_g(tk['delta'])} m",
        f"  (Δ/a = {_g(tk['delta_over_a'])}, Δ/d = {_g(tk['delta_over_d'])}); start tilt "
        f"{_g(doc['initial_tilt'])} rad; end t_f = {_g(doc['t_f'], '.10g')} s "
        f"({doc['t_f_source']})",
        "",
    ]
    regimes = doc["regimes"]
    lines.append(
        table(
            [
                [
                    NAMES[r["regime"]],
                    f"{r['t_start']:.6g}",
                    f"{r['duration']:.3g}",
                    f"{r['time_to_singularity_at_start']:.3g}",
                    str(r["impacts"]["rim"]),
                    str(r["impacts"]["bump"]),
                ]
                for r in regimes
            ],
            ["regime", "from t [s]", "lasting [s]", "t_f − t [s]", "rim impacts", "bump impacts"],
            align="lrrrrr",
        )  # fmt: skip
    )
    lines += ["", _tilt_table(regimes), ""]
    lines += [
        f"  bumps first act at t = {_g(tk['first_bump_t'], '.6g')} s, "
        f"tilt {_g(tk['first_bump_tilt'])} rad"
        f" = {_g(tk['first_bump_tilt_over_delta_a'])} Δ/a "
        f"(the face reaches a bump at Δ/(a − b) = {_g(tk['face_reach_tilt'])} rad)",
        f"  rim last acts at t = {_g(tk['last_rim_t'], '.6g')} s, tilt "
        f"{_g(tk['last_rim_tilt'])} rad = {_g(tk['last_rim_tilt_over_delta_a'])} Δ/a",
        f"  from the first bump to the end: {_g(tk['time_from_first_bump_to_end'])} s "
        "(paper: tilt ~ Δ/d, during the last 0.1 ... 1 s)",
    ]
    return "\n".join(line for chunk in lines for line in _wrapped(chunk))


def _tilt_table(regimes: list[dict[str, Any]]) -> str:
    """Each regime's tilt at its start and end and the energy exponent c of E ~ (t_f − t)^c
    fitted over it, with its standard error."""
    rows = [
        [
            NAMES[r["regime"]],
            _g(r["tilt_start"]),
            _g(r["tilt_end"]),
            "-" if r["c"] is None else f"{r['c']:.3f}",
            _g(r["c_stderr"], ".2g"),
        ]
        for r in regimes
    ]
    header = ["regime", "tilt at start [rad]", "tilt at end [rad]", "energy exponent c", "± c"]
    return table(rows, header, align="lrrrr")


def _wrapped(text: str) -> list[str]:
    """A line of the report within WIDTH columns (tables and blank lines as they are)."""
    if "\n" in text or len(text) <= WIDTH:
        return text.splitlines() or [text]
    return textwrap.wrap(text, WIDTH, subsequent_indent="    ")
