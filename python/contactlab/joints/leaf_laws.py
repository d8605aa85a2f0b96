"""The joint laws with a fixed list of scalar parameters (Jenkins, Segalman, Iwan, Dahl,
LuGre, Bouc-Wen, Kelvin-Voigt, Masing) and the Maxwell-slip arrays of elements."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from . import _reference as ref
from .law_base import JointLaw, ParamSpec, _array, _nonneg, _pos


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
