"""Joint laws driven by displacement: ``F(t) = law(x(t))`` with exact non-local memory.

Every law shares one interface (:class:`JointLaw`):

- ``law.force(t, x, x0=0.0) -> F`` for a whole history (``t`` may be None for a
  rate-independent law), and ``op = law.operator(); op.push(t_chunk, x_chunk)`` for a
  recording streamed in chunks (chunked and one pass give the same forces);
- ``law.param_names``, ``law.params`` (dict), ``law.units``, ``law.bounds`` (dict of
  ``(lo, hi)``), ``law.vector`` and ``law.with_params(vector_or_dict)`` for fitters;
- bad parameters, non-finite samples and a time axis that does not strictly increase raise
  :class:`contactlab.InputError` naming the value.

Conventions: the operator starts relaxed (force 0, no history) at displacement ``x0``; the
path between samples is a straight line in time, so a rate-dependent law sees the velocity
``(x_n - x_{n-1}) / (t_n - t_{n-1})`` over each step and is integrated exactly along it (the
first sample is reached from ``x0`` quasi-statically: velocity 0 in the rate terms).
Rate-independent laws (Jenkins, Iwan, Segalman, Maxwell-slip, Dahl, Bouc-Wen, Masing) ignore
``t`` apart from checking it.

Laws (the registry :data:`LAWS` maps a lower-case name to the class):

========================  =====================================================================
``jenkins``               elastic-Coulomb: stiffness ``k`` in series with a slider ``fs``
``iwan``                  continuous Iwan model, uniform slip-force density up to ``fs_max``
``segalman``              Segalman's 4-parameter power-law Iwan model (J. Appl. Mech. 72, 2005)
``maxwell_slip``          ``N`` Jenkins elements in parallel (arrays ``k``, ``fs``)
``gms``                   generalised Maxwell-slip (Al-Bender, Lampaert & Swevers 2005)
``dahl``                  Dahl's law ``dF/dx = σ0 |1 - F/Fc sgn ẋ|^α``
``lugre``                 LuGre (bristle state, Stribeck curve, viscous term)
``bouc_wen``              Bouc-Wen in displacement-driven form
``kelvin_voigt``          ``F = k x + c ẋ``
``masing``                Masing's rules on an exponential (or any) virgin curve
``series``                laws in series (the force balance solved at every sample)
``parallel``              laws in parallel, plus a stiffness ``k`` and a viscous ``c``
``backlash``              a clearance ``gap`` in series with a law (a dead band)
========================  =====================================================================
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from . import _reference as ref

INF = math.inf


@dataclass(frozen=True)
class ParamSpec:
    """One scalar parameter: name, unit, bounds, and whether the lower bound is excluded."""

    name: str
    unit: str
    lo: float = -INF
    hi: float = INF
    open_lo: bool = False

    def check(self, value: Any, where: str) -> float:
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(
                f"{where}: parameter {self.name} must be a number, got {value!r}"
            ) from None
        if not math.isfinite(v):
            raise InputError(f"{where}: parameter {self.name} is not finite ({v})")
        if v < self.lo or (self.open_lo and v == self.lo) or v > self.hi:
            lo = "(" if self.open_lo else "["
            raise InputError(
                f"{where}: parameter {self.name} = {v} is outside {lo}{self.lo}, {self.hi}]"
            )
        return v


def _pos(name: str, unit: str) -> ParamSpec:
    return ParamSpec(name, unit, 0.0, INF, True)


def _nonneg(name: str, unit: str) -> ParamSpec:
    return ParamSpec(name, unit, 0.0, INF, False)


def _array(v: Any, name: str, where: str) -> np.ndarray:
    try:
        a = np.ascontiguousarray(np.asarray(v, dtype=float).reshape(-1))
    except (TypeError, ValueError):
        raise InputError(f"{where}: {name} must be an array of numbers") from None
    if a.size == 0:
        raise InputError(f"{where}: {name} is empty")
    return a


def _check_series(name: str, a: Any, n: int | None = None) -> np.ndarray:
    try:
        arr = np.asarray(a)
        if np.iscomplexobj(arr):
            raise InputError(f"{name} is complex; pass a real array")
        arr = np.ascontiguousarray(arr, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} cannot be converted to a float array: {exc}") from None
    if arr.ndim != 1:
        raise InputError(f"{name} must be 1-D, got an array of shape {arr.shape}")
    if n is not None and arr.size != n:
        raise InputError(f"{name} has {arr.size} samples but x has {n}")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{name}[{i}] is not finite ({arr[i]})")
    return arr


def _check_time(t: np.ndarray, t_prev: float | None) -> None:
    if t.size > 1:
        d = np.diff(t)
        bad = ~(d > 0)
        if bad.any():
            i = int(np.argmax(bad)) + 1
            raise InputError(
                f"t must be strictly increasing, but t[{i}] = {t[i]} does not exceed "
                f"t[{i - 1}] = {t[i - 1]}"
            )
    if t.size and t_prev is not None and not t[0] > t_prev:
        raise InputError(
            f"t must be strictly increasing across chunks, but t[0] = {t[0]} does not exceed "
            f"the previous chunk's last time {t_prev}"
        )


class JointLaw:
    """Base class of the displacement-driven joint laws (see the module docstring)."""

    #: Registry name of the law.
    name: ClassVar[str] = ""
    #: True when the law is odd: ``F(-x) = -F(x)`` for any history from the relaxed state.
    symmetric: ClassVar[bool] = True

    # -- parameters ---------------------------------------------------------------------
    def _specs(self) -> list[ParamSpec]:
        raise NotImplementedError

    def _values(self) -> list[float]:
        raise NotImplementedError

    def _rebuild(self, values: list[float]) -> JointLaw:
        raise NotImplementedError

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the parameters, in the order of :attr:`vector`."""
        return tuple(s.name for s in self._specs())

    @property
    def params(self) -> dict[str, float]:
        """Parameter values by name."""
        return dict(zip(self.param_names, self._values(), strict=True))

    @property
    def vector(self) -> np.ndarray:
        """Parameter values as a float array in the order of :attr:`param_names`."""
        return np.array(self._values(), dtype=float)

    @property
    def units(self) -> dict[str, str]:
        """Unit of each parameter (SI; ``""`` for a dimensionless one)."""
        return {s.name: s.unit for s in self._specs()}

    @property
    def bounds(self) -> dict[str, tuple[float, float]]:
        """``(lo, hi)`` of each parameter (a positive parameter has ``lo = 0`` excluded)."""
        return {s.name: (s.lo, s.hi) for s in self._specs()}

    def with_params(self, values: Sequence[float] | np.ndarray | Mapping[str, float]) -> JointLaw:
        """A copy of this law with new parameter values.

        Parameters
        ----------
        values : array-like or mapping
            A full vector in the order of :attr:`param_names`, or a mapping of some names to
            new values (the others are kept).

        Returns
        -------
        JointLaw
            The new law (this one is unchanged).
        """
        names = self.param_names
        if isinstance(values, Mapping):
            unknown = [k for k in values if k not in names]
            if unknown:
                raise InputError(
                    f"{self.name}: unknown parameter(s) {', '.join(map(str, unknown))}; "
                    f"it has {', '.join(names)}"
                )
            cur = self.params
            cur.update({k: values[k] for k in values})
            vec = [cur[n] for n in names]
        else:
            arr = np.asarray(values, dtype=float).reshape(-1)
            if arr.size != len(names):
                raise InputError(
                    f"{self.name}: {arr.size} parameter values given for {len(names)} "
                    f"parameters ({', '.join(names)})"
                )
            vec = [float(v) for v in arr]
        checked = [s.check(v, self.name) for s, v in zip(self._specs(), vec, strict=True)]
        return self._rebuild(checked)

    # -- behaviour ----------------------------------------------------------------------
    @property
    def rate_dependent(self) -> bool:
        """True when the force depends on the velocity (``t`` is then required)."""
        return self._ref().rate_dependent

    def _ref(self) -> ref.RefLaw:
        """The plain-Python reference of this law (tests, and the fallback kernel)."""
        raise NotImplementedError

    def spec(self) -> tuple[str, list[float], list[Any]]:
        """``(kind, own parameters, children)``: the description the Rust core builds the law
        from (children: the specs of the laws a composite holds); :func:`from_spec` inverts
        it."""
        return (self._kind(), [float(v) for v in self._values()], [])

    def _kind(self) -> str:
        """Registry name of the nearest registered class (a subclass with a name of its own
        runs on its parent's kernel)."""
        for cls in type(self).__mro__:
            if LAWS.get(getattr(cls, "name", "")) is cls:
                return cls.name
        raise InputError(f"{self.name}: not derived from a registered joint law")

    @property
    def initial_stiffness(self) -> float:
        """Tangent stiffness from the relaxed state, N/m (0 for a law behind an open gap)."""
        return _initial_stiffness(self)

    def _kernel(self, x0: float) -> Any:
        """The Rust operator of this law, relaxed at ``x0``."""
        from .. import _core

        return _core.JointOperatorCore(self.spec(), x0)

    def operator(self, x0: float = 0.0) -> JointOperator:
        """A stateful operator for a recording streamed in chunks.

        Parameters
        ----------
        x0 : float, default 0.0
            Displacement at which the joint starts relaxed (force 0, no history).

        Returns
        -------
        JointOperator
            ``op.push(t_chunk, x_chunk)`` returns the forces of the chunk.
        """
        return JointOperator(self, x0)

    def force(self, t: Any, x: Any, x0: float = 0.0) -> np.ndarray:
        """Force for the displacement history ``x`` sampled at times ``t``.

        Parameters
        ----------
        t : array-like or None
            Sample times, s, strictly increasing (None for a rate-independent law).
        x : array-like
            Displacement, m.
        x0 : float, default 0.0
            Displacement at which the joint starts relaxed.

        Returns
        -------
        numpy.ndarray
            Force, N, one value per sample.
        """
        return self.operator(x0).push(t, x)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"{type(self).__name__}({args})"

    def __eq__(self, other: object) -> bool:
        return (
            type(other) is type(self)
            and isinstance(other, JointLaw)
            and other.param_names == self.param_names
            and bool(np.array_equal(other.vector, self.vector))
        )

    __hash__ = None  # type: ignore[assignment]


class JointOperator:
    """A law with its carried state; see :meth:`JointLaw.operator`."""

    def __init__(self, law: JointLaw, x0: float = 0.0) -> None:
        self.law = law
        self.x0 = ParamSpec("x0", "m").check(x0, law.name)
        self.reset()

    def reset(self) -> None:
        """Back to the relaxed state at ``x0``."""
        self._kernel = self.law._kernel(self.x0)
        self._t_prev: float | None = None
        self._started = False

    def push(self, t: Any, x: Any) -> np.ndarray:
        """Forces for the next chunk ``(t, x)``, continuing the carried history.

        Parameters
        ----------
        t : array-like or None
            Times of the chunk, s (strictly increasing, after the previous chunk's), or None
            for a rate-independent law.
        x : array-like
            Displacement of the chunk, m.

        Returns
        -------
        numpy.ndarray
            Force, N.
        """
        xa = _check_series("x", x)
        if t is None:
            if self.law.rate_dependent:
                raise InputError(f"{self.law.name} is rate-dependent: pass the sample times t")
            if self._t_prev is not None:
                raise InputError("t was given for an earlier chunk: pass it for every chunk")
            ta = None
        else:
            ta = _check_series("t", t, xa.size)
            if self._started and self._t_prev is None:
                raise InputError("t was None for an earlier chunk: pass None for every chunk")
            _check_time(ta, self._t_prev)
        out = self._kernel.push(ta, xa)
        self._started = True
        if ta is not None and ta.size:
            self._t_prev = float(ta[-1])
        return out


# ============================================================================================
class _Leaf(JointLaw):
    """A law with a fixed list of scalar parameters, stored as attributes."""

    _SPECS: ClassVar[tuple[ParamSpec, ...]] = ()

    def __init__(self, **kw: Any) -> None:
        for s in self._SPECS:
            setattr(self, s.name, s.check(kw[s.name], self.name))
        self._validate()

    def _validate(self) -> None:
        pass

    def _specs(self) -> list[ParamSpec]:
        return list(self._SPECS)

    def _values(self) -> list[float]:
        return [getattr(self, s.name) for s in self._SPECS]

    def _rebuild(self, values: list[float]) -> JointLaw:
        return type(self)(**dict(zip(self.param_names, values, strict=True)))


class Jenkins(_Leaf):
    """Elastic-Coulomb element: stiffness ``k`` in series with a slider of slip force ``fs``.

    Energy dissipated per symmetric cycle of amplitude ``A``: ``4 fs (A - fs/k)`` for
    ``A > fs/k``, else 0.

    Parameters
    ----------
    k : float
        Stiffness, N/m (> 0).
    fs : float
        Slip force, N (> 0).
    """

    name = "jenkins"
    _SPECS = (_pos("k", "N/m"), _pos("fs", "N"))

    def __init__(self, k: float, fs: float) -> None:
        super().__init__(k=k, fs=fs)

    def _ref(self) -> ref.RefLaw:
        return ref.RefJenkins(self.k, self.fs)


class Segalman(_Leaf):
    """Segalman's four-parameter Iwan model (J. Appl. Mech. 72: 752-760, 2005), exact.

    Slip-displacement density ``ρ(φ) = R φ^χ [H(φ) - H(φ - φmax)] + S δ(φ - φmax)`` of a
    continuum of Jenkins elements. The response is evaluated in closed form through Masing's
    rules on the virgin curve ``f(u) = K_T u - R u^(χ+2) / ((χ+1)(χ+2))`` (``u < φmax``;
    ``F_S`` beyond), with the wiping-out memory of reversal points: no discretisation.
    At small amplitude the energy per cycle is ``D = 4 R A^(χ+3) / ((χ+2)(χ+3))``.

    Parameters
    ----------
    F_S : float
        Macro-slip force, N (> 0).
    K_T : float
        Tangent stiffness at the origin, N/m (> 0).
    chi : float
        Power-law exponent ``χ`` (> -1; Segalman's range is ``-1 < χ <= 0``).
    beta : float
        Strength of the delta at ``φmax`` relative to the power-law part (>= 0).
    """

    name = "segalman"
    _SPECS = (
        _pos("F_S", "N"),
        _pos("K_T", "N/m"),
        ParamSpec("chi", "", -1.0, 1.0, True),
        _nonneg("beta", ""),
    )

    def __init__(self, F_S: float, K_T: float, chi: float, beta: float) -> None:
        super().__init__(F_S=F_S, K_T=K_T, chi=chi, beta=beta)

    @property
    def phi_max(self) -> float:
        """Largest slip displacement ``φmax = F_S (1+β) / (K_T (β + (χ+1)/(χ+2)))``, m."""
        c = self.chi
        return self.F_S * (1.0 + self.beta) / (self.K_T * (self.beta + (c + 1.0) / (c + 2.0)))

    @property
    def R(self) -> float:
        """Coefficient ``R`` of the power-law density."""
        c, b = self.chi, self.beta
        return self.F_S * (c + 1.0) / (self.phi_max ** (c + 2.0) * (b + (c + 1.0) / (c + 2.0)))

    @property
    def S(self) -> float:
        """Strength ``S`` of the delta at ``φmax``, N/m."""
        c, b = self.chi, self.beta
        return self.F_S / self.phi_max * b / (b + (c + 1.0) / (c + 2.0))

    def virgin(self, u: Any) -> np.ndarray:
        """Virgin curve ``f(u)``, N (odd)."""
        a = np.abs(np.asarray(u, dtype=float))
        c = self.R / ((self.chi + 1.0) * (self.chi + 2.0))
        am = np.minimum(a, self.phi_max)
        v = np.where(a >= self.phi_max, self.F_S, self.K_T * am - c * am ** (self.chi + 2.0))
        return np.sign(u) * v

    def loop_energy(self, A: Any) -> np.ndarray:
        """Energy dissipated per symmetric cycle of amplitude ``A`` (exact for all ``A``), J.

        ``D = 8 [∫_0^A f du - A f(A) / 2]`` (Masing); for ``A <= φmax`` this is Segalman's
        ``4 R A^(χ+3) / ((χ+2)(χ+3))``.
        """
        a = np.abs(np.asarray(A, dtype=float))
        c, n, pm = self.R / ((self.chi + 1.0) * (self.chi + 2.0)), self.chi + 2.0, self.phi_max
        am = np.minimum(a, pm)
        integ = self.K_T * am**2 / 2 - c * am ** (n + 1) / (n + 1) + self.F_S * (a - am)
        return 8.0 * (integ - a * self.virgin(a) / 2.0)

    def _ref(self) -> ref.RefLaw:
        return ref.RefSegalman(self.F_S, self.K_T, self.chi, self.beta)


class Iwan(Segalman):
    """Continuous Iwan model with a uniform slip-force density, exact (no discretisation).

    ``k`` is the stiffness at the origin and ``fs_max`` the macro-slip force; the virgin
    curve is ``k u - k² u² / (4 fs_max)`` up to ``u = 2 fs_max / k``. It is
    :class:`Segalman` with ``χ = 0``, ``β = 0``. Energy per cycle of amplitude
    ``A <= 2 fs_max / k``: ``k² A³ / (3 fs_max)``.

    Parameters
    ----------
    k : float
        Initial stiffness, N/m (> 0).
    fs_max : float
        Macro-slip force, N (> 0).
    density : {"uniform"}
        Slip-force density (Segalman's power law is :class:`Segalman`).
    """

    name = "iwan"
    _SPECS = (_pos("k", "N/m"), _pos("fs_max", "N"))  # type: ignore[assignment]

    def __init__(self, k: float, fs_max: float, density: str = "uniform") -> None:
        if density != "uniform":
            raise InputError(
                f"iwan: density {density!r} is not known; use 'uniform' "
                "(or the Segalman law for a power-law density)"
            )
        _Leaf.__init__(self, k=k, fs_max=fs_max)
        self.F_S, self.K_T, self.chi, self.beta = self.fs_max, self.k, 0.0, 0.0


class MaxwellSlip(JointLaw):
    """``N`` Jenkins elements in parallel (Maxwell-slip model; a discrete Iwan model).

    Parameters
    ----------
    k : array-like
        Element stiffnesses, N/m (> 0).
    fs : array-like
        Element slip forces, N (> 0), same length.
    """

    name = "maxwell_slip"

    def __init__(self, k: Any, fs: Any) -> None:
        k_, fs_ = _array(k, "k", self.name), _array(fs, "fs", self.name)
        if k_.size != fs_.size:
            raise InputError(f"{self.name}: k has {k_.size} elements but fs has {fs_.size}")
        self.k = np.array([_pos(f"k{i}", "N/m").check(v, self.name) for i, v in enumerate(k_)])
        self.fs = np.array([_pos(f"fs{i}", "N").check(v, self.name) for i, v in enumerate(fs_)])

    def _specs(self) -> list[ParamSpec]:
        n = self.k.size
        return [_pos(f"k{i}", "N/m") for i in range(n)] + [_pos(f"fs{i}", "N") for i in range(n)]

    def _values(self) -> list[float]:
        return [float(v) for v in self.k] + [float(v) for v in self.fs]

    def _rebuild(self, values: list[float]) -> JointLaw:
        n = self.k.size
        return MaxwellSlip(values[:n], values[n:])

    def _ref(self) -> ref.RefLaw:
        return ref.RefMaxwellSlip(self.k.tolist(), self.fs.tolist())

    @classmethod
    def from_segalman(cls, law: Segalman, n: int) -> MaxwellSlip:
        """Discretise a Segalman (or uniform Iwan) density into ``n`` Jenkins elements.

        The power-law part is split into ``n - 1`` intervals of equal stiffness share (midpoint
        slip displacement in each, so the total stiffness and the macro-slip force are kept);
        the delta at ``φmax`` is the last element (or merged into the last interval when
        ``β = 0``).
        """
        if int(n) < 2:
            raise InputError("maxwell_slip.from_segalman: n must be >= 2")
        n = int(n)
        c, pm, R, S = law.chi, law.phi_max, law.R, law.S
        m = n - 1 if S > 0 else n
        # equal stiffness shares of R φ^χ on [0, φmax]: edges φ_j = φmax (j/m)^(1/(χ+1))
        edges = pm * (np.arange(m + 1) / m) ** (1.0 / (c + 1.0))
        kk = R * (edges[1:] ** (c + 1) - edges[:-1] ** (c + 1)) / (c + 1)
        mom = R * (edges[1:] ** (c + 2) - edges[:-1] ** (c + 2)) / (c + 2)
        phi = mom / kk
        k_el, fs_el = list(kk), list(kk * phi)
        if S > 0:
            k_el.append(S)
            fs_el.append(S * pm)
        return cls(k_el, fs_el)


class GeneralizedMaxwellSlip(JointLaw):
    """Generalised Maxwell-slip model (Al-Bender, Lampaert & Swevers, IEEE TAC 50, 2005).

    ``N`` elements: element ``i`` sticks (``dF_i = k_i dx``) until ``|F_i|`` reaches
    ``α_i s(v)``, ``s(v) = Fc + (Fs - Fc) exp(-|v/vs|^δ)`` (the Stribeck curve), then slips
    with ``dF_i/dt = sgn(v) C (1 - F_i / (α_i s(v) sgn v))`` until the motion reverses.
    ``F = Σ F_i + σ2 v``. Steady sliding force: ``Σα_i s(v) + σ2 v``.

    Parameters
    ----------
    k, alpha : array-like
        Element stiffnesses, N/m, and shares of the Stribeck force ``α_i`` (> 0).
    Fc, Fs : float
        Coulomb and static friction force, N.
    vs : float
        Stribeck velocity, m/s.
    C : float
        Attraction rate of the sliding elements to the Stribeck curve, N/s.
    delta : float, default 2
        Stribeck exponent.
    sigma2 : float, default 0
        Viscous coefficient, N s/m.
    """

    name = "gms"
    _TAIL = (
        _pos("Fc", "N"),
        _pos("Fs", "N"),
        _pos("vs", "m/s"),
        _pos("C", "N/s"),
        _pos("delta", ""),
        _nonneg("sigma2", "N s/m"),
    )

    def __init__(
        self,
        k: Any,
        alpha: Any,
        Fc: float,
        Fs: float,
        vs: float,
        C: float,
        delta: float = 2.0,
        sigma2: float = 0.0,
    ) -> None:
        k_, a_ = _array(k, "k", self.name), _array(alpha, "alpha", self.name)
        if k_.size != a_.size:
            raise InputError(f"{self.name}: k has {k_.size} elements but alpha has {a_.size}")
        self.k = np.array([_pos(f"k{i}", "N/m").check(v, self.name) for i, v in enumerate(k_)])
        self.alpha = np.array([_pos(f"alpha{i}", "").check(v, self.name) for i, v in enumerate(a_)])
        vals = [Fc, Fs, vs, C, delta, sigma2]
        for s, v in zip(self._TAIL, vals, strict=True):
            setattr(self, s.name, s.check(v, self.name))

    def _specs(self) -> list[ParamSpec]:
        n = self.k.size
        return (
            [_pos(f"k{i}", "N/m") for i in range(n)]
            + [_pos(f"alpha{i}", "") for i in range(n)]
            + list(self._TAIL)
        )

    def _values(self) -> list[float]:
        return (
            [float(v) for v in self.k]
            + [float(v) for v in self.alpha]
            + [getattr(self, s.name) for s in self._TAIL]
        )

    def _rebuild(self, values: list[float]) -> JointLaw:
        n = self.k.size
        return GeneralizedMaxwellSlip(values[:n], values[n : 2 * n], *values[2 * n :])

    def _ref(self) -> ref.RefLaw:
        return ref.RefGMS(
            self.k.tolist(),
            self.alpha.tolist(),
            self.Fc,
            self.Fs,
            self.vs,
            self.C,
            self.delta,
            self.sigma2,
        )


class Dahl(_Leaf):
    """Dahl's friction law ``dF/dx = σ0 |1 - F/Fc sgn ẋ|^α sgn(1 - F/Fc sgn ẋ)``.

    Rate-independent; solved in closed form along each step. Steady sliding force ``±Fc``.

    Parameters
    ----------
    sigma0 : float
        Initial stiffness, N/m (> 0).
    Fc : float
        Coulomb force, N (> 0).
    alpha : float, default 1
        Shape exponent (> 0).
    """

    name = "dahl"
    _SPECS = (_pos("sigma0", "N/m"), _pos("Fc", "N"), _pos("alpha", ""))

    def __init__(self, sigma0: float, Fc: float, alpha: float = 1.0) -> None:
        super().__init__(sigma0=sigma0, Fc=Fc, alpha=alpha)

    def _ref(self) -> ref.RefLaw:
        return ref.RefDahl(self.sigma0, self.Fc, self.alpha)


class LuGre(_Leaf):
    """LuGre friction model (Canudas de Wit et al. 1995).

    ``dz/dt = v - σ0 |v| z / g(v)``, ``g(v) = Fc + (Fs - Fc) exp(-|v/vs|^δ)``,
    ``F = σ0 z + σ1 dz/dt + σ2 v``. The bristle equation is integrated exactly over each step
    (``v`` constant between samples: ``z`` relaxes exponentially in the travelled distance),
    stable at any sampling rate. Steady sliding force ``sgn(v) g(v) + σ2 v``.

    Parameters
    ----------
    sigma0 : float
        Bristle stiffness, N/m (> 0).
    sigma1 : float
        Bristle damping, N s/m (>= 0).
    sigma2 : float
        Viscous coefficient, N s/m (>= 0).
    Fc, Fs : float
        Coulomb and static friction force, N (> 0).
    vs : float
        Stribeck velocity, m/s (> 0).
    delta : float, default 2
        Stribeck exponent (> 0).
    """

    name = "lugre"
    _SPECS = (
        _pos("sigma0", "N/m"),
        _nonneg("sigma1", "N s/m"),
        _nonneg("sigma2", "N s/m"),
        _pos("Fc", "N"),
        _pos("Fs", "N"),
        _pos("vs", "m/s"),
        _pos("delta", ""),
    )

    def __init__(
        self,
        sigma0: float,
        sigma1: float,
        sigma2: float,
        Fc: float,
        Fs: float,
        vs: float,
        delta: float = 2.0,
    ) -> None:
        super().__init__(
            sigma0=sigma0, sigma1=sigma1, sigma2=sigma2, Fc=Fc, Fs=Fs, vs=vs, delta=delta
        )

    def steady_force(self, v: Any) -> np.ndarray:
        """Steady sliding force ``sgn(v) g(v) + σ2 v``, N."""
        v = np.asarray(v, dtype=float)
        g = self.Fc + (self.Fs - self.Fc) * np.exp(-((np.abs(v) / self.vs) ** self.delta))
        return np.sign(v) * g + self.sigma2 * v

    def _ref(self) -> ref.RefLaw:
        return ref.RefLuGre(
            self.sigma0, self.sigma1, self.sigma2, self.Fc, self.Fs, self.vs, self.delta
        )


class BoucWen(_Leaf):
    """Bouc-Wen hysteresis in displacement-driven form (rate-independent).

    ``F = z``, ``dz/dx = α - β (γ s |z|^(ν-1) z + δ |z|^ν)``, ``s = sgn(ẋ)`` (the form of the
    hysteretic benchmark of Noël & Schoukens 2016, and of the ``bouc_wen`` joint of
    :mod:`contactlab.structure`). Integrated by RK4 in ``x`` on sub-steps of at most 5 % of
    the saturation displacement ``z_c / α``, ``z_c = (α / (β (|γ| + |δ|)))^(1/ν)``.

    Parameters
    ----------
    alpha : float
        Initial stiffness, N/m (> 0).
    beta : float
        Hysteresis scale (>= 0), N^(1-ν)/m.
    gamma, delta : float
        Shape parameters.
    nu : float
        Exponent (> 0).
    """

    name = "bouc_wen"
    _SPECS = (
        _pos("alpha", "N/m"),
        _nonneg("beta", "N^(1-nu)/m"),
        ParamSpec("gamma", ""),
        ParamSpec("delta", ""),
        _pos("nu", ""),
    )

    def __init__(
        self, alpha: float, beta: float, gamma: float, delta: float, nu: float = 1.0
    ) -> None:
        super().__init__(alpha=alpha, beta=beta, gamma=gamma, delta=delta, nu=nu)

    def _validate(self) -> None:
        if self.beta * (self.gamma + self.delta) < 0:
            raise InputError(
                f"bouc_wen: beta (gamma + delta) = {self.beta * (self.gamma + self.delta)} "
                "< 0 makes the force grow without bound"
            )

    def _ref(self) -> ref.RefLaw:
        return ref.RefBoucWen(self.alpha, self.beta, self.gamma, self.delta, self.nu)


class KelvinVoigt(_Leaf):
    """Linear spring and dashpot ``F = k (x - x0) + c ẋ``.

    Parameters
    ----------
    k : float
        Stiffness, N/m (>= 0).
    c : float, default 0
        Viscous coefficient, N s/m (>= 0).
    """

    name = "kelvin_voigt"
    _SPECS = (_nonneg("k", "N/m"), _nonneg("c", "N s/m"))

    def __init__(self, k: float, c: float = 0.0) -> None:
        super().__init__(k=k, c=c)

    def _ref(self) -> ref.RefLaw:
        return ref.RefKelvinVoigt(self.k, self.c)


class MasingLaw(_Leaf):
    """Masing's rules with non-local memory (:class:`contactlab.Masing`) as a joint law.

    ``MasingLaw(h0, ac, scale)`` uses the exponential virgin curve; :meth:`from_model`
    wraps any :class:`contactlab.Masing`, including a tabulated backbone (then without
    fittable parameters).

    Parameters
    ----------
    h0 : float
        Saturation force, N.
    ac : float
        Curvature of the virgin curve, 1/m.
    scale : float, default 2
        Branch scale λ.
    """

    name = "masing"
    _SPECS = (_pos("h0", "N"), _pos("ac", "1/m"), _pos("scale", ""))

    def __init__(self, h0: float, ac: float, scale: float = 2.0) -> None:
        super().__init__(h0=h0, ac=ac, scale=scale)
        self._model: Any = None

    @classmethod
    def from_model(cls, model: Any) -> MasingLaw:
        """Wrap a :class:`contactlab.Masing` (exponential or tabulated backbone)."""
        if model.is_exponential:
            return cls(model.h0, model.ac, model.scale)
        self = cls.__new__(cls)
        self.h0, self.ac, self.scale = float("nan"), float("nan"), model.scale
        self._model = model
        return self

    def _specs(self) -> list[ParamSpec]:
        return [] if self._model is not None else list(self._SPECS)

    def _values(self) -> list[float]:
        return [] if self._model is not None else [self.h0, self.ac, self.scale]

    def _rebuild(self, values: list[float]) -> JointLaw:
        return self if self._model is not None else MasingLaw(*values)

    def masing(self) -> Any:
        """The :class:`contactlab.Masing` model."""
        if self._model is not None:
            return self._model
        from ..masing import Masing

        return Masing(self.h0, self.ac, self.scale)

    def _ref(self) -> ref.RefLaw:
        if self._model is None and self.scale == 2.0:
            return ref.RefMasingExp(self.h0, self.ac)
        return _MasingRef(self.masing())

    def spec(self) -> tuple[str, list[float], list[Any]]:
        if self._model is not None or self.scale != 2.0:
            raise InputError(
                "masing: inside a series, parallel or backlash law only the exponential curve "
                f"with Masing's rule (scale 2) is available, got {self!r}"
            )
        return super().spec()

    def _kernel(self, x0: float) -> Any:
        return _MasingKernel(self.masing(), x0)


class _MasingKernel:
    """The Masing operator (any backbone and scale) behind the joint-law operator."""

    def __init__(self, model: Any, x0: float) -> None:
        self.op, self.x0 = model.operator(), x0

    def push(self, t: Any, x: np.ndarray) -> np.ndarray:
        return self.op.push(x - self.x0 if self.x0 else x)


class _MasingRef(ref.RefLaw):
    """Reference stand-in for a Masing law with a tabulated curve or a scale other than 2:
    the Masing operator, sample by sample (relative to ``x0``)."""

    def __init__(self, model: Any) -> None:
        self.model = model

    def start(self, x0: float) -> Any:
        return {"x0": x0, "op": self.model.operator()}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        return float(st["op"].push(np.array([x - st["x0"]]))[0])


# ============================================================================================
def _child_names(laws: Sequence[JointLaw]) -> list[str]:
    names = [law.name for law in laws]
    return [n if names.count(n) == 1 else f"{n}{i}" for i, n in enumerate(names)]


class _Composite(JointLaw):
    """Own parameters first, then each child's prefixed with ``<child>.``."""

    symmetric = True
    _OWN: ClassVar[tuple[ParamSpec, ...]] = ()
    laws: list[JointLaw]

    def _own(self) -> list[float]:
        return [getattr(self, s.name) for s in self._OWN]

    def _specs(self) -> list[ParamSpec]:
        out = list(self._OWN)
        for pre, law in zip(_child_names(self.laws), self.laws, strict=True):
            out += [
                ParamSpec(f"{pre}.{s.name}", s.unit, s.lo, s.hi, s.open_lo) for s in law._specs()
            ]
        return out

    def _values(self) -> list[float]:
        out = self._own()
        for law in self.laws:
            out += law._values()
        return out

    def spec(self) -> tuple[str, list[float], list[Any]]:
        return (self._kind(), [float(v) for v in self._own()], [law.spec() for law in self.laws])

    def _split(self, values: list[float]) -> tuple[list[float], list[JointLaw]]:
        n = len(self._OWN)
        own, rest = values[:n], values[n:]
        laws = []
        for law in self.laws:
            m = len(law._specs())
            laws.append(law._rebuild(rest[:m]))
            rest = rest[m:]
        return own, laws


def _as_law(law: Any, where: str) -> JointLaw:
    if isinstance(law, JointLaw):
        return law
    raise InputError(f"{where}: expected a joint law, got {type(law).__name__}")


class Series(_Composite):
    """Laws in series: the same force, displacements adding up (``x = Σ x_i``).

    The split is found at every sample by a bracketed root search on the force balance
    (the laws must have a non-decreasing force in their own displacement over a step).

    Parameters
    ----------
    *laws : JointLaw
        Two or more laws.
    """

    name = "series"

    def __init__(self, *laws: JointLaw) -> None:
        if len(laws) < 2:
            raise InputError("series: give two or more laws")
        self.laws = [_as_law(law, self.name) for law in laws]

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return all(law.symmetric for law in self.laws)

    def _rebuild(self, values: list[float]) -> JointLaw:
        return Series(*self._split(values)[1])

    def _ref(self) -> ref.RefLaw:
        refs = [law._ref() for law in self.laws]
        out = refs[-1]
        for r in reversed(refs[:-1]):
            out = ref.RefSeries(r, out)
        return out


class Parallel(_Composite):
    """Laws in parallel with a linear stiffness and a viscous term.

    ``F = Σ F_i(x) + k (x - x0) + c ẋ``.

    Parameters
    ----------
    *laws : JointLaw
        Zero or more laws.
    k : float, default 0
        Parallel stiffness, N/m (>= 0).
    c : float, default 0
        Viscous coefficient, N s/m (>= 0).
    """

    name = "parallel"
    _OWN = (_nonneg("k", "N/m"), _nonneg("c", "N s/m"))

    def __init__(self, *laws: JointLaw, k: float = 0.0, c: float = 0.0) -> None:
        self.laws = [_as_law(law, self.name) for law in laws]
        self.k = self._OWN[0].check(k, self.name)
        self.c = self._OWN[1].check(c, self.name)

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return all(law.symmetric for law in self.laws)

    def _rebuild(self, values: list[float]) -> JointLaw:
        own, laws = self._split(values)
        return Parallel(*laws, k=own[0], c=own[1])

    def _ref(self) -> ref.RefLaw:
        return ref.RefParallel([law._ref() for law in self.laws], self.k, self.c)


class Backlash(_Composite):
    """A clearance (dead band) of total width ``gap`` in series with a law.

    While the gap is open the force is 0; in contact the law is driven by ``x ∓ gap/2``.
    ``Backlash(gap, law)`` with a number for ``law`` uses a linear spring of that stiffness
    (a pure dead-zone spring).

    Parameters
    ----------
    gap : float
        Total free play, m (>= 0); the joint starts centred in it.
    law : JointLaw or float
        The law behind the clearance (or a contact stiffness, N/m).
    """

    name = "backlash"
    _OWN = (_nonneg("gap", "m"),)

    def __init__(self, gap: float, law: JointLaw | float | None = None) -> None:
        self.gap = self._OWN[0].check(gap, self.name)
        if law is None:
            raise InputError("backlash: give the law behind the clearance (or a contact stiffness)")
        if not isinstance(law, JointLaw):
            law = KelvinVoigt(ParamSpec("k", "N/m", 0.0, INF, True).check(law, self.name))
        self.laws = [law]

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return self.laws[0].symmetric

    def _rebuild(self, values: list[float]) -> JointLaw:
        own, laws = self._split(values)
        return Backlash(own[0], laws[0])

    def _ref(self) -> ref.RefLaw:
        return ref.RefBacklash(self.gap, self.laws[0]._ref())


def _initial_stiffness(law: JointLaw) -> float:
    if isinstance(law, Iwan):
        return law.k
    if isinstance(law, Segalman):
        return law.K_T
    if isinstance(law, (Jenkins, KelvinVoigt)):
        return law.k
    if isinstance(law, (MaxwellSlip, GeneralizedMaxwellSlip)):
        return float(np.sum(law.k))
    if isinstance(law, (Dahl, LuGre)):
        return law.sigma0
    if isinstance(law, BoucWen):
        return law.alpha
    if isinstance(law, MasingLaw):
        return float(law.masing().local_stiffness(0.0))
    if isinstance(law, Parallel):
        return law.k + sum(x.initial_stiffness for x in law.laws)
    if isinstance(law, Series):
        ks = [x.initial_stiffness for x in law.laws]
        return 0.0 if min(ks) <= 0 else 1.0 / sum(1.0 / k for k in ks)
    if isinstance(law, Backlash):
        return law.laws[0].initial_stiffness if law.gap == 0 else 0.0
    raise InputError(f"{law.name}: no initial stiffness")  # pragma: no cover


def from_spec(spec: Any) -> JointLaw:
    """The law a :meth:`JointLaw.spec` describes.

    Parameters
    ----------
    spec : tuple
        ``(kind, params, children)`` (lists may be any sequences).

    Returns
    -------
    JointLaw
        A new law equal to the one the spec was taken from.
    """
    try:
        kind, params, children = spec
        p = [float(v) for v in params]
        kids = [from_spec(c) for c in children]
    except (TypeError, ValueError):
        raise InputError(f"a joint-law spec is (kind, params, children), got {spec!r}") from None
    cls = LAWS.get(str(kind))
    if cls is None:
        raise InputError(f"unknown joint law {kind!r}: use one of {', '.join(LAWS)}")
    if cls in (Series, Parallel, Backlash):
        if cls is Series:
            return Series(*kids)
        if cls is Parallel:
            if len(p) != 2:
                raise InputError(f"parallel takes 2 parameters (k, c), got {len(p)}")
            return Parallel(*kids, k=p[0], c=p[1])
        if len(p) != 1 or len(kids) != 1:
            raise InputError("backlash takes 1 parameter (gap) and 1 law")
        return Backlash(p[0], kids[0])
    if kids:
        raise InputError(f"{kind} takes no child laws")
    if cls is MaxwellSlip:
        n = len(p) // 2
        return MaxwellSlip(p[:n], p[n:])
    if cls is GeneralizedMaxwellSlip:
        n = (len(p) - 6) // 2
        if n < 1 or len(p) != 2 * n + 6:
            raise InputError(f"gms takes 2 n + 6 parameters, got {len(p)}")
        return GeneralizedMaxwellSlip(p[:n], p[n : 2 * n], *p[2 * n :])
    try:
        return cls(*p)
    except TypeError as exc:
        raise InputError(f"{kind}: {exc}") from None


#: Registry of the joint laws by name.
LAWS: dict[str, type[JointLaw]] = {
    "jenkins": Jenkins,
    "iwan": Iwan,
    "segalman": Segalman,
    "maxwell_slip": MaxwellSlip,
    "gms": GeneralizedMaxwellSlip,
    "dahl": Dahl,
    "lugre": LuGre,
    "bouc_wen": BoucWen,
    "kelvin_voigt": KelvinVoigt,
    "masing": MasingLaw,
    "series": Series,
    "parallel": Parallel,
    "backlash": Backlash,
}
