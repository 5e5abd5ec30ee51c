"""The `harness` command: simulate, compare, bench, stress, analyze, sweep, record."""
