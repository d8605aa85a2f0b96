"""Type stubs for the Rust extension ``contactlab._core`` (hand-written)."""

from typing import Any, final

import numpy as np
import numpy.typing as npt

__version__: str

_F = npt.NDArray[np.float64]

@final
class MasingCore:
    @staticmethod
    def exponential(h0: float, ac: float, scale: float) -> MasingCore: ...
    @staticmethod
    def tabulated(x_points: _F, f_points: _F, scale: float) -> MasingCore: ...
    def fresh(self, anchored: bool | None = None) -> MasingCore: ...
    def push(self, x: _F, out: _F | None = None, threads: int = 1, piece: int = ...) -> _F: ...
    def cycles(self, x: _F) -> dict[str, np.ndarray]: ...
    def reset(self) -> None: ...
    def get_state(self) -> _F: ...
    def set_state(self, state: _F) -> None: ...
    def backbone(self, u: _F) -> _F: ...
    def slope(self, u: _F) -> _F: ...
    def chord_area(self, u: _F) -> _F: ...
    @property
    def scale(self) -> float: ...

def loop_area(x: _F, f: _F) -> float: ...
def simd_level() -> str: ...

@final
class ReversalDetector:
    def __new__(cls, centre: float, threshold: float) -> ReversalDetector: ...
    def push(self, x: _F, value: _F | None = None) -> dict[str, np.ndarray]: ...
    def open(self) -> dict[str, np.ndarray]: ...
    @property
    def count(self) -> int: ...

@final
class PhaseFold:
    def __new__(cls, n_bins: int, n_cycles: int) -> PhaseFold: ...
    def push(self, t: _F, x: _F, f: _F, offset: int, knot_t: _F, knot_phase: _F) -> None: ...
    def sums(self, cells: bool = True) -> dict[str, np.ndarray]: ...
    def spread(self) -> dict[str, np.ndarray]: ...

@final
class WindowFold:
    def sums(self) -> dict[str, np.ndarray]: ...
    def spread(self) -> dict[str, np.ndarray]: ...
    def cycles(self) -> dict[str, np.ndarray]: ...

def fold_window(
    t: _F,
    x: _F,
    f: _F,
    knot_t: _F,
    knot_phase: _F,
    n_bins: int,
    n_cycles: int,
    edges: _F,
    scan: WindowScan | None = None,
) -> WindowFold: ...

@final
class WindowScan:
    @property
    def clean(self) -> bool: ...
    @property
    def order_stats(self) -> _F: ...

def detrend_pair_scan_into(
    t: _F,
    tm: float,
    f: _F,
    slope_f: float,
    x: _F,
    slope_x: float,
    out_f: _F,
    out_x: _F,
    ranks: list[int],
) -> WindowScan: ...
def loop_areas(x: _F, f: _F, bounds: list[int]) -> _F: ...
def fit_steady_loop(
    x: _F,
    f: _F,
    w: _F,
    bin_var: _F | None,
    prior: tuple[float | None, float | None, float, float] | None,
    setup: tuple[list[float], list[bool], list[float], list[float], list[float]],
    tol: tuple[float, float, float, float],
    max_nfev: int,
) -> tuple[list[float], int, int]: ...
def period_means(t: _F, v: _F, edges: _F) -> _F: ...
def period_means_pair(t: _F, f: _F, x: _F, edges: _F) -> tuple[_F, _F]: ...
def order_stats(x: _F, ranks: list[int]) -> _F: ...
def monotone_path(x: _F, edges: npt.NDArray[np.int64]) -> _F: ...
def detrend_pair(
    t: _F, tm: float, f: _F, slope_f: float, x: _F, slope_x: float
) -> tuple[_F, _F]: ...
def detrend_pair_into(
    t: _F, tm: float, f: _F, slope_f: float, x: _F, slope_x: float, out_f: _F, out_x: _F
) -> None: ...
def loop_area_sensitivity(x: _F, f: _F, bounds: list[int]) -> tuple[_F, _F]: ...

@final
class CycleTracker:
    def __new__(cls) -> CycleTracker: ...
    def push(
        self, t: _F, x: _F, f: _F, drive: _F, offset: int, low: float, high: float
    ) -> dict[str, np.ndarray]: ...

@final
class CycleStream:
    def __new__(cls) -> CycleStream: ...
    def push(
        self, t: _F, x: _F, f: _F, drive: _F, offset: int, low: float, high: float
    ) -> dict[str, np.ndarray]: ...
    def push_sampled(
        self,
        t0: float,
        dt: float,
        x: _F,
        f: _F,
        drive: _F,
        offset: int,
        low: float,
        high: float,
    ) -> dict[str, np.ndarray]: ...

def branch_memory(x: _F) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
def force_many(
    models: list[MasingCore],
    xs: list[_F],
    threads: int,
    outs: list[_F] | None = None,
    cpu_times: bool = False,
    piece: int = ...,
) -> tuple[list[_F], list[dict[str, Any]]]: ...
def force_repeat(
    model: MasingCore, x: _F, jobs: int, repeats: int, threads: int
) -> list[dict[str, Any]]: ...
def signature_positions(
    block: npt.NDArray[np.uint8], needles: list[bytes], starts_below: int, offset: int
) -> list[npt.NDArray[np.int64]]: ...
def fill_time(out: _F, t0: float, dt: float, offset: int) -> None: ...
def finite_min_max(v: _F) -> tuple[bool, float, float]: ...

# --- normal contact (contactlab.normal) ---
def normal_simulate(
    t: _F,
    p: _F,
    law: str,
    coeffs: _F,
    psi: float,
    omega: float,
    delta0: float,
    rtol: float,
    atol: float,
    interp: str = "cubic",
    dpdt: _F | None = None,
    first_step: float | None = None,
    max_steps: int = 0,
    method: str = "auto",
) -> dict[str, object]: ...
def normal_simulate_grid(
    t: _F,
    p: _F,
    law: str,
    coeffs: _F,
    psi: float,
    omega: float,
    delta0: float,
    substeps: int,
    tol: float,
    dpdt: _F | None = None,
) -> dict[str, object]: ...
def normal_equilibrium(law: str, coeffs: _F, psi: float, omega: float, p: float) -> float: ...
def kv_analytic(
    k: float, psi: float, omega: float, pa: float
) -> tuple[float, float, float, float]: ...
def kv_steady_state(k: float, psi: float, omega: float, pa: float, t: _F) -> tuple[_F, _F]: ...
def poly_fit(x: _F, y: _F, degree: int, weights: _F | None = None) -> _F: ...
def poly_roots_in(c: _F, lo: float, hi: float) -> _F: ...
def poly_min_on(c: _F, lo: float, hi: float) -> tuple[float, float]: ...
def fold_cycles(x: _F, start: float, period: float, n_cycles: int, n_bins: int) -> _F: ...

# --- structures with joints (contactlab.structure) ---
def structure_simulate(
    n: int,
    m: _F,
    c: _F,
    k: _F,
    joints: list[tuple[str, int, int, _F, _F, _F]],
    t: _F,
    x0: _F,
    v0: _F,
    force: _F | None = None,
    base: _F | None = None,
    base_velocity: _F | None = None,
    kr: _F | None = None,
    cr: _F | None = None,
    rtol: float = 1e-10,
    max_iter: int = 30,
    outputs: list[str] | None = None,
) -> dict[str, object]: ...

# --- joint laws driven by displacement (contactlab.joints) ---
_LawSpec = tuple[str, list[float], list[Any]]

@final
class JointOperatorCore:
    def __new__(cls, spec: _LawSpec, x0: float) -> JointOperatorCore: ...
    def push(self, t: _F | None, x: _F) -> _F: ...
    def reset(self) -> None: ...
    @property
    def rate_dependent(self) -> bool: ...
    def copy(self) -> JointOperatorCore: ...

def joint_force_sens(spec: _LawSpec, t: _F | None, x: _F, x0: float) -> tuple[_F, _F]: ...
def joint_has_sens(spec: _LawSpec) -> bool: ...
