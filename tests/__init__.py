"""The test suite (a regular package, so that no installed top-level `tests` package,
such as the one dartpy 6.20 ships, shadows it)."""
