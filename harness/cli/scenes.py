"""`harness scenes`: the built-in scenes, one line each."""

from __future__ import annotations


def register(sub) -> None:
    sub.add_parser(
        "scenes",
        help="list built-in scenes",
        description="The built-in scenes (usable by name as SCENE), one line each.",
    ).set_defaults(func=run)


def run(args) -> int:
    from ..scenes import list_builtin
    from ..text import terminal_safe

    for name, desc in list_builtin():
        print(terminal_safe(f"{name:24s} {desc}"))
    return 0
