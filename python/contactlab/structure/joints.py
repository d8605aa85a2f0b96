"""Joint elements of a :class:`~contactlab.structure.Structure` and their parameters.

Each joint acts on the relative displacement ``d = x[dof] - x[dof2]`` (``dof2=None``: the
ground, which stays fixed under base excitation) and adds its force ``F(d)`` to ``dof`` and
``-F`` to ``dof2``. Models (PHYSICS.md §1 for the Masing operator):

- ``masing``: the Masing operator with non-local memory, exponential virgin curve
  ``h0 (1 - exp(-ac u))`` or a tabulated backbone ``(x_points, f_points)``, branch scale λ.
- ``jenkins``: elastic-Coulomb element, stiffness ``k`` in series with a slider ``fs``.
- ``iwan``: parallel Jenkins elements ``(k_i, fs_i)`` (a discretised slip-force distribution;
  :func:`iwan_uniform` builds the uniform one).
- ``bouc_wen``: ``F = z``, ``ż = α ḋ − β (γ |ḋ| |z|^(ν−1) z + δ ḋ |z|^ν)`` (the form of the
  hysteretic benchmark of Noël & Schoukens, 2016).
- ``kelvin_voigt``: ``F = k d + c ḋ``.
- ``normal``: nonlinear contact stiffness ``F = k_s(d) d``, ``k_s(d) = a1 + a2 d + a3 d² + …``
  (Konowalski's eq. 6, the same polynomial law as :class:`contactlab.normal.NonlinearContact`).
- ``law``: any law of :mod:`contactlab.joints` (Segalman, Dahl, LuGre, Maxwell-slip, GMS,
  a backlash, laws in series or parallel, …), ``add_joint("law", dof, law=Segalman(...))``;
  a rate-dependent law sees the velocity at the end of each integrator step as its velocity
  over the step;
  stored as the flat float encoding :func:`encode_law` of its spec (array ``spec``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError

#: Parameter names of each joint model, in the order the core takes them.
PARAMS: dict[str, tuple[str, ...]] = {
    "masing": ("h0", "ac", "scale"),
    "masing_tabulated": ("scale",),
    "jenkins": ("k", "fs"),
    "iwan": (),
    "bouc_wen": ("alpha", "beta", "gamma", "delta", "nu"),
    "kelvin_voigt": ("k", "c"),
    "normal": (),
    "law": (),
}

UNITS: dict[str, str] = {
    "h0": "N",
    "ac": "1/m",
    "scale": "",
    "k": "N/m",
    "fs": "N",
    "alpha": "N/m",
    "beta": "1/m^nu",
    "gamma": "",
    "delta": "",
    "nu": "",
    "c": "N s/m",
}


@dataclass
class Joint:
    """One joint element.

    Parameters
    ----------
    kind : str
        ``"masing"``, ``"jenkins"``, ``"iwan"``, ``"bouc_wen"``, ``"kelvin_voigt"`` or
        ``"normal"``.
    dof : int
        Degree of freedom the joint acts on.
    dof2 : int or None
        Second degree of freedom (``d = x[dof] - x[dof2]``); None: the fixed ground.
    params : dict
        Scalar parameters (see :data:`PARAMS`).
    arrays : dict
        Array parameters: ``x_points``/``f_points`` (tabulated Masing backbone), ``k``/``fs``
        (Iwan elements), ``coeffs`` (normal-contact ``k_s(d)`` polynomial, ascending).
    """

    kind: str
    dof: int
    dof2: int | None = None
    params: dict[str, float] = field(default_factory=dict)
    arrays: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def initial_stiffness(self) -> float:
        """Tangent stiffness at the virgin state (d = 0, no history), N/m."""
        p, a = self.params, self.arrays
        if self.kind == "masing":
            if "x_points" in a:
                xp, fp = a["x_points"], a["f_points"]
                return float(_pchip_slope0(xp, fp))
            return p["h0"] * p["ac"]
        if self.kind in ("jenkins", "kelvin_voigt"):
            return p["k"]
        if self.kind == "iwan":
            return float(np.sum(a["k"]))
        if self.kind == "bouc_wen":
            return p["alpha"]
        if self.kind == "normal":
            return float(a["coeffs"][0])
        if self.kind == "law":
            return decode_law(a["spec"]).initial_stiffness
        raise InputError(f"unknown joint kind {self.kind!r}")

    @property
    def viscous_damping(self) -> float:
        """Linear viscous coefficient the joint adds (Kelvin-Voigt ``c``), N s/m."""
        return self.params["c"] if self.kind == "kelvin_voigt" else 0.0

    def core_spec(self) -> tuple[str, int, int, np.ndarray, np.ndarray, np.ndarray]:
        """``(kind, dof, dof2 or -1, params, array_a, array_b)`` as the Rust core takes it."""
        p, a = self.params, self.arrays
        empty = np.zeros(0)
        j = -1 if self.dof2 is None else self.dof2
        if self.kind == "masing":
            if "x_points" in a:
                return (
                    "masing_tabulated",
                    self.dof,
                    j,
                    np.array([p["scale"]]),
                    a["x_points"],
                    a["f_points"],
                )
            return ("masing", self.dof, j, np.array([p["h0"], p["ac"], p["scale"]]), empty, empty)
        if self.kind == "iwan":
            return ("iwan", self.dof, j, empty, a["k"], a["fs"])
        if self.kind == "normal":
            return ("normal", self.dof, j, empty, a["coeffs"], empty)
        if self.kind == "law":
            return ("law", self.dof, j, empty, a["spec"], empty)
        vals = np.array([p[n] for n in PARAMS[self.kind]], dtype=float)
        return (self.kind, self.dof, j, vals, empty, empty)

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "dof": self.dof,
            "dof2": self.dof2,
            "params": {k: float(v) for k, v in self.params.items()},
            "arrays": {k: [float(x) for x in v] for k, v in self.arrays.items()},
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Joint:
        try:
            return make_joint(
                d["kind"],
                int(d["dof"]),
                None if d.get("dof2") is None else int(d["dof2"]),
                **dict(d.get("params", {})),
                **{k: np.asarray(v, float) for k, v in d.get("arrays", {}).items()},
            )
        except (KeyError, TypeError) as exc:
            raise InputError(f"joint description is incomplete or malformed: {exc}") from None


def _pchip_slope0(x: np.ndarray, f: np.ndarray) -> float:
    from scipy.interpolate import PchipInterpolator

    return float(PchipInterpolator(x, f).derivative()(0.0))


def _finite(name: str, v: Any, *, positive: bool = False, nonneg: bool = False) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(f"joint parameter {name} must be a number, got {v!r}") from None
    if not math.isfinite(x):
        raise InputError(f"joint parameter {name} is not finite ({x})")
    if positive and x <= 0:
        raise InputError(f"joint parameter {name} must be > 0, got {x}")
    if nonneg and x < 0:
        raise InputError(f"joint parameter {name} must be >= 0, got {x}")
    return x


def _array(name: str, v: Any) -> np.ndarray:
    a = np.ascontiguousarray(np.asarray(v, dtype=float).reshape(-1))
    if a.size == 0:
        raise InputError(f"joint array {name} is empty")
    if not np.all(np.isfinite(a)):
        i = int(np.argmax(~np.isfinite(a)))
        raise InputError(f"joint array {name}[{i}] is not finite ({a[i]})")
    return a


def make_joint(kind: str, dof: int, dof2: int | None = None, **kw: Any) -> Joint:
    """Validate parameters and build a :class:`Joint` (see :meth:`Structure.add_joint`)."""
    kind = str(kind).lower().replace("-", "_")
    aliases = {"boucwen": "bouc_wen", "kv": "kelvin_voigt", "normal_contact": "normal"}
    kind = aliases.get(kind, kind)

    def take(names: tuple[str, ...], **rules: dict[str, bool]) -> dict[str, float]:
        missing = [n for n in names if n not in kw]
        if missing:
            raise InputError(f"joint {kind!r} needs parameter(s) {', '.join(missing)}")
        return {n: _finite(n, kw.pop(n), **rules.get(n, {})) for n in names}

    params: dict[str, float] = {}
    arrays: dict[str, np.ndarray] = {}
    pos = {"positive": True}
    if kind == "masing":
        kw.setdefault("scale", 2.0)
        if "x_points" in kw or "f_points" in kw:
            if "x_points" not in kw or "f_points" not in kw:
                raise InputError("a tabulated Masing joint needs both x_points and f_points")
            arrays["x_points"] = _array("x_points", kw.pop("x_points"))
            arrays["f_points"] = _array("f_points", kw.pop("f_points"))
            params = take(("scale",), scale=pos)
        else:
            params = take(("h0", "ac", "scale"), h0=pos, ac=pos, scale=pos)
    elif kind == "jenkins":
        params = take(("k", "fs"), k=pos, fs=pos)
    elif kind == "iwan":
        if "k" not in kw or "fs" not in kw:
            raise InputError("an Iwan joint needs arrays k and fs (one entry per element)")
        arrays["k"] = _array("k", kw.pop("k"))
        arrays["fs"] = _array("fs", kw.pop("fs"))
        if arrays["k"].size != arrays["fs"].size:
            raise InputError(
                f"Iwan k has {arrays['k'].size} elements but fs has {arrays['fs'].size}"
            )
        if np.any(arrays["k"] <= 0) or np.any(arrays["fs"] <= 0):
            raise InputError("Iwan element stiffnesses k and slip forces fs must all be > 0")
    elif kind == "bouc_wen":
        kw.setdefault("nu", 1.0)
        params = take(("alpha", "beta", "gamma", "delta", "nu"), alpha=pos, nu=pos)
        if params["beta"] < 0:
            raise InputError(f"joint parameter beta must be >= 0, got {params['beta']}")
    elif kind == "kelvin_voigt":
        params = take(("k", "c"), k={"nonneg": True}, c={"nonneg": True})
    elif kind == "law":
        arrays["spec"] = _law_array(kw)
    elif kind == "normal":
        if "coeffs" not in kw:
            raise InputError("a normal-contact joint needs coeffs (k_s(d) = a1 + a2 d + ...)")
        arrays["coeffs"] = _array("coeffs", kw.pop("coeffs"))
    else:
        raise InputError(
            f"unknown joint kind {kind!r}: use masing, jenkins, iwan, bouc_wen, "
            "kelvin_voigt, normal or law"
        )
    if kw:
        raise InputError(f"joint {kind!r} does not take parameter(s) {', '.join(sorted(kw))}")
    return Joint(
        kind=kind,
        dof=int(dof),
        dof2=None if dof2 is None else int(dof2),
        params=params,
        arrays=arrays,
    )


def iwan_uniform(k_total: float, f_total: float, n: int = 20) -> dict[str, np.ndarray]:
    """Iwan elements for a uniform density of slip displacements on ``(0, φ_max]``.

    ``n`` Jenkins elements of stiffness ``k_total / n``; element ``i`` slips at displacement
    ``φ_i = φ_max (i + 1/2) / n``, i.e. at force ``fs_i = k_total φ_i / n``, with
    ``φ_max = 2 f_total / k_total`` so that the fully slipped joint carries ``f_total``. The
    virgin curve is then piecewise linear, close to the parabola ``k d − k² d² / (4 f_total)``
    up to ``d = φ_max``.

    Returns ``{"k": ..., "fs": ...}`` for ``add_joint("iwan", dof, **iwan_uniform(...))``.

    Examples
    --------
    >>> e = iwan_uniform(1e5, 10.0, n=4)
    >>> float(e["k"].sum()), float(e["fs"].sum())
    (100000.0, 10.0)
    """
    k_total = _finite("k_total", k_total, positive=True)
    f_total = _finite("f_total", f_total, positive=True)
    if int(n) < 1:
        raise InputError(f"n must be >= 1, got {n}")
    n = int(n)
    phi = 2.0 * f_total / k_total * (np.arange(n) + 0.5) / n
    return {"k": np.full(n, k_total / n), "fs": k_total / n * phi}


#: Kind codes of the flat encoding of a joint-law spec (the Rust core's
#: ``contactlab_core::joints::AnyLaw::from_flat`` reads the same table).
LAW_CODES: tuple[str, ...] = (
    "jenkins",
    "iwan",
    "segalman",
    "masing",
    "maxwell_slip",
    "gms",
    "dahl",
    "lugre",
    "bouc_wen",
    "kelvin_voigt",
    "parallel",
    "series",
    "backlash",
)


def encode_law(law: Any) -> np.ndarray:
    """Flat float encoding of a :class:`contactlab.joints.JointLaw` (or its spec):
    ``[code, n_params, params..., n_children, children...]``, depth first."""
    spec = law.spec() if hasattr(law, "spec") else law
    out: list[float] = []

    def walk(sp: Any) -> None:
        kind, params, children = sp
        out.extend([float(LAW_CODES.index(kind)), float(len(params)), *map(float, params)])
        out.append(float(len(children)))
        for c in children:
            walk(c)

    walk(spec)
    return np.asarray(out, dtype=float)


def decode_law(flat: Any) -> Any:
    """The :class:`contactlab.joints.JointLaw` of a flat encoding (:func:`encode_law`)."""
    from ..joints import from_spec

    v = [float(x) for x in np.asarray(flat, dtype=float).reshape(-1)]
    pos = 0

    def take() -> float:
        nonlocal pos
        if pos >= len(v):
            raise InputError("joint-law encoding ends early")
        pos += 1
        return v[pos - 1]

    def walk() -> tuple[str, list[float], list[Any]]:
        code = int(take())
        if not 0 <= code < len(LAW_CODES):
            raise InputError(f"joint-law encoding has an unknown kind code {code}")
        params = [take() for _ in range(int(take()))]
        children = [walk() for _ in range(int(take()))]
        return (LAW_CODES[code], params, children)

    spec = walk()
    if pos != len(v):
        raise InputError("joint-law encoding has trailing values")
    return from_spec(spec)


def _law_array(kw: dict[str, Any]) -> np.ndarray:
    """The ``spec`` array of a ``law`` joint from ``law=`` (a JointLaw) or ``spec=`` (its
    encoding, as :meth:`Joint.to_dict` stores it)."""
    from ..joints import JointLaw

    if "law" in kw:
        law = kw.pop("law")
        if not isinstance(law, JointLaw):
            raise InputError(f"joint 'law' needs a contactlab.joints law, got {type(law).__name__}")
    elif "spec" in kw:
        law = decode_law(_array("spec", kw.pop("spec")))
    else:
        raise InputError("joint 'law' needs law=<a contactlab.joints law>")
    return encode_law(law)
