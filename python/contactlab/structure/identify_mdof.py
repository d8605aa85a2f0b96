"""Identification of a structure with several degrees of freedom and one joint.

Every DOF's displacement is measured (``y`` is ``n_samples × n_dofs``). The linear part is
parameterised either as a chain of masses (``structure="chain"``: masses ``m{i}``, springs
``k{i}`` and dashpots ``c{i}`` between DOF ``i−1`` and DOF ``i``, element 0 to the ground or
base) or by masks of free entries of ``M``, ``C`` and ``K`` (symmetric; parameters
``M[i,j]``, ``C[i,j]``, ``K[i,j]`` for ``i ≤ j``). In both cases each matrix is a sum of
parameter × basis matrix, so the model stays linear in its linear parameters:

    ``M x'' + C x' + K x + b F_joint(bᵀ x) = e_in u``     (force ``u`` at ``input_dof``)
    ``M x'' + C (x' − r ẏ) + K (x − r y) + b F_joint = 0`` (base motion ``y``, ``r`` = ones)

with ``b = e_i − e_j`` the joint's direction (``joint_dofs=(i, j)``; ``j = None``: the fixed
ground). A ``kelvin_voigt`` joint (``kj``, ``cj``) is one more spring and dashpot across
``b``: it is accepted only where the pattern has no stiffness or damping entry along the same
direction (e.g. masks of grounded masses and the joint between them). Starting values come
from the equation error of these equations (derivatives of
the measured displacements), with and without a Coulomb term ``fs sign(bᵀ x')``; the
output-error fit (:func:`contactlab.fitting.least_squares_fit`) then refines all parameters
and the initial state ``x0``, ``v0`` of every DOF, from several starts fitted on a short
stretch of the record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import as_1d
from .._physical import MAX_MAGNITUDE, check_channel
from ..errors import ContactLabError, InputError
from ..fitting import Parameter, least_squares_fit
from .fitkit import (
    add_fitted_joint,
    best_start,
    column_derivatives,
    hold_state,
    noise_model_covariance,
)
from .model import Structure

MDOF_JOINTS = ("masing", "jenkins", "iwan", "bouc_wen", "kelvin_voigt", "linear")


@dataclass
class Pattern:
    """Which entries of ``M``, ``C``, ``K`` are parameters: ``basis[kind]`` lists
    ``(name, matrix)`` pairs, each matrix = ∂(M, C or K)/∂parameter."""

    n: int
    kind: str  # "chain" or "masks"
    basis: dict[str, list[tuple[str, np.ndarray]]]

    def matrix(self, kind: str, v: dict[str, float]) -> np.ndarray:
        out = np.zeros((self.n, self.n))
        for name, b in self.basis[kind]:
            out += v[name] * b
        return out

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "n": self.n,
            "parameters": {k: [name for name, _ in lst] for k, lst in self.basis.items()},
        }


def chain_pattern(n: int) -> Pattern:
    """Chain of ``n`` masses: element ``i`` joins DOF ``i−1`` (the ground for ``i = 0``)
    to DOF ``i``."""
    eye = np.eye(n)
    basis: dict[str, list[tuple[str, np.ndarray]]] = {"M": [], "C": [], "K": []}
    for i in range(n):
        basis["M"].append((f"m{i}", np.outer(eye[i], eye[i])))
        b = eye[i] - (eye[i - 1] if i > 0 else 0.0)
        for kind, p in (("C", "c"), ("K", "k")):
            basis[kind].append((f"{p}{i}", np.outer(b, b)))
    return Pattern(n, "chain", basis)


def _mask(a: Any, name: str, n: int | None) -> np.ndarray:
    try:
        m = np.asarray(a, dtype=bool)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} cannot be read as a boolean mask: {exc}") from None
    if m.ndim != 2 or m.shape[0] != m.shape[1]:
        raise InputError(f"{name} must be a square boolean matrix, got shape {m.shape}")
    if n is not None and m.shape[0] != n:
        raise InputError(f"{name} is {m.shape[0]}×{m.shape[0]}, expected {n}×{n}")
    if not np.array_equal(m, m.T):
        i, j = np.argwhere(m != m.T)[0]
        raise InputError(f"{name} must be symmetric: [{i}, {j}] differs from [{j}, {i}]")
    return m


def mask_pattern(masks: dict[str, Any], n: int) -> Pattern:
    """Free entries of ``M``, ``C``, ``K`` given as symmetric boolean masks (a missing
    ``M`` mask: the diagonal; missing ``C``: the same as ``K``)."""
    unknown = sorted(set(masks) - {"M", "C", "K"})
    if unknown:
        raise InputError(f"masks are given for M, C and K only, not {', '.join(unknown)}")
    mk = {k: _mask(v, f"{k} mask", n) for k, v in masks.items() if v is not None}
    if "K" not in mk:
        raise InputError("masks need at least the K mask (free entries of the stiffness)")
    for kind, m in mk.items():
        if not np.all(np.diag(m)):
            i = int(np.argmin(np.diag(m)))
            raise InputError(f"the {kind} mask must free every diagonal entry ([{i}, {i}] isn't)")
    mk.setdefault("M", np.eye(n, dtype=bool))
    mk.setdefault("C", mk["K"].copy())
    basis: dict[str, list[tuple[str, np.ndarray]]] = {"M": [], "C": [], "K": []}
    for kind in ("M", "C", "K"):
        for i in range(n):
            for j in range(i, n):
                if mk[kind][i, j]:
                    b = np.zeros((n, n))
                    b[i, j] = b[j, i] = 1.0
                    basis[kind].append((f"{kind}[{i},{j}]", b))
    return Pattern(n, "masks", basis)


def pattern_from_dict(d: dict[str, Any]) -> Pattern:
    n = int(d["n"])
    if d["kind"] == "chain":
        return chain_pattern(n)
    names = d["parameters"]
    masks = {}
    for kind in ("M", "C", "K"):
        m = np.zeros((n, n), dtype=bool)
        for name in names[kind]:
            i, j = (int(s) for s in name[2:-1].split(","))
            m[i, j] = m[j, i] = True
        masks[kind] = m
    return mask_pattern(masks, n)


# ------------------------------------------------------------------ the joint
def build_mdof(
    pattern: Pattern,
    joint: str,
    v: dict[str, float],
    joint_dofs: tuple[int, int | None],
    mass: np.ndarray | None = None,
) -> Structure:
    M = mass if mass is not None else pattern.matrix("M", v)
    s = Structure(M, pattern.matrix("C", v), pattern.matrix("K", v))
    add_fitted_joint(s, joint, v, joint_dofs[0], joint_dofs[1])
    return s


# ------------------------------------------------------------------ equation error
def equation_error_mdof(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    pattern: Pattern,
    excitation: str,
    input_dof: int,
    joint_dofs: tuple[int, int | None],
    mass: np.ndarray | None,
    *,
    periodic: bool = False,
    joint_stiffness: float = 0.0,
    coulomb: bool = False,
) -> dict[str, Any]:
    """Least-squares values of the pattern's parameters from the equations of motion.

    ``joint_stiffness``: the joint taken as a linear spring of this stiffness (its force is
    moved to the right-hand side); ``coulomb``: a Coulomb force ``fs sign(bᵀ x')`` is fitted
    with the rest (``fs`` in the result). Returns ``values`` (name → value), ``fs`` and the
    force the joint must supply (``joint_force``: ``bᵀ``-projection of the residual force).
    """
    n = pattern.n
    xd, xdd = column_derivatives(t, y, periodic)
    b = np.zeros(n)
    b[joint_dofs[0]] = 1.0
    if joint_dofs[1] is not None:
        b[joint_dofs[1]] = -1.0
    if excitation == "base":
        ud = column_derivatives(t, u[:, None], periodic)[0][:, 0]
        xs, xds = y - u[:, None], xd - ud[:, None]
        rhs = -(xdd @ mass.T) if mass is not None else np.zeros_like(y)
    else:
        xs, xds = y, xd
        rhs = np.zeros_like(y)
        rhs[:, input_dof] = u
        if mass is not None:
            rhs = rhs - xdd @ mass.T
    d = y @ b
    rhs = rhs - joint_stiffness * np.outer(d, b)
    cols, names = [], []
    groups = [("C", xds), ("K", xs)] if mass is not None else [("M", xdd), ("C", xds), ("K", xs)]
    for kind, z in groups:
        for name, B in pattern.basis[kind]:
            cols.append((z @ B.T).reshape(-1))
            names.append(name)
    if coulomb:
        cols.append(np.outer(np.sign(xd @ b), b).reshape(-1))
        names.append("fs")
    A = np.stack(cols, axis=1)
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    coef, *_ = np.linalg.lstsq(A / norms, rhs.reshape(-1), rcond=None)
    coef = coef / norms
    vals = dict(zip(names, (float(c) for c in coef), strict=True))
    fs = vals.pop("fs", 0.0)
    res = (rhs.reshape(-1) - A @ coef).reshape(y.shape)
    return {
        "values": vals,
        "fs": fs,
        "joint_force": res @ b / float(b @ b) + joint_stiffness * d,
    }


def _positive_starts(pattern: Pattern, vals: dict[str, float]) -> dict[str, float]:
    """Starting values with the sign a physical structure needs: chain elements and
    diagonal entries positive (a negative equation-error value, e.g. from a short, noisy
    record, is replaced by a tenth of the largest of its kind)."""
    out = dict(vals)
    for lst in pattern.basis.values():
        positive = [n for n, B in lst if pattern.kind == "chain" or B.trace() > 0]
        top = max([out.get(n, 0.0) for n in positive] + [0.0])
        for name in positive:
            if name in out and not out[name] > 0:
                out[name] = 0.1 * top if top > 0 else 1.0
    return out


# ------------------------------------------------------------------ parameters
def _joint_params(
    joint: str, kj: float, fs: float, st: dict[str, float], dr: float, cj: float = 0.0
) -> list:
    if joint == "kelvin_voigt":
        return [
            Parameter("kj", kj, min=0.0, unit="N/m"),
            Parameter("cj", cj, min=0.0, unit="N s/m"),
        ]
    if joint == "bouc_wen":
        return [
            Parameter("alpha", kj, min=1e-9 * kj, unit="N/m"),
            Parameter("gamma", st["gamma"] / dr, unit="1/m", scale=1 / dr),
            Parameter("delta", st["delta"] / dr, unit="1/m", scale=1 / dr),
            Parameter("nu", 1.0, min=0.25, max=4.0, vary=st.get("fit_nu", True), unit=""),
        ]
    if joint == "masing":
        return [
            Parameter("h0", fs, min=0.0, unit="N"),
            Parameter("ac", kj / fs, min=0.0, unit="1/m"),
        ]
    if joint in ("jenkins", "iwan"):
        return [Parameter("kj", kj, min=0.0, unit="N/m"), Parameter("fs", fs, min=0.0, unit="N")]
    return []


def _mdof_starts(joint: str) -> list[dict[str, float]]:
    if joint == "kelvin_voigt":
        return [{"k_frac": 0.5}]
    if joint == "bouc_wen":
        return [
            {"gamma": g, "delta": d, "k_frac": 0.5}
            for (g, d) in ((0.5, -0.5), (0.5, 0.5), (-0.25, 0.5))
        ]
    if joint in ("masing", "jenkins", "iwan"):
        return [{"f_frac": f, "k_frac": kf} for f in (0.1, 0.5) for kf in (0.5,)] + [
            {"coulomb": 1.0, "f_frac": f, "kj_frac": kf} for f in (0.7, 1.4) for kf in (3.0, 30.0)
        ]
    return [{}]


def _start_params(
    st: dict[str, float],
    ee: Any,
    pattern: Pattern,
    joint: str,
    b: np.ndarray,
    d_rms: float,
    mass: np.ndarray | None,
    x0: np.ndarray,
    v0: np.ndarray,
    y_rms: float,
) -> list[Parameter]:
    """One start's parameters: ``ee(joint_stiffness, coulomb)`` is the equation error."""
    base = ee(0.0, False)
    lin = _positive_starts(pattern, base["values"])
    kb = float(b @ pattern.matrix("K", lin) @ b)  # stiffness seen across the joint
    kb = kb if kb > 0 else max(abs(v) for n, v in lin.items() if n[0] in "kK")
    if joint == "linear" or not st:
        vals, kj, fs = lin, 0.0, 0.0
    elif st.get("coulomb"):
        cf = ee(0.0, True)
        vals = _positive_starts(pattern, cf["values"])
        kj = st["kj_frac"] * kb
        fs = st["f_frac"] * cf["fs"] if cf["fs"] > 0 else st["f_frac"] * kb * d_rms
    else:
        kj = st["k_frac"] * kb
        vals = _positive_starts(pattern, ee(kj, False)["values"])
        fs = st.get("f_frac", 0.5) * kj * d_rms
    ps: list[Parameter] = []
    for kind, unit in (("M", "kg"), ("C", "N s/m"), ("K", "N/m")):
        if kind == "M" and mass is not None:
            continue
        scale = max(abs(vals[n]) for n, _ in pattern.basis[kind])
        for name, B in pattern.basis[kind]:
            positive = pattern.kind == "chain" or B.trace() > 0
            sc = max(abs(vals[name]), 1e-3 * scale, 1e-300)
            lo = 0.0 if positive else -math.inf
            ps.append(Parameter(name, vals[name], min=lo, unit=unit, scale=sc))
    cb = float(b @ pattern.matrix("C", vals) @ b)  # damping seen across the joint
    cj = (
        0.5 * cb
        if cb > 0
        else 1e-3
        * math.sqrt(
            max(kj, 1e-300) * max(float(np.trace(mass)) if mass is not None else 1.0, 1e-300)
        )
    )
    ps += _joint_params(joint, max(kj, 1e-300), max(fs, 1e-300), st, max(d_rms, 1e-300), cj)
    for i in range(pattern.n):
        ps.append(Parameter(f"x0_{i}", float(x0[i]), unit="m", scale=y_rms))
        ps.append(Parameter(f"v0_{i}", float(v0[i]), unit="m/s", scale=y_rms * 2 * np.pi * 10))
    return ps


# ------------------------------------------------------------------ identify
def identify_mdof(
    t: Any,
    u: Any,
    y: Any,
    joint: str,
    excitation: str,
    *,
    structure: Any = "chain",
    masks: dict[str, Any] | None = None,
    joint_dofs: Any = (0, None),
    input_dof: int | None = None,
    mass: Any = None,
    substeps: int = 4,
    interpolation: str = "auto",
    periodic: bool | None = None,
    multistart: bool = True,
    start_samples: int = 4096,
    max_nfev: int = 200,
    estimate_initial_state: bool = True,
) -> dict[str, Any]:
    """Multi-DOF :func:`~contactlab.structure.identify` (``y`` 2-D; see there): the fields of
    the :class:`~contactlab.structure.IdentifiedModel` it builds."""
    if joint not in MDOF_JOINTS:
        raise InputError(
            f"with several DOFs, joint must be one of {', '.join(MDOF_JOINTS)}; got {joint!r}"
        )
    t, u, y = _checked_mdof_record(t, u, y)
    nt, n = y.shape
    pattern = _pattern(structure, masks, n)
    i_j, j_j, input_dof = _dofs(joint_dofs, input_dof, excitation, n)
    mass_m = _mass_matrix(mass, n, excitation)
    if interpolation == "auto":
        interpolation = "fourier" if periodic else "linear"
    if periodic is None:
        periodic = interpolation == "fourier"
    b = np.zeros(n)
    b[i_j] = 1.0
    if j_j is not None:
        b[j_j] = -1.0
    jdofs = (i_j, j_j)
    if joint == "kelvin_voigt":
        _check_kv_joint(pattern, b, i_j, j_j)

    def ee(kj: float, coulomb: bool) -> dict[str, Any]:
        return equation_error_mdof(
            t,
            u,
            y,
            pattern,
            excitation,
            input_dof or 0,
            jdofs,
            mass_m,
            periodic=bool(periodic),
            joint_stiffness=kj,
            coulomb=coulomb,
        )

    xd, _ = column_derivatives(t, y, bool(periodic))
    d_rms = max(float(np.std(y @ b)), 1e-300)
    y_rms = max(float(np.std(y)), 1e-300)
    # from the measured start when the state is estimated, else the record starts from rest
    x0s, v0s = (y[0], xd[0]) if estimate_initial_state else (np.zeros(n), np.zeros(n))

    residual_on = _MdofResidual(
        t, u, y, interpolation, excitation, input_dof, pattern, joint, jdofs, mass_m
    )

    starts = _mdof_starts(joint)
    records: list[dict[str, Any]] = []

    def params(st: dict[str, float]) -> list[Parameter]:
        ps = _start_params(st, ee, pattern, joint, b, d_rms, mass_m, x0s, v0s, y_rms)
        return hold_state(ps, estimate_initial_state, prefixes=("x0_", "v0_"))

    best_ps = params(starts[0])
    if multistart and len(starts) > 1:
        n_s = min(int(start_samples), nt)
        tried = [(st, params(st)) for st in starts]
        best_ps = best_start(tried, residual_on(n_s, 2), records) or best_ps
    fit = least_squares_fit(
        residual_on(nt, substeps), best_ps, max_nfev=max_nfev, ftol=1e-7, xtol=1e-7, gtol=1e-10
    )
    # residuals correlated in time and across DOFs (input noise reaches every DOF)
    v = fit.values
    r_fit = residual_on(nt, substeps)(v)
    fit, noise = noise_model_covariance(
        fit, lambda du: residual_on(nt, substeps, u + du)(v) - r_fit, u, n
    )
    return {
        "structure": build_mdof(pattern, joint, v, jdofs, mass_m),
        "joint": joint,
        "excitation": excitation,
        "fit": fit,
        "x0": [float(v[f"x0_{i}"]) for i in range(n)],
        "v0": [float(v[f"v0_{i}"]) for i in range(n)],
        "substeps": int(substeps),
        "interpolation": interpolation,
        "rms": float(np.sqrt(fit.chisqr / max(fit.ndata, 1))),
        "starts": records,
        "input_dof": input_dof if excitation == "force" else None,
        "joint_dofs": jdofs,
        "pattern": pattern,
        "noise": noise,
    }


class _MdofResidual:
    """The output-error residual of a multi-DOF model on the first ``nn`` samples: every
    DOF's simulated minus measured displacement, flattened (a large constant where the
    simulation fails or stops early); ``u_in`` replaces the input (the noise model)."""

    def __init__(
        self,
        t: np.ndarray,
        u: np.ndarray,
        y: np.ndarray,
        interpolation: str,
        excitation: str,
        input_dof: int | None,
        pattern: Any,
        joint: str,
        jdofs: tuple[int, int | None],
        mass_m: np.ndarray | None,
    ) -> None:
        self.t, self.u, self.y = t, u, y
        self.interpolation, self.excitation, self.input_dof = interpolation, excitation, input_dof
        self.pattern, self.joint, self.jdofs, self.mass_m = pattern, joint, jdofs, mass_m

    def __call__(self, nn: int, sub: int, u_in: np.ndarray | None = None) -> Any:
        t, u, y = self.t, self.u, self.y
        nt, n = y.shape
        interpolation, excitation, input_dof = self.interpolation, self.excitation, self.input_dof
        pattern, joint, jdofs, mass_m = self.pattern, self.joint, self.jdofs, self.mass_m
        tt, uu, yy = t[:nn], (u[:nn] if u_in is None else u_in), y[:nn]
        interp = interpolation if nn == nt else "linear"
        fail = 10 * float(np.max(np.abs(yy))) + 1.0
        if excitation == "force":
            f = np.zeros((nn, n))
            f[:, input_dof] = uu
            kw: dict[str, Any] = {"force": f}
        else:
            kw = {"base": uu}

        def res(v: dict[str, float]) -> np.ndarray:
            try:
                s = build_mdof(pattern, joint, v, jdofs, mass_m)
                r = s.simulate(
                    tt,
                    x0=[v[f"x0_{i}"] for i in range(n)],
                    v0=[v[f"v0_{i}"] for i in range(n)],
                    substeps=sub,
                    interpolation=interp,
                    **kw,
                )
            except ContactLabError:
                return np.full(nn * n, 100 * fail)
            x = np.asarray(r.x).reshape(-1, n)
            if x.shape[0] < nn:
                x = np.concatenate([x, np.full((nn - x.shape[0], n), fail)])
            return (x - yy).reshape(-1)

        return res


def _checked_mdof_record(t: Any, u: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Several DOFs' record as checked arrays: ``y`` (samples × DOFs) finite, same lengths,
    enough samples, physical magnitudes, increasing time."""
    t = as_1d(t, "t")
    u = as_1d(u, "u")
    try:
        y = np.array(y, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"y cannot be converted to a float array: {exc}") from None
    if y.ndim != 2:
        raise InputError(f"y must be (n_samples, n_dofs), got shape {y.shape}")
    if not np.all(np.isfinite(y)):
        i, j = np.argwhere(~np.isfinite(y))[0]
        raise InputError(f"y[{i}, {j}] is not finite")
    nt, n = y.shape
    if not (t.size == u.size == nt):
        raise InputError(f"t, u and y differ in length ({t.size}, {u.size}, {nt})")
    if nt < 20:
        raise InputError(f"{nt} samples are too few to identify a structure")
    big = float(np.max(np.abs(u)))
    if big > MAX_MAGNITUDE:
        raise InputError(
            f"u reaches {big:.3g}: beyond any physical input; a unit mix-up or a corrupt file?"
        )
    for j in range(n):  # each DOF's displacement: in range, not zero, not constant
        check_channel(f"y[:, {j}]", y[:, j], "m", f"displacement (DOF {j})")
    if np.any(np.diff(t) <= 0):
        raise InputError("t must be strictly increasing")
    return t, u, y


def _pattern(structure: Any, masks: dict[str, Any] | None, n: int) -> Any:
    """The free entries of ``M``, ``C``, ``K``: a chain of ``n`` DOFs or the given masks."""
    if isinstance(structure, str) and structure == "chain" and masks is None:
        return chain_pattern(n)
    elif masks is not None or structure == "masks":
        return mask_pattern(dict(masks or {}), n)
    else:
        raise InputError(
            f"structure must be 'chain' or masks=... of free entries, got {structure!r}"
        )


def _dofs(
    joint_dofs: Any, input_dof: int | None, excitation: str, n: int
) -> tuple[int, int | None, int | None]:
    """The joint's DOFs ``(i, j or None)`` and the force's DOF, checked against ``n``."""
    try:
        jd = tuple(joint_dofs)
        i_j = int(jd[0])
        j_j = None if len(jd) < 2 or jd[1] is None else int(jd[1])
    except (TypeError, ValueError, IndexError):
        raise InputError(f"joint_dofs must be (i, j) or (i, None), got {joint_dofs!r}") from None
    for d in (i_j, j_j):
        if d is not None and not 0 <= d < n:
            raise InputError(f"joint_dofs {joint_dofs!r}: DOF {d} is outside 0..{n - 1}")
    if i_j == j_j:
        raise InputError("joint_dofs must name two different DOFs (or one and None: ground)")
    if excitation == "force":
        input_dof = n - 1 if input_dof is None else int(input_dof)
        if not 0 <= input_dof < n:
            raise InputError(f"input_dof = {input_dof} is outside 0..{n - 1}")
    return i_j, j_j, input_dof


def _mass_matrix(mass: Any, n: int, excitation: str) -> np.ndarray | None:
    """The given masses as an ``n``×``n`` matrix (None: to be identified)."""
    mass_m = None
    if mass is not None:
        mm = np.asarray(mass, dtype=float)
        mass_m = np.diag(mm) if mm.ndim == 1 else mm
        if mass_m.shape != (n, n) or not np.all(np.isfinite(mass_m)):
            raise InputError(f"mass must be {n} masses or an {n}×{n} matrix, got {mm.shape}")
        if np.any(np.diag(mass_m) <= 0):
            raise InputError("mass: every diagonal entry must be > 0")
    elif excitation == "base":
        raise InputError("base excitation needs the masses: pass mass=[m0, m1, ...] (kg)")
    return mass_m


def _check_kv_joint(pattern: Any, b: np.ndarray, i_j: int, j_j: int | None) -> None:
    """A linear spring-damper across the joint is one more stiffness and damping entry:
    identifiable only where the pattern has none along the same direction."""
    bb = np.outer(b, b).ravel()
    for kind, what in (("K", "spring"), ("C", "dashpot")):
        Bm = np.stack([B.ravel() for _, B in pattern.basis[kind]], axis=1)
        coef, *_ = np.linalg.lstsq(Bm, bb, rcond=None)
        if np.linalg.norm(Bm @ coef - bb) < 1e-9:
            where = "the ground" if j_j is None else f"DOF {j_j}"
            raise InputError(
                f"a Kelvin-Voigt joint between DOF {i_j} and {where} duplicates the "
                f"structure's own {what} there ({kind} entries of the "
                f"{pattern.kind}); give masks= that leave that coupling out"
            )
