"""Normal-contact models driven by a sampled pressure (Konowalski 2009, eqs. 8-17).

- :class:`KelvinVoigt`: ``p = k δ + h δ'`` with ``h = ψ k / (2π ω)`` (eqs. 8, 13) and the
  analytic steady state under ``pa sin ω t``: ``K = (pa/k) / sqrt(1 + (ψ/2π)²)``,
  ``φ = arctan(ψ/2π)`` (eqs. 14-15).
- :class:`NonlinearContact`: eq. 17, ``p = k_s δ + (ψ k_s / (2π ω)) δ'`` with ``k_s`` a
  polynomial of δ (eq. 6) or of the dynamic pressure p (eq. 16).

Both are solved as ``δ' = (2π ω / ψ)(p / k_s − δ)`` by the Rust core, stepping sample to
sample over a cubic-Hermite or linear continuation of p between samples: Taylor series of
adaptive order in each interval (error-controlled), RODAS4 (an L-stable Rosenbrock method)
where an interval is stiff. ω is the angular frequency at which ψ holds; for a
pressure that is not a single sine it must still be given.

:meth:`~_ContactModel.simulate_grid` is the fast route for a well-sampled record: a
fixed-grid exponential integrator on the samples' own times (the stiff decay exact, the
quasi-static displacement ``p / k_s`` continued by cubic Hermite interpolation over each
step), several times faster than the adaptive solve and within 1e-4 of the displacement
range of it at 128 or more steps per period of the fastest excitation (exact for a constant
stiffness).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import _core
from .._arrays import as_1d, positive
from ..errors import ContactLabWarning, InputError
from . import paper as _paper

#: default cap on the ODE's step attempts: this many per sample, plus AUTO_STEPS_BASE (a
#: record takes a few per sample; an absurd model, e.g. a stiffness of -1e300, otherwise ran
#: for minutes on two samples: found by the kernels fuzz target)
AUTO_STEPS_PER_SAMPLE = 20_000
AUTO_STEPS_BASE = 100_000

if TYPE_CHECKING:
    from .loop import LoopResult


@dataclass
class OdeResult:
    """Outcome of :meth:`simulate`, in the manner of scipy's ``OdeResult``.

    ``t``, ``delta`` (m) and ``velocity`` (m/s, the model's δ' at the samples) hold the samples
    reached; on failure (``success`` False) they stop where the solver stopped.
    """

    t: np.ndarray
    delta: np.ndarray
    velocity: np.ndarray
    success: bool
    status: int
    message: str
    nfev: int
    njev: int
    nlu: int
    n_steps: int
    n_rejected: int

    @property
    def y(self) -> np.ndarray:
        """``delta`` as a (1, n) array, like ``solve_ivp``."""
        return self.delta[np.newaxis, :]

    @property
    def response(self) -> np.ndarray:
        """``delta``: the main output, as :class:`contactlab.simulation.SimulatedResponse`
        names it."""
        return self.delta

    def __repr__(self) -> str:
        return (
            f"OdeResult(success={self.success}, status={self.status}, n={self.t.size}, "
            f"n_steps={self.n_steps}, n_rejected={self.n_rejected}, nfev={self.nfev}, "
            f"message={self.message!r})"
        )


class _ContactModel:
    """Common driver: pressure handling, tolerances, initial state, result wrapping."""

    psi: float
    omega: float
    p0: float | None
    _law: str
    _coeffs: np.ndarray

    def _delta_scale(self, pmax: float) -> float:
        raise NotImplementedError

    def _check_pressure(self, pd: np.ndarray) -> None:
        """Model-specific checks of the dynamic pressure (override)."""

    def _check_solution(self, delta: np.ndarray) -> None:
        """Model-specific checks of the solution (override)."""

    def equilibrium(self, p: float) -> float:
        """Displacement (m) in equilibrium with a constant dynamic pressure ``p`` (Pa)."""
        return float(_core.normal_equilibrium(self._law, self._coeffs, self.psi, self.omega, p))

    def simulate(
        self,
        t: Any,
        p: Any,
        *,
        dpdt: Any = None,
        p0: float | None = None,
        delta0: float | str = "equilibrium",
        rtol: float = 1e-8,
        atol: float | None = None,
        interp: str = "cubic",
        first_step: float | None = None,
        max_steps: int | None = None,
        method: str = "auto",
    ) -> OdeResult:
        """Displacement response δ(t) to the sampled pressure ``p(t)``.

        Parameters
        ----------
        t, p : array_like
            Sample times (s, strictly increasing) and pressure (Pa).
        dpdt : array_like, optional
            Exact dp/dt at the samples (used for the cubic continuation instead of finite
            differences, e.g. for a synthetic sine).
        p0 : float, optional
            Static pressure subtracted from ``p`` (default: the model's ``p0``; if neither is
            set, ``p`` is taken as the dynamic pressure).
        delta0 : float or "equilibrium"
            δ at ``t[0]`` (m); default the equilibrium under ``p(t[0])``.
        rtol, atol : float
            Local error tolerance ``|err| <= atol + rtol |δ|``; ``atol`` defaults to
            ``rtol`` times the displacement scale ``max|p| / k_s(0)``.
        interp : {"cubic", "linear"}
            Continuation of p between samples (cubic Hermite with ``numpy.gradient`` slopes,
            or straight lines).
        first_step, max_steps :
            First trial step (s) and a cap on step attempts (0: none; default
            ``AUTO_STEPS_PER_SAMPLE`` per sample plus ``AUTO_STEPS_BASE``, so that a stiff
            or absurd model ends with ``success=False`` and a message instead of running
            for minutes: an ordinary record takes a few steps per sample).
        method : {"auto", "rodas4"}
            ``"auto"``: each sample interval by Taylor-series steps of adaptive order (the
            interval's forcing is one cubic, so the series is exact up to its truncation,
            which is kept below the tolerance), RODAS4 where the interval is stiff
            (``2π ω Δt / ψ`` above 256) or the series does not converge; ``"rodas4"``:
            RODAS4 throughout.

        Returns
        -------
        OdeResult
        """
        tv = as_1d(t, "t")
        pv = as_1d(p, "p")
        if tv.size != pv.size:
            raise InputError(f"t has {tv.size} samples but p has {pv.size}")
        if tv.size < 2:
            raise InputError("at least two samples are needed")
        base = self.p0 if p0 is None else float(p0)
        pd = pv - base if base else pv
        if base and np.min(pv) < 0:
            warnings.warn(
                "the total pressure becomes negative: the joint would separate, which the "
                "model does not describe",
                ContactLabWarning,
                stacklevel=2,
            )
        self._check_pressure(pd)
        dv = None if dpdt is None else as_1d(dpdt, "dpdt")
        if dv is not None and dv.size != tv.size:
            raise InputError(f"t has {tv.size} samples but dpdt has {dv.size}")
        rtol, atol, d0, max_steps = self._solver_settings(
            pd, tv.size, rtol, atol, delta0, interp, max_steps, method
        )
        r = _core.normal_simulate(
            tv,
            np.ascontiguousarray(pd),
            self._law,
            self._coeffs,
            self.psi,
            self.omega,
            d0,
            rtol,
            atol,
            interp,
            dv,
            first_step,
            int(max_steps),
            method,
        )
        n_out = int(r.n_out)
        res = OdeResult(
            t=tv[:n_out],
            delta=r.delta,
            velocity=r.velocity,
            success=r.status == 0,
            status=int(r.status),
            message=str(r.message),
            nfev=int(r.nfev),
            njev=int(r.njev),
            nlu=int(r.nlu),
            n_steps=int(r.n_accepted),
            n_rejected=int(r.n_rejected),
        )
        if not res.success:
            res.message += self._failure_hint(res.delta)
        self._check_solution(res.delta)
        return res

    def _solver_settings(
        self,
        pd: np.ndarray,
        n: int,
        rtol: float,
        atol: float | None,
        delta0: float | str,
        interp: str,
        max_steps: int | None,
        method: str,
    ) -> tuple[float, float, float, int]:
        """:meth:`simulate`'s tolerances, start and options checked: ``(rtol, atol, δ0,
        max_steps)`` for ``n`` samples of the dynamic pressure ``pd``."""
        rtol = positive(rtol, "rtol")
        if atol is None:
            atol = rtol * self._delta_scale(float(np.max(np.abs(pd))))
        atol = positive(atol, "atol")
        if isinstance(delta0, str):
            if delta0 != "equilibrium":
                raise InputError(f"delta0 must be a number or 'equilibrium', got {delta0!r}")
            d0 = self.equilibrium(float(pd[0]))
        else:
            d0 = float(delta0)
            if not math.isfinite(d0):
                raise InputError(f"delta0 must be finite, got {delta0}")
        if interp not in ("cubic", "linear"):
            raise InputError(f"interp must be 'cubic' or 'linear', got {interp!r}")
        if max_steps is None:
            max_steps = AUTO_STEPS_PER_SAMPLE * n + AUTO_STEPS_BASE
        if max_steps < 0:
            raise InputError(f"max_steps must be >= 0, got {max_steps}")
        if method not in ("auto", "rodas4"):
            raise InputError(f"method must be 'auto' or 'rodas4', got {method!r}")
        return rtol, atol, d0, int(max_steps)

    def _failure_hint(self, delta: np.ndarray) -> str:
        """Extra explanation appended to a failed solve's message (override)."""
        return ""

    def simulate_grid(
        self,
        t: Any,
        p: Any,
        *,
        p0: float | None = None,
        delta0: float | str = "equilibrium",
        substeps: int = 1,
        tol: float | None = None,
        dpdt: Any = None,
    ) -> OdeResult:
        """Displacement response on the samples' own grid (fixed steps, no error control).

        Each sample interval is cut into ``substeps`` equal steps (more where the start from
        ``delta0`` decays, so that start-up transient is followed). A step integrates the
        stiff decay exactly and continues the quasi-static displacement ``n = p / k_s``
        (``p`` the cubic Hermite continuation :meth:`simulate` uses) by the cubic Hermite
        interpolant of its values and rates at the step's ends; its local error is about
        ``(Δt ω)⁴ / 384`` of the displacement for a step ``Δt``. For a constant stiffness
        the result is the exact response to that continuation. Use :meth:`simulate` (error
        control) for records with fewer than about 128 steps per period of their fastest
        content, or when the response may reach ``k_s = 0`` (an implicit step can step over
        such a point between samples).

        Parameters
        ----------
        t, p, p0, delta0 :
            As in :meth:`simulate` (the cubic continuation with ``numpy.gradient`` slopes).
        substeps : int
            Equal steps per sample interval (1 to 2**20).
        tol : float, optional
            Absolute tolerance (m) of each step's Newton iteration; default ``1e-12`` of
            the displacement scale ``max|p| / k_s(0)``.
        dpdt : array_like, optional
            The pressure's slopes at the samples (Pa/s) for the cubic continuation, instead
            of ``numpy.gradient`` slopes (e.g. known at a higher rate than ``t``).

        Returns
        -------
        OdeResult
            ``n_steps`` is the number of steps; ``njev``, ``nlu`` and ``n_rejected`` are 0.

        Examples
        --------
        >>> import numpy as np
        >>> from contactlab.normal import NonlinearContact
        >>> m = NonlinearContact(k_s_delta=[1.3e12, 0.0, 2.0e25], psi=0.09, omega=1.0)
        >>> t = np.arange(4 * 256 + 1) * (2 * np.pi / 256)
        >>> p = 0.4e6 * np.sin(t)
        >>> a, b = m.simulate(t, p, rtol=1e-10), m.simulate_grid(t, p)
        >>> bool(np.max(np.abs(a.delta - b.delta)) < 1e-6 * np.ptp(a.delta))
        True
        """
        tv = as_1d(t, "t")
        pv = as_1d(p, "p")
        if tv.size != pv.size:
            raise InputError(f"t has {tv.size} samples but p has {pv.size}")
        if tv.size < 2:
            raise InputError("at least two samples are needed")
        base = self.p0 if p0 is None else float(p0)
        pd = pv - base if base else pv
        self._check_pressure(pd)
        if isinstance(substeps, bool) or not isinstance(substeps, int | np.integer):
            raise InputError(f"substeps must be an integer, got {substeps!r}")
        if not 1 <= substeps <= 2**20:
            raise InputError(f"substeps must be between 1 and 2**20, got {substeps}")
        if tol is None:
            tol = 1e-12 * self._delta_scale(float(np.max(np.abs(pd))))
        tol = positive(tol, "tol")
        if isinstance(delta0, str):
            if delta0 != "equilibrium":
                raise InputError(f"delta0 must be a number or 'equilibrium', got {delta0!r}")
            d0 = self.equilibrium(float(pd[0]))
        else:
            d0 = float(delta0)
            if not math.isfinite(d0):
                raise InputError(f"delta0 must be finite, got {delta0}")
        r = _core.normal_simulate_grid(
            tv,
            np.ascontiguousarray(pd),
            self._law,
            self._coeffs,
            self.psi,
            self.omega,
            d0,
            int(substeps),
            tol,
            None if dpdt is None else np.ascontiguousarray(as_1d(dpdt, "dpdt")),
        )
        n_out = int(r.n_out)
        res = OdeResult(
            t=tv[:n_out],
            delta=r.delta,
            velocity=r.velocity,
            success=r.status == 0,
            status=int(r.status),
            message=str(r.message),
            nfev=int(r.nfev),
            njev=0,
            nlu=0,
            n_steps=int(r.n_accepted),
            n_rejected=0,
        )
        if not res.success:
            res.message += self._failure_hint(res.delta)
        self._check_solution(res.delta)
        return res


class KelvinVoigt(_ContactModel):
    """Linear Kelvin-Voigt contact ``p = k δ + h δ'``, ``h = ψ k / (2π ω)`` (eqs. 8, 13).

    Parameters
    ----------
    k : float
        Stiffness, Pa/m.
    psi : float
        Energy dissipation coefficient ψ = E_d / E_pu (eq. 3), > 0.
    omega : float
        Angular frequency (rad/s) at which ψ holds.
    p0 : float, optional
        Static pressure (Pa) that :meth:`simulate` subtracts from the pressure it is given.

    Examples
    --------
    >>> import numpy as np
    >>> from contactlab.normal import KelvinVoigt
    >>> kv = KelvinVoigt(k=1.206e12, psi=0.0887, omega=1.0)
    >>> t = np.linspace(0, 6 * 2 * np.pi, 6 * 512 + 1)
    >>> res = kv.simulate(t, 0.4e6 * np.sin(t), dpdt=0.4e6 * np.cos(t), rtol=1e-10)
    >>> d_ss, _ = kv.steady_state(t, 0.4e6)
    >>> bool(np.max(np.abs(res.delta[1024:] - d_ss[1024:])) < 1e-8 * kv.amplitude(0.4e6))
    True
    """

    def __init__(self, k: float, psi: float, omega: float, *, p0: float | None = None) -> None:
        self.k = positive(k, "k")
        self.psi = positive(psi, "psi")
        self.omega = positive(omega, "omega")
        self.p0 = None if p0 is None else float(p0)
        self._law = "constant"
        self._coeffs = np.array([self.k])

    def __repr__(self) -> str:
        return f"KelvinVoigt(k={self.k:.6g}, psi={self.psi:.6g}, omega={self.omega:.6g})"

    @classmethod
    def from_loop(
        cls, result: LoopResult, *, stiffness: str = "tan", psi: str = "eq7"
    ) -> KelvinVoigt:
        """Linear model from a loop analysis: ``k = k_tan`` (eq. 4) or ``k_sec`` (eq. 5),
        ``ψ`` by eq. 7 (default) or eq. 3."""
        k = {"tan": result.k_tan, "sec": result.k_sec}.get(stiffness)
        if k is None:
            raise InputError(f"stiffness must be 'tan' or 'sec', got {stiffness!r}")
        ps = {"eq7": result.psi, "eq3": result.psi_kv}.get(psi)
        if ps is None:
            raise InputError(f"psi must be 'eq7' or 'eq3', got {psi!r}")
        return cls(k, ps, result.omega, p0=result.p0)

    @property
    def h(self) -> float:
        """Damping coefficient ``ψ k / (2π ω)``, Pa·s/m (eq. 13)."""
        return float(_core.kv_analytic(self.k, self.psi, self.omega, 1.0)[0])

    @property
    def phase(self) -> float:
        """Phase lag φ = arctan(ψ / 2π) of δ behind p, rad (eq. 15)."""
        return float(_core.kv_analytic(self.k, self.psi, self.omega, 1.0)[2])

    def amplitude(self, pa: float) -> float:
        """Steady displacement amplitude K under ``pa sin ω t``, m (eq. 14)."""
        return float(_core.kv_analytic(self.k, self.psi, self.omega, float(pa))[1])

    def loop_energy(self, pa: float) -> float:
        """Dissipated energy per cycle (ellipse area π pa K sin φ), J/m²."""
        return float(_core.kv_analytic(self.k, self.psi, self.omega, float(pa))[3])

    def analytic(self, pa: float) -> dict[str, float]:
        """The analytic steady state under ``pa sin ω t``: damping ``h`` (eq. 13), amplitude
        ``K`` (eqs. 11, 14), phase lag ``phi`` (eqs. 12, 15) and loop energy ``E_d``."""
        h, k_amp, phi, e_d = _core.kv_analytic(self.k, self.psi, self.omega, float(pa))
        return {"h": h, "K": k_amp, "phi": phi, "E_d": e_d}

    def steady_state(self, t: Any, pa: float) -> tuple[np.ndarray, np.ndarray]:
        """Steady δ(t) = K sin(ω t − φ) and δ'(t) under ``p = pa sin ω t`` (eqs. 10-15)."""
        tv = as_1d(t, "t")
        d, v = _core.kv_steady_state(self.k, self.psi, self.omega, float(pa), tv)
        return np.asarray(d), np.asarray(v)

    def _delta_scale(self, pmax: float) -> float:
        return max(pmax, 1e-300) / self.k


class NonlinearContact(_ContactModel):
    """Konowalski's nonlinear contact (eq. 17): ``p = k_s δ + (ψ k_s / (2π ω)) δ'``.

    Give exactly one stiffness law:

    - ``k_s_delta = [a1, a2, a3, a4]``: ``k_s(δ) = a1 + a2 δ + a3 δ² + a4 δ³`` (eq. 6; SI,
      ascending; the centre curve's coefficients without a0, ``LoopResult.k_s_delta``);
    - ``b = [b1, b2, b3, b4]``: ``k_s(p) = b1 p³ + b2 p² + b3 p + b4`` in the paper's order
      (eq. 16; p the dynamic pressure in Pa, k_s in Pa/m), e.g. from
      :func:`fit_pressure_stiffness`.

    Parameters
    ----------
    k_s_delta, b : sequence of float
        The stiffness polynomial (see above); any length ≥ 1.
    psi : float
        Energy dissipation coefficient (eq. 7), > 0.
    omega : float
        Angular frequency (rad/s) at which ψ holds.
    p0 : float, optional
        Static pressure subtracted by :meth:`simulate` (see there).
    delta_range : (float, float), optional
        δ range over which ``k_s_delta`` was identified (e.g. the loop's δ_min, δ_max): k_s
        must be positive there, and :meth:`simulate` warns when δ leaves it by more than 10 %.

    Examples
    --------
    >>> import numpy as np
    >>> from contactlab.normal import NonlinearContact
    >>> m = NonlinearContact(k_s_delta=[1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30],
    ...                      psi=0.09, omega=1.0)
    >>> t = np.arange(4 * 256 + 1) * (2 * np.pi / 256)
    >>> res = m.simulate(t, 0.4e6 * np.sin(t))
    >>> res.success, round(float(res.delta.max() * 1e6), 2)
    (True, 0.22)
    """

    def __init__(
        self,
        k_s_delta: Any = None,
        psi: float | None = None,
        omega: float | None = None,
        *,
        b: Any = None,
        p0: float | None = None,
        delta_range: tuple[float, float] | None = None,
    ) -> None:
        if (k_s_delta is None) == (b is None):
            raise InputError("give exactly one of k_s_delta (eq. 6) and b (eq. 16)")
        if psi is None or omega is None:
            raise InputError("psi and omega are required")
        self.psi = positive(psi, "psi")
        self.omega = positive(omega, "omega")
        self.p0 = None if p0 is None else float(p0)
        self.delta_range: tuple[float, float] | None = None
        if k_s_delta is not None:
            c = as_1d(k_s_delta, "k_s_delta")
            self._law = "delta"
            self._coeffs = c.copy()
            self.k_s_delta: np.ndarray | None = c.copy()
            self.b: np.ndarray | None = None
            if c[0] <= 0:
                raise InputError(f"k_s(0) = a1 must be > 0, got {c[0]}")
        else:
            bb = as_1d(b, "b")
            self._law = "pressure"
            self._coeffs = np.ascontiguousarray(bb[::-1])
            self.b = bb.copy()
            self.k_s_delta = None
            if bb[-1] <= 0:
                raise InputError(f"k_s(p = 0) = b4 must be > 0, got {bb[-1]}")
        if delta_range is not None:
            lo, hi = (float(v) for v in delta_range)
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise InputError(f"delta_range must be finite with lo < hi, got {delta_range}")
            self.delta_range = (lo, hi)
            if self._law == "delta":
                kmin, at = _core.poly_min_on(self._coeffs, lo, hi)
                if kmin <= 0:
                    raise InputError(
                        "k_s(δ) is not positive over delta_range: "
                        f"{kmin:.4g} Pa/m at δ = {at:.4g} m"
                    )

    def __repr__(self) -> str:
        law = (
            f"k_s_delta={self.k_s_delta.tolist()}"
            if self.k_s_delta is not None
            else (f"b={self.b.tolist() if self.b is not None else None}")
        )
        return f"NonlinearContact({law}, psi={self.psi:.6g}, omega={self.omega:.6g})"

    @classmethod
    def from_loop(cls, result: LoopResult, *, psi: str = "eq7") -> NonlinearContact:
        """Model with ``k_s(δ)`` from a loop analysis (eq. 6) and ψ by eq. 7 (or eq. 3)."""
        ps = {"eq7": result.psi, "eq3": result.psi_kv}.get(psi)
        if ps is None:
            raise InputError(f"psi must be 'eq7' or 'eq3', got {psi!r}")
        return cls(
            k_s_delta=result.k_s_delta,
            psi=ps,
            omega=result.omega,
            p0=result.p0,
            delta_range=(result.delta_min, result.delta_max),
        )

    def k_s(self, delta: Any = None, p: Any = None) -> Any:
        """Secant stiffness (Pa/m) at displacement ``delta`` (eq. 6) or pressure ``p`` (eq. 16)."""
        if self._law == "delta":
            if delta is None:
                raise InputError("this model's k_s depends on delta")
            return np.polynomial.polynomial.polyval(np.asarray(delta, float), self._coeffs)
        if p is None:
            raise InputError("this model's k_s depends on p")
        return np.polynomial.polynomial.polyval(np.asarray(p, float), self._coeffs)

    def k_s_display(self) -> list[float]:
        """The stiffness coefficients in the paper's units (MPa/µm with δ in µm or p in MPa)."""
        if self.k_s_delta is not None:
            return _paper.ks_delta_to_display(self.k_s_delta).tolist()
        assert self.b is not None
        return _paper.ks_pressure_to_display(self.b).tolist()

    def _delta_scale(self, pmax: float) -> float:
        k0 = float(self._coeffs[0])
        return max(pmax, 1e-300) / k0

    def _check_pressure(self, pd: np.ndarray) -> None:
        if self._law != "pressure":
            return
        k = np.polynomial.polynomial.polyval(pd, self._coeffs)
        bad = k <= 0
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(
                f"k_s(p) is not positive at sample {i} (p = {pd[i]:.6g} Pa, k_s = {k[i]:.4g} Pa/m)"
            )

    def _failure_hint(self, delta: np.ndarray) -> str:
        if self._law != "delta" or delta.size == 0:
            return ""
        span = 4 * float(np.max(np.abs(delta)))
        roots = np.asarray(_core.poly_roots_in(self._coeffs, -span, span)) if span > 0 else []
        if len(roots) == 0:
            return ""
        d = float(roots[np.argmin(np.abs(roots - delta[-1]))])
        return (
            f" k_s(δ) vanishes at δ = {d:.4g} m next to the response (last δ = "
            f"{delta[-1]:.4g} m): the stiffness polynomial is not positive over the "
            "response's range, so δ runs away."
        )

    def _check_solution(self, delta: np.ndarray) -> None:
        if self.delta_range is None or delta.size == 0:
            return
        lo, hi = self.delta_range
        margin = 0.1 * (hi - lo)
        if delta.min() < lo - margin or delta.max() > hi + margin:
            warnings.warn(
                f"δ leaves the range k_s(δ) was identified on ([{lo:.4g}, {hi:.4g}] m): "
                f"the polynomial is extrapolated (δ in [{delta.min():.4g}, {delta.max():.4g}] m)",
                ContactLabWarning,
                stacklevel=3,
            )
