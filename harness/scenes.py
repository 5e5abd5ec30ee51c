"""Scene lookup for the harness: the built-in scenes live with the reference
(reference.scenes); these names are kept for the harness's callers."""

from reference.scenes import builtin_dir, builtin_names, list_builtin, resolve_scene, scene_file

__all__ = ["builtin_dir", "builtin_names", "list_builtin", "resolve_scene", "scene_file"]
