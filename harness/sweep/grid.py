"""What an exponent sweep computes: its parameters, grid, random initial states and tasks.

A task is one run: grid point (i_gamma, i_rho) and sample number s.  Its initial state
is the paper's (section 4.3):

    p = (0.1 χ1, 0.1 χ2, −1),  q = (0.001 χ3, 0.001 χ4, 1),  χ uniform on [−0.5, 0.5],

with χ drawn from `numpy.random.SeedSequence(seed, spawn_key=(i_gamma, i_rho, s))`, so
a task's state depends on nothing but (seed, i_gamma, i_rho, s): not on the executor,
the order of execution, the chunking, or which tasks ran before.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

MANIFEST_VERSION = 1
# Most runs one sweep may hold.  Every task key is listed in memory (about 100 bytes each
# in Python) and every stored row is read back for the summary; at the linear model's
# 1-100 ms per run, 1e6 runs are up to a day of CPU.  Checked before anything is written.
MAX_RUNS = 1_000_000


@dataclass(frozen=True)
class SweepConfig:
    """Everything that determines a sweep's results (and nothing that does not: the
    executor, worker count and chunking are left out on purpose).  Its `to_dict()` is
    the manifest stored in the sweep directory.

    `gyration` and `restitution` are (first, last, count) as on the command line.
    `t_end` and `min_decades` apply to Trajectory engines; the linear model runs to
    the singularity and uses its own estimator (reference.linear.exponent).  `t_end`
    is a cap: the linear model's t_f reaches ~91 at γ = 0.95 from the paper's initial
    states, and fixed-step engines run to 1.5 t_lin + 0.5 (run.fixed_step_t_end).
    `dt` to fixed-step engines only."""

    n: int
    gyration: tuple[float, float, int]
    restitution: tuple[float, float, int]
    samples: int
    seed: int
    engine: str = "linear"
    dt: float | None = None
    gravity: float = 1.0
    max_impacts: int = 20000
    t_end: float = 200.0
    min_decades: float = 6.0
    impact_law: str = "paper"  # the reference's law of simultaneous impacts
    simultaneity_window: float = 0.0  # and its window (0 in manifests without the key)

    def to_dict(self) -> dict:
        d = asdict(self)
        if d["impact_law"] == "paper":  # manifests written before the keys stay valid
            del d["impact_law"]
        if d["simultaneity_window"] == 0.0:
            del d["simultaneity_window"]
        d["gyration"] = list(self.gyration)
        d["restitution"] = list(self.restitution)
        d["version"] = MANIFEST_VERSION
        return d

    @classmethod
    def from_dict(cls, d: dict) -> SweepConfig:
        d = {k: v for k, v in d.items() if k != "version"}
        d["gyration"] = tuple(d["gyration"])
        d["restitution"] = tuple(d["restitution"])
        return cls(**d)

    @property
    def rho_values(self) -> np.ndarray:
        return grid_values(*self.gyration)

    @property
    def gamma_values(self) -> np.ndarray:
        return grid_values(*self.restitution)

    @property
    def n_tasks(self) -> int:
        return self.gyration[2] * self.restitution[2] * self.samples


def config_problem(config: SweepConfig) -> str:
    """Why the sweep cannot run ('' when it can): grid values outside what a scene
    accepts (reference.scene: ρ in GYRATION_RANGE, so ρ = 0 is refused as by simulate and
    analyze; γ in [0, 1]), too many runs, no samples."""
    from reference.scene import GYRATION_RANGE, MAX_VERTICES

    lo, hi = GYRATION_RANGE
    a, b, _ = config.gyration
    if not (lo <= min(a, b) and max(a, b) <= hi):
        return (
            f"--gyration values must be in [{lo:g}, {hi:g}] (rho = 0 has no rotational "
            f"inertia; simulate and analyze refuse it too), got {a:g}:{b:g}"
        )
    a, b, _ = config.restitution
    if not (0.0 <= min(a, b) and max(a, b) <= 1.0):
        return f"--restitution values must be in [0, 1], got {a:g}:{b:g}"
    if not 2 <= config.n <= MAX_VERTICES:
        return f"--n must be in [2, {MAX_VERTICES}], got {config.n}"
    if config.samples < 1:
        return f"--samples must be >= 1, got {config.samples}"
    if config.n_tasks > MAX_RUNS:
        return (
            f"the sweep has {config.n_tasks:.3g} runs ({config.restitution[2]} gamma x "
            f"{config.gyration[2]} rho x {config.samples} samples); at most {MAX_RUNS:g}"
        )
    return ""


def default_min_decades(engine: str) -> float:
    """Decades of energy the fit window must span: 6 for the linear model (its own
    rule; it follows time-to-go in log2 and reaches 19 decades), 4 for the reference
    (its double-double clock resolves time-to-go down to ~1e-28 t_f, which for c < 1
    limits the energy it can follow to ~28 c decades), 2 for fixed-step engines, which
    cannot follow the energy much further down than a few decades at a fixed dt."""
    return {"linear": 6.0, "reference": 4.0}.get(engine, 2.0)


def grid_values(first: float, last: float, count: int) -> np.ndarray:
    """`count` values from `first` to `last` inclusive (count = 1: `first` alone)."""
    if count == 1:
        return np.array([float(first)])
    return np.linspace(float(first), float(last), int(count))


def chi(seed: int, i_gamma: int, i_rho: int, sample: int) -> np.ndarray:
    """The four uniform variables χ1..χ4 on [−0.5, 0.5] of one task."""
    ss = np.random.SeedSequence(seed, spawn_key=(i_gamma, i_rho, sample))
    return np.random.default_rng(ss).uniform(-0.5, 0.5, 4)


def initial_state(seed: int, i_gamma: int, i_rho: int, sample: int):
    """(q0, p0) of one task: q = (0.001 χ3, 0.001 χ4, 1), p = (0.1 χ1, 0.1 χ2, −1)."""
    x = chi(seed, i_gamma, i_rho, sample)
    q0 = np.array([0.001 * x[2], 0.001 * x[3], 1.0])
    p0 = np.array([0.1 * x[0], 0.1 * x[1], -1.0])
    return q0, p0


@dataclass(frozen=True)
class Chunk:
    """Samples [s for s in samples] of grid point (i_gamma, i_rho): one unit of work
    shipped to a worker (plain data, picklable)."""

    config: SweepConfig
    i_gamma: int
    i_rho: int
    samples: tuple[int, ...]

    @property
    def gamma(self) -> float:
        return float(self.config.gamma_values[self.i_gamma])

    @property
    def rho(self) -> float:
        return float(self.config.rho_values[self.i_rho])

    @property
    def label(self) -> str:
        s = self.samples
        return f"g{self.i_gamma:03d}-r{self.i_rho:03d}-s{s[0]:05d}-{s[-1]:05d}"


def all_keys(config: SweepConfig) -> list[tuple[int, int, int]]:
    """Every task key (i_gamma, i_rho, sample) of the sweep."""
    return [
        (ig, ir, s)
        for ig in range(config.restitution[2])
        for ir in range(config.gyration[2])
        for s in range(config.samples)
    ]


def default_chunk_size(engine: str) -> int:
    """Runs per unit of work: the event-driven simulators (the linear model, the
    reference) take about 1-100 ms per run, so 25 of them keep the per-task overhead
    (pickling, a Parquet part) small while a kill loses little (the reference's full
    map wrote 42,000 parts with one run each: 40 s of its 252 s); fixed-step engines
    take seconds per run, one run per task."""
    from ..simulators import is_fixed_step

    return 1 if is_fixed_step(engine) else 25


def make_chunks(config: SweepConfig, missing, chunk_size: int) -> list[Chunk]:
    """Group the missing keys by grid point into chunks of at most `chunk_size` samples,
    interleaving grid points so that slow regions of the map are spread over time."""
    by_point: dict[tuple[int, int], list[int]] = {}
    for ig, ir, s in sorted(missing):
        by_point.setdefault((ig, ir), []).append(s)
    per_point = []
    for (ig, ir), samples in by_point.items():
        per_point.append(
            [
                Chunk(config, ig, ir, tuple(samples[k : k + chunk_size]))
                for k in range(0, len(samples), chunk_size)
            ]
        )
    out = []
    depth = max((len(c) for c in per_point), default=0)
    for k in range(depth):
        out.extend(c[k] for c in per_point if k < len(c))
    return out
