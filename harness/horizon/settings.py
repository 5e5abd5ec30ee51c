"""Defaults of the horizon ensembles, importable without numpy (the CLI's options)."""

DEFAULT_RUNS = 24  # members per ensemble (`--horizon-runs`)
DEFAULT_SEED = 0  # `--horizon-seed`
