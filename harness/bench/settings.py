"""The bench's settings: timesteps, the reference's accuracy settings and the truth,
the budget, the error metrics (harness.bench)."""

from __future__ import annotations

from dataclasses import dataclass

from reference.scene import Scene
from reference.simulate import ReferenceOptions, simulate
from reference.trajectory import Trajectory

from ..simulators import run_simulator

DEFAULT_DTS = (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6)
# (contact_rtol, chatter_tol), loose to tight; the last one is the truth.
REFERENCE_SETTINGS = ((1e-6, 1e-3), (1e-8, 1e-4), (1e-10, 1e-5), (1e-12, 1e-6))
TRUTH = REFERENCE_SETTINGS[-1]
# A setting is skipped when repeats × its predicted single-run time exceeds this (s).
DEFAULT_BUDGET_S = 60.0
# Errors below this are drawn (and interpolated) at this value on log axes.
ERROR_FLOOR = 1e-16
# Error metrics of the work-precision curves; the first is the headline one.
METRICS = ("energy_error_agreeing", "energy_error", "impact_time_error")
METRIC_LABELS = {
    "energy_error_agreeing": "energy error before divergence, max |E - E_ref| / E_ref(0)",
    "energy_error": "energy error over the common window, max |E - E_ref| / E_ref(0)",
    "impact_time_error": "impact time error of matched impacts, max |t - t_ref| [s]",
}


@dataclass(frozen=True)
class Setting:
    """One configuration of one simulator."""

    engine: str
    dt: float | None = None
    contact_rtol: float | None = None
    chatter_tol: float | None = None

    @property
    def label(self) -> str:
        if self.dt is not None:
            return f"dt={self.dt:g}"
        if self.contact_rtol is not None:
            return f"rtol={self.contact_rtol:g} chatter={self.chatter_tol:g}"
        return "exact"

    def run(self, scene: Scene, t_end: float) -> Trajectory:
        if self.contact_rtol is not None:
            opts = ReferenceOptions(contact_rtol=self.contact_rtol, chatter_tol=self.chatter_tol)
            return simulate(scene, t_end=t_end, options=opts)
        return run_simulator(self.engine, scene, dt=self.dt, t_end=t_end)


def reference_setting(rtol_chatter: tuple[float, float]) -> Setting:
    return Setting("reference", contact_rtol=rtol_chatter[0], chatter_tol=rtol_chatter[1])
