"""A linear structure ``(M, C, K)`` with joint elements, simulated by the Rust core.

``M x'' + C x' + K x + Σ F_j = f(t) + K r y(t) + C r ẏ(t)``: force input ``f`` and/or a
prescribed base (ground) displacement ``y`` whose velocity ``ẏ`` is taken from the samples
(second-order finite differences, or given); ``r`` is the influence vector (ones: the whole
structure stands on one moving base). Joints attach to the fixed ground, not to the base
(a frame rubbing on a wall). Integration: implicit Newmark average acceleration with Newton
iterations on the joint forces, steps split at reversals and stick-slip transitions, outputs
exactly at the samples; by default error-controlled (step doubling with Richardson
extrapolation, fourth order, in the Rust core), or ``substeps`` fixed steps per sample.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import _core
from .._arrays import as_1d
from .._io_atomic import write_text
from ..errors import InputError
from .joints import Joint, make_joint
from .modal import Modes, modes


def _matrix(a: Any, name: str, n: int | None = None) -> np.ndarray:
    try:
        m = np.asarray(a, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} cannot be converted to a float matrix: {exc}") from None
    if m.ndim == 0:
        m = m.reshape(1, 1)
    if m.ndim == 1 and m.size == 1:
        m = m.reshape(1, 1)
    if m.ndim != 2 or m.shape[0] != m.shape[1]:
        raise InputError(f"{name} must be a square matrix (or a scalar), got shape {m.shape}")
    if n is not None and m.shape[0] != n:
        raise InputError(f"{name} is {m.shape[0]}×{m.shape[0]} but M is {n}×{n}")
    if not np.all(np.isfinite(m)):
        i, j = np.argwhere(~np.isfinite(m))[0]
        raise InputError(f"{name}[{i}, {j}] is not finite ({m[i, j]})")
    return np.ascontiguousarray(m)


@dataclass
class SimulationResult:
    """Sampled response of :meth:`Structure.simulate`, in the manner of scipy's ``OdeResult``.

    Attributes
    ----------
    t : ndarray (nt,)
    x, v, a : ndarray (nt,) for one DOF, else (nt, n)
        Displacement [m], velocity [m/s], acceleration [m/s²] (absolute, also under base
        excitation).
    joint_force : ndarray (nt, n_joints)
        Force each joint exerts on its ``dof`` [N].
    joint_energy : ndarray (nt, n_joints)
        Cumulative energy dissipated by each joint [J] (work minus stored energy).
    joint_work : ndarray (nt, n_joints)
        Cumulative work done on each joint [J].
    input_work, damping_work : ndarray (nt,)
        Cumulative work of the external (and base) forces and of ``C`` [J].
    success, status, message
        ``status`` 0 on success, -1 when an integration step failed; a failed run returns
        the samples computed up to there (``len(t)`` may be shorter than requested).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    joint_force: np.ndarray
    joint_energy: np.ndarray
    joint_work: np.ndarray
    input_work: np.ndarray
    damping_work: np.ndarray
    success: bool
    status: int
    message: str
    n_steps: int = 0
    n_iter: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def response(self) -> np.ndarray:
        """``x``: the main output, as :class:`contactlab.simulation.SimulatedResponse` names
        it."""
        return self.x

    def kinetic_energy(self, M: np.ndarray) -> np.ndarray:
        v = self.v.reshape(len(self.t), -1)
        return 0.5 * np.einsum("ti,ij,tj->t", v, M, v)

    def strain_energy(self, K: np.ndarray) -> np.ndarray:
        x = self.x.reshape(len(self.t), -1)
        return 0.5 * np.einsum("ti,ij,tj->t", x, K, x)


class Structure:
    """A linear structure with joints.

    Parameters
    ----------
    M, C, K : array_like (n, n) or scalar
        Mass [kg], viscous damping [N s/m] and stiffness [N/m] matrices.

    Examples
    --------
    >>> import numpy as np
    >>> s = Structure(2.0, 4.0, 800.0)
    >>> _ = s.add_joint("jenkins", 0, k=200.0, fs=1.0)
    >>> md = s.modes()              # linearised: K + joint initial stiffness
    >>> round(float(md.frequency_hz[0]), 4)
    3.5588
    >>> t = np.linspace(0, 1, 201)
    >>> r = s.simulate(t, force=2.0 * np.sin(2 * np.pi * 3 * t))
    >>> r.success, r.x.shape, r.joint_force.shape
    (True, (201,), (201, 1))
    """

    def __init__(self, M: Any, C: Any, K: Any) -> None:
        self.M = _matrix(M, "M")
        n = self.M.shape[0]
        self.C = _matrix(C, "C", n)
        self.K = _matrix(K, "K", n)
        self.joints: list[Joint] = []

    @property
    def n(self) -> int:
        return int(self.M.shape[0])

    def add_joint(self, kind: str, dof: int = 0, dof2: int | None = None, **params: Any) -> Joint:
        """Add a joint between ``dof`` and ``dof2`` (None: the fixed ground); returns it.

        ``kind`` and parameters: ``"masing"`` (``h0``, ``ac``, ``scale=2`` or ``x_points``,
        ``f_points``, ``scale``), ``"jenkins"`` (``k``, ``fs``), ``"iwan"`` (arrays ``k``,
        ``fs``; see :func:`~contactlab.structure.iwan_uniform`), ``"bouc_wen"`` (``alpha``,
        ``beta``, ``gamma``, ``delta``, ``nu=1``), ``"kelvin_voigt"`` (``k``, ``c``),
        ``"normal"`` (``coeffs`` of ``k_s(d)``, ascending). See
        :mod:`contactlab.structure.joints` for the laws.
        """
        for name, d in (("dof", dof), ("dof2", dof2)):
            if d is not None and not (0 <= int(d) < self.n):
                raise InputError(f"joint {name} = {d} is outside 0..{self.n - 1}")
        if dof2 is not None and int(dof2) == int(dof):
            raise InputError("a joint's dof and dof2 must differ")
        j = make_joint(kind, int(dof), None if dof2 is None else int(dof2), **params)
        self.joints.append(j)
        return j

    def linearised(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(M, C, K)`` with each joint's initial tangent stiffness (virgin state) in K and a
        Kelvin-Voigt joint's ``c`` in C."""
        K = self.K.copy()
        C = self.C.copy()
        for j in self.joints:
            for mat, g in ((K, j.initial_stiffness), (C, j.viscous_damping)):
                mat[j.dof, j.dof] += g
                if j.dof2 is not None:
                    mat[j.dof2, j.dof2] += g
                    mat[j.dof, j.dof2] -= g
                    mat[j.dof2, j.dof] -= g
        return self.M.copy(), C, K

    def modes(self) -> Modes:
        """Natural frequencies [Hz], damping ratios and mode shapes of the linearised structure.

        Joints contribute their initial tangent stiffness (the virgin state at d = 0: Masing
        ``h0·ac`` or the tabulated backbone's slope at 0, Jenkins ``k``, Iwan ``Σ k_i``,
        Bouc-Wen ``α``, Kelvin-Voigt ``k`` (and ``c`` to the damping), normal contact
        ``k_s(0)``). Returns a :class:`~contactlab.structure.modal.Modes`: ``frequency_hz``,
        ``damping_ratio`` (modal projection ``φᵀCφ / 2ω``), ``shapes`` (n × m, mass-normalised
        columns), ``damped_frequency_hz`` and ``state_damping_ratio`` (state-space
        eigenvalues).
        """
        return modes(*self.linearised())

    modal = modes

    # ----------------------------------------------------------------- simulation
    def _inputs(
        self, t: np.ndarray, force: Any, base: Any, base_velocity: Any, influence: Any
    ) -> dict[str, Any]:
        nt, n = t.size, self.n
        kw: dict[str, Any] = {}
        if force is not None:
            f = np.asarray(force, dtype=float)
            if f.ndim == 1 and n == 1:
                f = f.reshape(-1, 1)
            if f.ndim == 1:
                raise InputError(
                    f"force must be (len(t), {n}) for a {n}-DOF structure, got a 1-D array"
                )
            if f.shape != (nt, n):
                raise InputError(f"force has shape {f.shape}, expected ({nt}, {n})")
            if not np.all(np.isfinite(f)):
                i = int(np.argmax(~np.isfinite(f).all(axis=1)))
                raise InputError(f"force[{i}] is not finite")
            kw["force"] = np.ascontiguousarray(f.reshape(-1))
        if base is not None:
            y = as_1d(base, "base")
            if y.size != nt:
                raise InputError(f"base has {y.size} samples but t has {nt}")
            if base_velocity is None:
                with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                    yd = np.gradient(y, t, edge_order=2) if nt > 2 else np.gradient(y, t)
                if not np.all(np.isfinite(yd)):
                    i = int(np.argmax(~np.isfinite(yd)))
                    raise InputError(
                        f"the base velocity (the derivative of the base displacement) is out "
                        f"of the double-precision range at sample {i} (base {y[i]:.3g} m, "
                        "time steps too short for such a displacement)"
                    )
            else:
                yd = as_1d(base_velocity, "base_velocity")
                if yd.size != nt:
                    raise InputError(f"base_velocity has {yd.size} samples but t has {nt}")
            r = np.ones(n) if influence is None else as_1d(influence, "influence")
            if r.size != n:
                raise InputError(f"influence has {r.size} entries, expected {n}")
            kw.update(
                base=y,
                base_velocity=np.ascontiguousarray(yd),
                kr=np.ascontiguousarray(self.K @ r),
                cr=np.ascontiguousarray(self.C @ r),
            )
        if not kw:
            kw["force"] = np.zeros(nt * n)
        return kw

    def simulate(
        self,
        t: Any,
        force: Any = None,
        base: Any = None,
        x0: Any = None,
        v0: Any = None,
        *,
        periodic: bool = False,
        base_velocity: Any = None,
        influence: Any = None,
        max_periods: int = 50,
        periodic_tol: float = 1e-6,
        rtol: float = 1e-10,
        substeps: int | None = None,
        interpolation: str = "linear",
        outputs: Any = None,
        tol: float | None = None,
    ) -> SimulationResult:
        """Response to a force input and/or base motion sampled at ``t``.

        Parameters
        ----------
        t : array_like (nt,)
            Strictly increasing sample times [s]; inputs are linear between samples.
        force : array_like (nt,) for one DOF, or (nt, n), optional
            External forces [N].
        base : array_like (nt,), optional
            Base (ground) displacement [m]; its velocity from the samples unless
            ``base_velocity`` is given.
        x0, v0 : array_like (n,), optional
            Initial displacement and velocity (default 0). Joints are stress-free at d = 0 and
            are loaded along their virgin curve to the initial position.
        periodic : bool
            Repeat the input (one period = the whole record) until the response repeats
            (relative change of ``x`` over a period below ``periodic_tol``, at most
            ``max_periods`` periods) and return the last period.
        influence : array_like (n,), optional
            Influence vector ``r`` of the base motion (default ones).
        substeps : int, optional
            Fixed stepping: this many equal Newmark steps per sample interval (split further
            at reversals and stick-slip transitions; second order), instead of the default
            error-controlled stepping. The response is returned at ``t`` only.
        interpolation : {"linear", "fourier"}
            How inputs are continued between samples when ``substeps > 1``: linear, or
            band-limited (FFT zero padding, for a uniformly sampled periodic input such as a
            multisine record of whole periods). Error-controlled stepping takes the inputs
            linear between samples.
        outputs : iterable of str, optional
            The arrays to compute, among ``x``, ``v``, ``a``, ``joint_force``,
            ``joint_energy``, ``joint_work``, ``input_work``, ``damping_work`` (default all).
            The others come back empty (no rows) and cost nothing. A periodic run also
            computes ``x``, ``v``, ``joint_energy`` and ``input_work`` (its convergence check).
        tol : float, optional
            Error-controlled stepping (the default, ``tol`` = :data:`DEFAULT_TOL`). Bouc-Wen,
            Masing, Jenkins, Iwan, Kelvin-Voigt and normal-contact joints: each piece of a
            sample interval is one Newmark step corrected twice by the two-point Hermite rule
            (fourth order; the jerk from the equation of motion), and pieces are shortened
            until the change of the second correction is at most ``tol`` relative to the
            largest displacement and velocity so far (pieces also end where a Masing branch
            closes). Joints of any
            :mod:`contactlab.joints` law and stiff structures: each piece is a Newmark step
            checked against two half steps, the pair's Richardson extrapolation is kept
            (fourth order) and the pair's difference / 3 is held to ``tol``. Pieces end on
            the samples, at velocity reversals and at stick-slip transitions. Not together
            with ``substeps``.

        Returns
        -------
        SimulationResult
        """
        t = as_1d(t, "t")
        if t.size < 2:
            raise InputError("t needs at least two samples")
        if np.any(np.diff(t) <= 0):
            i = int(np.argmax(np.diff(t) <= 0)) + 1
            raise InputError(f"t must be strictly increasing (t[{i}] = {t[i]} <= t[{i - 1}])")
        n = self.n
        x0a = np.zeros(n) if x0 is None else as_1d(np.atleast_1d(x0), "x0")
        v0a = np.zeros(n) if v0 is None else as_1d(np.atleast_1d(v0), "v0")
        for name, a in (("x0", x0a), ("v0", v0a)):
            if a.size != n:
                raise InputError(f"{name} has {a.size} entries, expected {n}")
        want = _core_outputs(outputs)
        step = _stepping(substeps, tol)
        if interpolation not in ("linear", "fourier"):
            raise InputError(f"interpolation must be 'linear' or 'fourier', got {interpolation!r}")
        if interpolation == "fourier" and step.substeps > 1:
            # band-limited inputs between samples: prepared here, stepped on the fine grid
            substeps = step.substeps
            tf, force, base, base_velocity = _refine(
                t, substeps, interpolation, force, base, base_velocity
            )
            r = self.simulate(
                tf,
                force,
                base,
                x0a,
                v0a,
                periodic=periodic,
                base_velocity=base_velocity,
                influence=influence,
                max_periods=max_periods,
                periodic_tol=periodic_tol,
                rtol=rtol,
                outputs=outputs,
                substeps=1,
            )
            return _slice(r, slice(None, None, substeps), t[: (r.t.size - 1) // substeps + 1])
        kw = self._inputs(t, force, base, base_velocity, influence)
        kw.update(tol=step.tol, substeps=step.substeps)
        if not periodic:
            return self._run(t, kw, x0a, v0a, rtol, want)
        if want is not None:
            want = sorted(set(want) | {"x", "v", "joint_dissipated", "input_work"})
        return self._periodic(t, kw, x0a, v0a, rtol, int(max_periods), float(periodic_tol), want)

    def _run(
        self,
        t: np.ndarray,
        kw: dict[str, Any],
        x0: np.ndarray,
        v0: np.ndarray,
        rtol: float,
        outputs: list[str] | None = None,
    ) -> SimulationResult:
        n, nj = self.n, len(self.joints)
        out = _core.structure_simulate(
            n,
            self.M.reshape(-1),
            self.C.reshape(-1),
            self.K.reshape(-1),
            [j.core_spec() for j in self.joints],
            t,
            x0,
            v0,
            rtol=rtol,
            outputs=outputs,
            **kw,
        )
        m = int(out.n_out)

        def arr(key: str, width: int) -> np.ndarray:
            # an output not asked for is empty: no rows
            rows = len(t) if outputs is None or key in outputs else 0
            a = np.asarray(getattr(out, key)).reshape(rows, width)[:m]
            return a[:, 0] if width == 1 and key in ("x", "v", "a") else a

        status = int(out.status)
        return SimulationResult(
            t=t[:m],
            x=arr("x", n),
            v=arr("v", n),
            a=arr("a", n),
            joint_force=arr("joint_force", nj),
            joint_energy=arr("joint_dissipated", nj),
            joint_work=arr("joint_work", nj),
            input_work=np.asarray(out.input_work)[:m],
            damping_work=np.asarray(out.damping_work)[:m],
            success=status == 0,
            status=status,
            message=str(out.message),
            n_steps=int(out.n_steps),
            n_iter=int(out.n_iter),
        )

    def _periodic(
        self,
        t: np.ndarray,
        kw: dict[str, Any],
        x0: np.ndarray,
        v0: np.ndarray,
        rtol: float,
        max_periods: int,
        tol: float,
        outputs: list[str] | None = None,
    ) -> SimulationResult:
        # The period is the record length plus one sample interval (the last sample is not
        # the first one repeated), so the state carried into the next period is the one
        # after the last sample; the core cannot carry joint history across calls, so the
        # input is tiled over several periods at once and the run extended until two
        # consecutive periods agree.
        nt = t.size
        dt = float(t[-1] - t[0]) / (nt - 1)
        periods = 4
        last: SimulationResult | None = None
        while True:
            tt = t[0] + dt * np.arange(nt * periods)
            kk = {
                k: (np.tile(v, periods) if k in ("force", "base", "base_velocity") else v)
                for k, v in kw.items()
            }
            r = self._run(tt, kk, x0, v0, rtol, outputs)
            if not r.success or r.t.size < nt * periods:
                return r
            if not all(np.all(np.isfinite(a)) for a in (r.x, r.v, r.joint_energy, r.input_work)):
                # a diverging response (inf - inf in the period's energies was a NaN, found
                # by fuzz/simulate): a failure that says so
                r.success, r.status = False, -2
                r.message = "the response left the double-precision range (it diverges)"
                return r
            xa = r.x.reshape(nt * periods, -1)
            a, b = xa[-2 * nt : -nt], xa[-nt:]
            change = float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))
            last = _slice(r, slice(-nt, None), t)
            last.extra = {"periods": periods, "periodic_change": change}
            if change <= tol or periods >= max_periods:
                if change > tol:
                    last.success = False
                    last.status = -1
                    last.message = (
                        f"no periodic steady state after {periods} periods "
                        f"(relative change {change:.3g} > {tol:g})"
                    )
                return last
            periods = min(2 * periods, max_periods)

    # ----------------------------------------------------------------- persistence
    def to_dict(self) -> dict[str, Any]:
        return {
            "M": self.M.tolist(),
            "C": self.C.tolist(),
            "K": self.K.tolist(),
            "joints": [j.to_dict() for j in self.joints],
            "units": {"M": "kg", "C": "N s/m", "K": "N/m"},
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Structure:
        if not isinstance(d, dict):
            raise InputError(f"a structure description is a JSON object, not {type(d).__name__}")
        try:
            s = cls(d["M"], d["C"], d["K"])
        except KeyError as exc:
            raise InputError(f"structure description lacks {exc}") from None
        joints = d.get("joints", [])
        if not isinstance(joints, list):
            raise InputError(f"'joints' must be a list, not {type(joints).__name__}")
        for jd in joints:
            try:
                j = Joint.from_dict(jd)
            except (KeyError, TypeError, ValueError, AttributeError) as exc:
                # untrusted JSON (found by fuzz/simulate): a sentence, not a traceback
                raise InputError(
                    f"a joint description is malformed ({exc!r}): {jd!r:.80}"
                ) from None
            s.add_joint(j.kind, j.dof, j.dof2, **j.params, **j.arrays)
        return s

    def save(self, path: str | Path) -> None:
        """Write the structure to a JSON file (atomically)."""
        write_text(path, json.dumps(self.to_dict(), indent=2))

    @classmethod
    def load(cls, path: str | Path) -> Structure:
        d = load_json(path, "structure JSON (Structure.save, or `contactlab identify --json`)")
        return cls.from_dict(d.get("structure", d) if isinstance(d, dict) else d)


def load_json(path: str | Path, what: str) -> Any:
    """The JSON document in ``path``; a missing file, a folder, a binary file or text that is
    not JSON is an :class:`~contactlab.InputError` of one line naming the file and ``what``
    it should be (never the codec's or the OS's raw message)."""
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file (expected a {what})")
    if p.is_dir():
        raise InputError(f"{path}: is a folder, not a {what}")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{path}: a binary file, not a {what}") from None
    try:
        return json.loads(text)
    except ValueError as exc:
        raise InputError(
            f"{path}: not JSON (line {getattr(exc, 'lineno', '?')}): expected a {what}"
        ) from None


_OUTPUTS = {
    "x": "x",
    "v": "v",
    "a": "a",
    "joint_force": "joint_force",
    "joint_energy": "joint_dissipated",
    "joint_work": "joint_work",
    "input_work": "input_work",
    "damping_work": "damping_work",
}


def _core_outputs(outputs: Any) -> list[str] | None:
    """The core's names of the outputs asked for (``None``: all)."""
    if outputs is None:
        return None
    names = [outputs] if isinstance(outputs, str) else list(outputs)
    for name in names:
        if name not in _OUTPUTS:
            raise InputError(f"unknown output {name!r} (known: {', '.join(_OUTPUTS)})")
    return [_OUTPUTS[name] for name in names]


#: Default error tolerance of :meth:`Structure.simulate` (see its ``tol``).
DEFAULT_TOL = 1e-4


@dataclass(frozen=True)
class _Stepping:
    tol: float | None
    substeps: int


def _stepping(substeps: Any, tol: Any) -> _Stepping:
    """The stepping asked for: error-controlled (``tol``, the default) or fixed."""
    if substeps is not None and tol is not None:
        raise InputError("give either substeps (fixed steps) or tol (error control), not both")
    if substeps is not None:
        try:
            k = int(substeps)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"substeps must be an integer, got {substeps!r}") from None
        if isinstance(substeps, bool) or k != substeps:
            raise InputError(f"substeps must be an integer, got {substeps!r}")
        if k < 1:
            raise InputError(f"substeps must be >= 1, got {substeps}")
        return _Stepping(None, k)
    if tol is None:
        return _Stepping(DEFAULT_TOL, 1)
    try:
        value = float(tol)
    except (TypeError, ValueError):
        raise InputError(f"tol must be a number, got {tol!r}") from None
    if not (np.isfinite(value) and value > 0):
        raise InputError(f"tol must be finite and > 0, got {tol!r}")
    return _Stepping(value, 1)


def _slice(r: SimulationResult, s: slice, t: np.ndarray) -> SimulationResult:
    return SimulationResult(
        t=t.copy(),
        extra=dict(r.extra),
        x=r.x[s],
        v=r.v[s],
        a=r.a[s],
        joint_force=r.joint_force[s],
        joint_energy=r.joint_energy[s] - r.joint_energy[s][:1],
        joint_work=r.joint_work[s] - r.joint_work[s][:1],
        input_work=r.input_work[s] - r.input_work[s][:1],
        damping_work=r.damping_work[s] - r.damping_work[s][:1],
        success=r.success,
        status=r.status,
        message=r.message,
        n_steps=r.n_steps,
        n_iter=r.n_iter,
    )


def _refine(
    t: np.ndarray, k: int, how: str, force: Any, base: Any, base_velocity: Any
) -> tuple[np.ndarray, Any, Any, Any]:
    """``k`` sub-samples per interval: the fine time grid and the band-limited inputs on it
    (``how="fourier"``; linear inputs are sub-stepped by the core itself)."""
    nt = t.size
    frac = np.arange(k) / k
    tf = np.concatenate([(t[:-1, None] + np.diff(t)[:, None] * frac).reshape(-1), t[-1:]])
    if how != "fourier":
        raise InputError(f"only interpolation='fourier' is refined here, got {how!r}")
    dt = np.diff(t)
    if np.ptp(dt) > 1e-9 * dt.mean():
        raise InputError("interpolation='fourier' needs uniformly sampled t")

    def fine(a: Any, name: str) -> Any:
        if a is None:
            return None
        arr = np.asarray(a, dtype=float)
        if arr.shape[0] != nt:
            raise InputError(f"{name} has {arr.shape[0]} samples but t has {nt}")
        # Periodic band-limited interpolation of the whole record (nt samples = one period),
        # evaluated on the k-times finer grid; the last point wraps around.
        spec = np.fft.rfft(arr.reshape(nt, -1), axis=0)
        out = np.fft.irfft(spec, n=nt * k, axis=0) * k
        return out[: (nt - 1) * k + 1].reshape((tf.size, *arr.shape[1:]))

    return tf, fine(force, "force"), fine(base, "base"), fine(base_velocity, "base_velocity")
