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
        print(terminal_safe(scene_line(name, desc)))
    return 0


def scene_line(name: str, desc: str, width: int = 100) -> str:
    """'name   description', the description wrapped at `width` columns under itself."""
    import textwrap

    indent = " " * 25
    return "\n".join(
        textwrap.wrap(desc, width, initial_indent=f"{name:24s} ", subsequent_indent=indent)
    )
