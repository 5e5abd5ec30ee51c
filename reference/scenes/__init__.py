"""The built-in scenes (reference/scenes/*.toml) and how a scene argument is found: a
path to a scene file, or the name of a built-in scene (`harness scenes` lists them)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ..scene import Scene, SceneError, load_scene_file, show_path


def load_scene(path_or_name: str | Path) -> Scene:
    """A scene from a file or the name of a built-in scene ("pentagon-bounce"),
    validated (`resolve_scene`)."""
    return resolve_scene(path_or_name)


def builtin_dir() -> Path:
    return Path(str(resources.files(__name__)))


def builtin_names() -> list[str]:
    return sorted(p.stem for p in builtin_dir().glob("*.toml"))


def resolve_scene(arg: str | Path) -> Scene:
    """SCENE is a path to a scene file or the name of a built-in scene."""
    path = scene_file(arg)
    if path is not None and path.stem in builtin_names() and not _exists(path):
        raise SceneError(
            f"scene file not found: {show_path(arg)}; the built-in scene is named "
            f"{path.stem!r} (without .toml)"
        )
    if path is None:
        raise SceneError(
            f"no scene file or built-in scene named {show_path(arg)!r} "
            f"(built-ins: {', '.join(builtin_names())})"
        )
    return load_scene_file(path)


def _exists(path: Path) -> bool:
    try:
        return path.exists()
    except (OSError, ValueError):  # name too long, a NUL character, ...: load_scene says
        return True


def scene_file(arg: str | Path) -> Path | None:
    """The file SCENE names: the path itself when it ends in .toml or exists, else the
    built-in scene of that name; None when neither (a path the system refuses, e.g. one
    too long, counts as a path: load_scene then says why it cannot be read)."""
    path = Path(arg)
    try:
        if path.suffix == ".toml" or path.exists():
            return path
        candidate = builtin_dir() / f"{arg}.toml"
        if candidate.is_file():
            return candidate
    except (OSError, ValueError):  # name too long, a NUL character, ...
        return path
    return None


def list_builtin() -> list[tuple[str, str]]:
    """(name, description) of every built-in scene, read from the files without building
    the scenes (listing needs no physics)."""
    import tomllib

    out = []
    for name in builtin_names():
        data = tomllib.loads((builtin_dir() / f"{name}.toml").read_text(encoding="utf-8"))
        out.append((name, str(data.get("description", ""))))
    return out


def as_scene(scene: Scene | str | Path) -> Scene:
    """A Scene as given, or the one a file path or built-in name gives (resolve_scene):
    every function that takes a scene takes a name too.  Anything else is refused with
    SceneError (reference.checks.run_horizon's message)."""
    if isinstance(scene, Scene):
        return scene
    if not isinstance(scene, str | Path):
        raise SceneError(
            f"a Scene, a scene file or a built-in scene name is needed, got {type(scene).__name__}"
        )
    return resolve_scene(scene)
