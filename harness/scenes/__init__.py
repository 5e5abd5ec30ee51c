"""Built-in scenes shipped with the package (harness/scenes/*.toml) and scene lookup."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from reference.scene import Scene, SceneError, load_scene


def builtin_dir() -> Path:
    return Path(str(resources.files("harness") / "scenes"))


def builtin_names() -> list[str]:
    return sorted(p.stem for p in builtin_dir().glob("*.toml"))


def resolve_scene(arg: str) -> Scene:
    """SCENE is a path to a scene file or the name of a built-in scene."""
    path = Path(arg)
    if path.suffix == ".toml" or path.exists():
        return load_scene(path)
    candidate = builtin_dir() / f"{arg}.toml"
    if candidate.is_file():
        return load_scene(candidate)
    raise SceneError(
        f"no scene file or built-in scene named {arg!r} (built-ins: {', '.join(builtin_names())})"
    )


def list_builtin() -> list[tuple[str, str]]:
    """(name, description) of every built-in scene, read from the files without building
    the scenes (listing needs no physics)."""
    import tomllib

    out = []
    for name in builtin_names():
        data = tomllib.loads((builtin_dir() / f"{name}.toml").read_text(encoding="utf-8"))
        out.append((name, str(data.get("description", ""))))
    return out
