"""Diagnosis on structures (issue 10): an identified structure is the base model; which effect
does it miss?

The base model is an :class:`~contactlab.structure.IdentifiedModel` (the result of
:func:`contactlab.structure.identify`, or its saved JSON). Its parameters (``m`` when it was
fitted, ``c``, ``k``, the joint's, the initial state) are refitted on the training part of the
record (the first ``1 − holdout``), and so is every candidate: the base model plus one effect.
Each fitted model is then simulated over the whole record from its fitted initial state, and
the error on the held-out end (data no fit saw) ranks them.

Candidates (joint to the ground, as :func:`~contactlab.structure.identify` builds them):

``joint_damping``
    A viscous dashpot ``c_j`` in the joint: a force ``c_j ẋ`` on the absolute velocity of the
    mass. Under base excitation this differs from the structure's ``C``, which acts on the
    velocity relative to the base. Under force excitation it is the same term as ``C`` (which
    the base refit already adjusts), so it is not a distinguishable candidate there and is
    reported as such.
``second_joint``
    A second friction joint in parallel with the first: a Jenkins element (stiffness ``k2``,
    slip force ``fs2``), fitted from several starts (slip force low and high against the first
    joint's). It must slip somewhere in the record, else it is only a spring (``k`` again).
``base_coupling``
    A force ``−e ÿ`` proportional to the base acceleration that the model lacks (a part of the
    mass driven by the base, an inertial coupling of the fixture); base excitation only,
    ``ÿ`` from a Savitzky-Golay cubic over 5 % of the excitation period.

A candidate is named only if (1) its held-out mean-square error is lower than the current
model's by at least ``min_gain σ²`` (σ: the output noise estimated from the data, by
:func:`~contactlab.diagnose._signal.noise_rms`) and by at least ``min_share`` of the gap
between the current model's held-out MSE and σ², (2) the improvement holds across the
held-out blocks (per-block log MSE ratios, mean / standard error above ``z``), (3) the
training BIC decreases, (4) its parameters are plausible (no negative damping, mass or
stiffness; ``|e|`` below the mass; a second joint that slips) and (5) determined by the record
(standard error below the value). What no candidate explains is
reported as unexplained, with where it lives (near reversals or mid-stroke, its frequency
against the excitation's, training against hold-out).
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import savgol_filter

from .._blas import with_single_blas_thread
from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, least_squares_fit
from ..structure import IdentifiedModel
from ..structure.identify import build_structure
from ..structure.model import SimulationResult, Structure
from ._signal import dominant_period_samples, noise_rms, smooth_window

__all__ = [
    "STRUCTURE_CANDIDATES",
    "StructureCandidate",
    "StructureDiagnosis",
    "diagnose_structure",
]

STRUCTURE_CANDIDATES = ("joint_damping", "second_joint", "base_coupling")

#: parameters each candidate adds, with their units
_EXTRA = {
    "joint_damping": (("cj", "N s/m"),),
    "second_joint": (("k2", "N/m"), ("fs2", "N")),
    "base_coupling": (("e", "kg"),),
}


@dataclass(frozen=True)
class StructureCandidate:
    """The verdict on one candidate at one step.

    ``heldout_rms``: RMS output error on the held-out samples [m]; ``gain``: held-out MSE
    reduction against the current model in units of σ²; ``t``: the consistency statistic over
    the held-out blocks; ``parameters``/``stderr``: the added parameters as fitted.
    """

    name: str
    accepted: bool
    reason: str
    heldout_rms: float = math.nan
    gain: float = math.nan
    t: float = math.nan
    parameters: dict[str, float] = field(default_factory=dict)
    stderr: dict[str, float | None] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "accepted": self.accepted,
            "reason": self.reason,
            "heldout_rms": _num(self.heldout_rms),
            "gain": _num(self.gain),
            "t": _num(self.t),
            "parameters": {k: _num(v) for k, v in self.parameters.items()},
            "stderr": {k: _num(v) for k, v in self.stderr.items()},
        }


@dataclass
class StructureDiagnosis:
    """What :func:`diagnose_structure` found; ``to_dict()`` is its JSON layout.

    Attributes
    ----------
    joint, excitation : str
        The base model's joint and excitation.
    effects : list of str
        Effects added, in order (empty: the base model suffices).
    parameters : dict
        The final model's parameters (base and added) fitted on the training part.
    steps : list of dict
        ``added`` (None for the base), ``heldout_rms``, ``train_rms`` [m] and the verdict on
        every candidate tried after that step.
    where : list of str
        Where the base model's (and the final model's) held-out residual lives.
    noise_rms : float
        Output noise estimated from the data [m].
    unexplained : bool
        The final held-out RMS is above 1.5 σ: a discrepancy no candidate explains.
    n_train, n_holdout : int
    """

    joint: str
    excitation: str
    effects: list[str]
    parameters: dict[str, float]
    stderr: dict[str, float | None]
    steps: list[dict[str, Any]]
    where: list[str]
    noise_rms: float
    unexplained: bool
    n_train: int
    n_holdout: int
    final_structure: Structure | None = field(default=None, repr=False)
    residual: np.ndarray | None = field(default=None, repr=False)
    #: the record and both models' simulations over it, for :meth:`write_html`
    record: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    base_prediction: np.ndarray | None = field(default=None, repr=False)
    base_joint_force: np.ndarray | None = field(default=None, repr=False)
    joint_force: np.ndarray | None = field(default=None, repr=False)

    @property
    def effect_names(self) -> list[str]:
        return list(self.effects)

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": "structure",
            "joint": self.joint,
            "excitation": self.excitation,
            "effects": list(self.effects),
            "parameters": {k: _num(v) for k, v in self.parameters.items()},
            "stderr": {k: _num(v) for k, v in self.stderr.items()},
            "steps": [
                {**s, "candidates": [c.to_dict() for c in s["candidates"]]} for s in self.steps
            ],
            "where": list(self.where),
            "noise_rms": _num(self.noise_rms),
            "unexplained": self.unexplained,
            "samples": {"train": self.n_train, "holdout": self.n_holdout},
            "units": {"heldout_rms": "m", "train_rms": "m", "noise_rms": "m"},
        }

    def to_json(self, indent: int = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def write_html(self, directory: Any) -> Path:
        """Write ``diagnose.html`` (measured vs simulated response of the base and the final
        model, the joint's loop, the residual before and after, the named effects with their
        parameters ± standard errors, the unexplained part and where it lives), its figures
        under ``figures/`` and ``diagnose.json`` into ``directory``, all or nothing; returns
        the HTML's path. Deprecated (issue 32: the diagnosis returns results, the report draws
        them): use :func:`contactlab.report.structure.write_diagnosis_html`."""
        from .._moved import moved

        fn = moved(
            "contactlab.diagnose.StructureDiagnosis",
            "write_html",
            "contactlab.report.structure",
            "write_diagnosis_html",
        )
        return fn(self, directory)

    def summary(self) -> str:
        out = [f"contactlab diagnose — structure ({self.joint} joint, {self.excitation} "
               "excitation)", ""]  # fmt: skip
        out += ["Where the model disagrees:"] + [f"  - {w}" for w in self.where] + [""]
        if not self.effects:
            out.append("No candidate improves the held-out error significantly.")
        for name in self.effects:
            ps = ", ".join(
                f"{k} = {self.parameters[k]:.4g} ± {_fmt(self.stderr.get(k))}"
                for k, _ in _EXTRA[name]
            )
            out.append(f"Added {name}: {ps}")
        out += ["", f"{'step':<22}{'held-out RMS [m]':>18}{'/ noise':>9}{'train RMS [m]':>15}"]
        for s in self.steps:
            name = "base model" if s["added"] is None else f"+ {s['added']}"
            ratio = s["heldout_rms"] / self.noise_rms
            out.append(f"{name:<22}{s['heldout_rms']:>18.4g}{ratio:>9.2f}"
                       f"{s['train_rms']:>15.4g}")  # fmt: skip
            for c in s["candidates"]:
                mark = "accepted" if c.accepted else "rejected"
                out.append(f"    {c.name:<18}{mark}: {c.reason}")
        out.append(f"noise RMS (estimated): {self.noise_rms:.4g} m")
        return "\n".join(out)


def _num(v: Any) -> float | None:
    return float(v) if v is not None and math.isfinite(float(v)) else None


def _fmt(v: float | None) -> str:
    return "nan" if v is None or not math.isfinite(v) else f"{v:.2g}"


# ------------------------------------------------------------------------------ the models
def _base_model(base: Any) -> IdentifiedModel:
    if isinstance(base, (str, Path)):
        base = IdentifiedModel.load(base)
    if not isinstance(base, IdentifiedModel):
        raise InputError(
            "the base structure must be an IdentifiedModel (contactlab.structure.identify) or "
            f"the path of its saved JSON, got {type(base).__name__}"
        )
    if base.structure.n != 1:
        raise InputError(
            f"the structure diagnosis takes a single-DOF base model; this one has "
            f"{base.structure.n} DOFs"
        )
    return base


def _structure(model: IdentifiedModel, effects: tuple[str, ...], v: dict[str, float]) -> Structure:
    s = build_structure(model.joint, v, model.excitation)
    if "joint_damping" in effects:
        s.add_joint("kelvin_voigt", 0, k=0.0, c=v["cj"])
    if "second_joint" in effects:
        s.add_joint("jenkins", 0, k=v["k2"], fs=v["fs2"])
    return s


@dataclass
class _Data:
    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    n_train: int
    substeps: int
    base_acc: np.ndarray | None
    blocks: list[slice]
    #: the record on the integration grid (``substeps`` per sample, inputs linear between
    #: samples as :meth:`Structure.simulate` makes them), built once for every simulation
    fine: dict[str, np.ndarray] = field(default_factory=dict)

    def build_fine(self, excitation: str) -> None:
        k = self.substeps
        frac = np.arange(k) / k
        t = self.t
        tf = np.concatenate([(t[:-1, None] + np.diff(t)[:, None] * frac).reshape(-1), t[-1:]])
        self.fine = {"t": tf, "u": np.interp(tf, t, self.u)}
        if excitation == "base":
            self.fine["ud"] = np.interp(tf, t, np.gradient(self.u, t, edge_order=2))
            if self.base_acc is not None:
                self.fine["acc"] = np.interp(tf, t, self.base_acc)


def _simulate(
    model: IdentifiedModel, effects: tuple[str, ...], v: dict[str, float], d: _Data, n: int
) -> SimulationResult:
    s = _structure(model, effects, v)
    m = (n - 1) * d.substeps + 1  # the first n samples on the integration grid
    f = d.fine
    kw: dict[str, Any] = {}
    if model.excitation == "force":
        kw["force"] = f["u"][:m]
    else:
        kw["base"] = f["u"][:m]
        kw["base_velocity"] = f["ud"][:m]
        if "base_coupling" in effects and "acc" in f:
            kw["force"] = -v["e"] * f["acc"][:m]
    # its own fine grid already resolves the joint: fixed steps (error control is the
    # default of Structure.simulate) keep the diagnosis's numbers and cost
    r = s.simulate(f["t"][:m], x0=[v["x0"]], v0=[v["v0"]], substeps=1, **kw)
    k = d.substeps
    return SimulationResult(
        t=d.t[: (r.t.size - 1) // k + 1], x=r.x[::k], v=r.v[::k], a=r.a[::k],
        joint_force=r.joint_force[::k], joint_energy=r.joint_energy[::k],
        joint_work=r.joint_work[::k], input_work=r.input_work[::k],
        damping_work=r.damping_work[::k], success=r.success, status=r.status,
        message=r.message,
    )  # fmt: skip


def _output(
    model: IdentifiedModel, effects: tuple[str, ...], v: dict[str, float], d: _Data, n: int
) -> np.ndarray:
    """The simulated displacement over the first ``n`` samples; a failed run is padded with a
    large error so that the fit turns away from it."""
    big = 10.0 * float(np.max(np.abs(d.y[:n]))) + 1.0
    try:
        r = _simulate(model, effects, v, d, n)
    except ContactLabError:
        return np.full(n, big)
    x = np.asarray(r.x, dtype=float)
    if x.size < n:
        x = np.concatenate([x, np.full(n - x.size, big)])
    return x


def _base_params(model: IdentifiedModel, values: dict[str, float]) -> list[Parameter]:
    out = []
    for name, p in model.fit.params.items():
        val = float(values.get(name, p.value))
        lo = (
            0.0 if name in ("m", "c", "k", "h0", "ac", "kj", "fs", "alpha", "cj", "a1") else -np.inf
        )
        hi = np.inf
        if name == "nu":
            lo, hi = 0.25, 4.0
        out.append(Parameter(name, val, vary=p.vary, min=lo, max=hi, unit=p.unit,
                             scale=abs(val) if val != 0 else None))  # fmt: skip
    return out


@dataclass
class _Fit:
    effects: tuple[str, ...]
    values: dict[str, float]
    stderr: dict[str, float | None]
    train_rss: float
    nfree: int
    pred: np.ndarray  # simulated displacement over the whole record

    def heldout_err(self, d: _Data) -> np.ndarray:
        return (self.pred - d.y)[d.n_train :]

    def heldout_rms(self, d: _Data) -> float:
        return float(np.sqrt(np.mean(self.heldout_err(d) ** 2)))

    def train_rms(self, d: _Data) -> float:
        return float(np.sqrt(self.train_rss / d.n_train))

    def bic(self, d: _Data) -> float:
        n = d.n_train
        return n * math.log(max(self.train_rss, 1e-300) / n) + self.nfree * math.log(n)


def _fit(
    model: IdentifiedModel,
    effects: tuple[str, ...],
    params: list[Parameter],
    d: _Data,
    max_nfev: int,
) -> tuple[_Fit, FitResult]:
    n = d.n_train

    def res(v: dict[str, float]) -> np.ndarray:
        return _output(model, effects, v, d, n) - d.y[:n]

    # a candidate driven far off (a huge slip force, a runaway coupling) may overflow inside
    # the solver's trial steps: such trials are rejected by the solver, not warned about
    with np.errstate(over="ignore", invalid="ignore"):
        fr = least_squares_fit(res, params, max_nfev=max_nfev, ftol=1e-8, xtol=1e-8, gtol=1e-10)
    v = fr.values
    if not all(math.isfinite(x) for x in v.values()):
        raise InputError("the fit ended at non-finite parameters")
    se = {k: p.stderr for k, p in fr.params.items()}
    pred = _output(model, effects, v, d, d.t.size)
    return _Fit(effects, v, se, float(fr.chisqr), int(fr.nvarys), pred), fr


def _extra_starts(name: str, model: IdentifiedModel, cur: _Fit, d: _Data) -> list[list[Parameter]]:
    """Starting values of a candidate's added parameters (several for the second joint)."""
    v = cur.values
    m = float(v["m"])
    k = max(float(v["k"]), 1e-300)
    yr = max(float(np.std(d.y[: d.n_train])), 1e-300)
    if name == "joint_damping":
        c0 = max(float(v["c"]), 2e-3 * math.sqrt(k * m))
        return [[Parameter("cj", 0.3 * c0, min=0.0, unit="N s/m", scale=c0)]]
    if name == "base_coupling":
        return [[Parameter("e", 0.0, unit="kg", scale=0.05 * m)]]
    # second joint: slip force on the scale of the first joint's force (or of k·|x|)
    r = _simulate(model, cur.effects, v, d, d.n_train)
    jf = np.asarray(r.joint_force)
    fscale = float(np.percentile(np.abs(jf[:, 0]), 95)) if jf.size else 0.0
    if not fscale > 0:
        fscale = 0.1 * k * yr
    starts = []
    for ff in (0.3, 1.5):
        fs2 = ff * fscale
        k2 = fs2 / (0.2 * yr)  # slips at a fifth of the typical amplitude
        starts.append([
            Parameter("k2", k2, min=0.0, unit="N/m", scale=k2),
            Parameter("fs2", fs2, min=0.0, unit="N", scale=fs2),
        ])  # fmt: skip
    return starts


def _implausible(name: str, f: _Fit, model: IdentifiedModel, d: _Data) -> str | None:
    v = f.values
    for key in ("m", "c", "k", "cj", "k2", "fs2"):
        if key in v and v[key] < 0:
            return f"{key} = {v[key]:.4g} is negative"
    if name == "base_coupling" and abs(v["e"]) > v["m"]:
        return f"|e| = {abs(v['e']):.4g} kg exceeds the mass {v['m']:.4g} kg"
    if name == "second_joint":
        if not (v["k2"] > 0 and v["fs2"] > 0):
            return "the second joint has no stiffness or no slip force"
        r = _simulate(model, f.effects, v, d, d.t.size)
        f2 = np.asarray(r.joint_force)[:, -1]
        slipping = float(np.mean(np.abs(f2) >= v["fs2"] * (1 - 1e-9)))
        if slipping < 0.01:
            return (
                f"the second joint slips in {100 * slipping:.1f} % of the samples: it acts as a "
                "spring, which k already is"
            )
    return None


def _determined(value: float, stderr: float | None) -> bool:
    """A fitted parameter the record pins down: a finite standard error below its size."""
    return stderr is not None and math.isfinite(stderr) and stderr < abs(value)


def _blocks(n_train: int, n: int, count: int) -> list[slice]:
    edges = np.linspace(n_train, n, count + 1).round().astype(int)
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(edges) if b > a]


def _judge(
    name: str,
    cur: _Fit,
    cand: _Fit,
    d: _Data,
    sigma: float,
    z: float,
    min_gain: float,
    min_share: float,
) -> tuple[bool, str, float, float]:
    e0, e1 = cur.pred - d.y, cand.pred - d.y
    mse0 = float(np.mean(e0[d.n_train :] ** 2))
    mse1 = float(np.mean(e1[d.n_train :] ** 2))
    gain = (mse0 - mse1) / sigma**2
    ratios = np.array([
        math.log(max(float(np.mean(e0[b] ** 2)), 1e-300) / max(float(np.mean(e1[b] ** 2)), 1e-300))
        for b in d.blocks
    ])  # fmt: skip
    sd = float(np.std(ratios, ddof=1)) if ratios.size > 1 else math.inf
    t = float(np.mean(ratios) / (sd / math.sqrt(ratios.size))) if sd > 0 else (
        math.inf if np.mean(ratios) > 0 else -math.inf)  # fmt: skip
    if gain < min_gain:
        return False, f"held-out gain {gain:.3g} σ² below {min_gain:g} σ²", gain, t
    excess = mse0 / sigma**2 - 1.0
    if excess > 0 and gain < min_share * excess:
        return (
            False,
            (
                f"held-out gain {gain:.3g} σ² is {100 * gain / excess:.1f} % of the gap "
                f"to the noise ({excess:.3g} σ²), below {100 * min_share:g} %"
            ),
            gain,
            t,
        )
    if not t > z:
        return (
            False,
            f"held-out gain {gain:.3g} σ² not consistent across blocks (t = {t:.2f} <= {z:g})",
            gain,
            t,
        )
    if not cand.bic(d) < cur.bic(d):
        return False, f"held-out gain {gain:.3g} σ² but the training BIC does not decrease", gain, t
    return True, f"held-out gain {gain:.3g} σ², t = {t:.1f}", gain, t


# ------------------------------------------------------------------------------ location
def _where(label: str, e: np.ndarray, d: _Data, sigma: float, pred: np.ndarray) -> list[str]:
    """Statements with numbers on where the residual ``e`` (whole record) lives."""
    out = []
    h = e[d.n_train :]
    tr = e[: d.n_train]
    rh, rt = float(np.sqrt(np.mean(h**2))), float(np.sqrt(np.mean(tr**2)))
    out.append(f"{label}: held-out RMS {rh:.3g} m = {rh / sigma:.2f} × the noise "
               f"(training {rt:.3g} m = {rt / sigma:.2f} ×)")  # fmt: skip
    if rh <= 1.5 * sigma:
        return out
    # near reversals (|ẋ| in its lowest fifth) vs mid-stroke
    dt = float(np.median(np.diff(d.t)))
    vel = np.gradient(pred, dt)
    vh = np.abs(vel[d.n_train :])
    low = vh <= np.percentile(vh, 20)
    share = float(np.sum(h[low] ** 2) / max(np.sum(h**2), 1e-300))
    out.append(f"{label}: {100 * share:.0f} % of the held-out residual power lies near the "
               "reversals (the fifth of the samples with the lowest velocity)"
               + (" — it lives at the reversals" if share > 0.4 else
                  (" — it lives mid-stroke" if share < 0.1 else "")))  # fmt: skip
    # frequency content against the excitation's
    per = dominant_period_samples(d.u)
    spec = np.abs(np.fft.rfft((h - h.mean()) * np.hanning(h.size))) ** 2
    spec[0] = 0.0
    k = int(np.argmax(spec))
    f_res = k / (h.size * dt)
    f_exc = 1.0 / (per * dt)
    out.append(f"{label}: the residual's strongest line is at {f_res:.3g} Hz "
               f"({f_res / f_exc:.2f} × the excitation's {f_exc:.3g} Hz)")  # fmt: skip
    return out


# ------------------------------------------------------------------------------ workflow
def _record(recording: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if isinstance(recording, dict):
        try:
            t, u, y = recording["t"], recording["u"], recording["y"]
        except KeyError as exc:
            raise InputError(f"the structure record lacks {exc} (needs t, u, y)") from None
    elif isinstance(recording, (tuple, list)) and len(recording) == 3:
        t, u, y = recording
    else:
        raise InputError("a structure record is (t, u, y) or a dict with t, u, y")
    from .._arrays import as_1d

    t, u, y = as_1d(t, "t"), as_1d(u, "u"), as_1d(y, "y")
    if not (t.size == u.size == y.size):
        raise InputError(f"t, u and y differ in length ({t.size}, {u.size}, {y.size})")
    return t, u, y


@with_single_blas_thread
def diagnose_structure(
    recording: Any,
    base: Any,
    *,
    candidates: Any = None,
    holdout: float = 0.25,
    max_effects: int = 2,
    z: float = 3.0,
    min_gain: float = 0.05,
    min_share: float = 0.1,
    blocks: int = 8,
    max_nfev: int = 60,
) -> StructureDiagnosis:
    """Which effect does an identified structure miss? (see the module docstring)

    Parameters
    ----------
    recording : (t, u, y) or dict with ``t``, ``u``, ``y``
        Input (force [N] or base displacement [m], as the model's ``excitation``) and the
        measured displacement of the mass [m], uniformly sampled.
    base : IdentifiedModel or path
        The base model, or its JSON (:meth:`IdentifiedModel.save`).
    candidates : sequence of str, optional
        Restrict to these of :data:`STRUCTURE_CANDIDATES`.
    holdout : float
        Fraction of the record, at its end, that no fit sees.
    max_effects : int
        Stop after this many additions.
    z, min_gain : float
        Consistency threshold over the held-out blocks and least held-out MSE reduction
        (units of the noise variance).
    min_share : float
        Least share of the gap (held-out MSE above the noise variance) a candidate must
        close: far from the noise, a candidate that trims a sliver of a large misfit is not
        the missing effect.
    blocks : int
        Held-out blocks for the consistency statistic.

    Returns
    -------
    StructureDiagnosis
    """
    model = _base_model(base)
    t, u, y = _record(recording)
    names, dt = _checked_settings(t, u, y, candidates, holdout, max_effects, blocks, z, min_gain)
    n = t.size
    n_train = round(n * (1.0 - holdout))
    base_acc = None
    if model.excitation == "base":
        w = smooth_window(dominant_period_samples(u), 0.05)
        w = min(w, n - (1 - n % 2))
        base_acc = savgol_filter(u, w, 3, deriv=2, delta=dt, mode="interp")
    d = _Data(t, u, y, n_train, max(1, int(model.substeps)), base_acc,
              _blocks(n_train, n, int(blocks)))  # fmt: skip
    d.build_fine(model.excitation)

    start = dict(model.fit.values)
    cur, _ = _fit(model, (), _base_params(model, start), d, max_nfev)
    base_fit = cur
    sigma = noise_rms(cur.pred - y)
    if not sigma > 0:
        raise InputError("the response has no noise at all; cannot judge significance")
    where = _where("base model", cur.pred - y, d, sigma, cur.pred)
    steps: list[dict[str, Any]] = [
        {"added": None, "heldout_rms": cur.heldout_rms(d), "train_rms": cur.train_rms(d),
         "candidates": []}
    ]  # fmt: skip
    added: list[str] = []
    while len(added) < max_effects:
        verdicts: list[StructureCandidate] = []
        best: tuple[float, str, _Fit] | None = None
        for name in names:
            if name in added:
                continue
            tried = _try_candidate(name, model, cur, d, sigma, (z, min_gain, min_share),
                                   max_nfev, verdicts)  # fmt: skip
            if tried is not None and (best is None or tried[0] > best[0]):
                best = (tried[0], name, tried[1])
        steps[-1]["candidates"] = sorted(
            verdicts, key=lambda c: c.heldout_rms if math.isfinite(c.heldout_rms) else math.inf
        )
        if best is None:
            break
        _, name, cur = best
        added.append(name)
        steps.append({"added": name, "heldout_rms": cur.heldout_rms(d),
                      "train_rms": cur.train_rms(d), "candidates": []})  # fmt: skip
    final_rms = cur.heldout_rms(d)
    unexplained = final_rms > 1.5 * sigma
    if added:
        where += _where("final model", cur.pred - y, d, sigma, cur.pred)
    if unexplained:
        where.append(
            f"after {'the additions' if added else 'the base refit'} the held-out RMS is still "
            f"{final_rms / sigma:.1f} × the noise level: unexplained by the candidates "
            f"({', '.join(names)})"
        )
    sims = [_joint_force(model, f, d, n) for f in (base_fit, cur)]
    return StructureDiagnosis(
        record={"t": t, "u": u, "y": y}, base_prediction=base_fit.pred,
        base_joint_force=sims[0], joint_force=sims[1], joint=model.joint,
        excitation=model.excitation, effects=added, parameters=dict(cur.values),
        stderr=dict(cur.stderr), steps=steps, where=where, noise_rms=sigma,
        unexplained=unexplained, n_train=n_train, n_holdout=n - n_train,
        final_structure=_structure(model, cur.effects, cur.values), residual=cur.pred - y,
    )  # fmt: skip


def _checked_settings(
    t: np.ndarray, u: np.ndarray, y: np.ndarray, candidates: Any, holdout: float,
    max_effects: int, blocks: int, z: float, min_gain: float,
) -> tuple[list[str], float]:  # fmt: skip
    """The candidates' names and the sampling step, once the settings and the record's
    channels and time axis are checked."""
    if not 0.05 <= holdout <= 0.5:
        raise InputError(f"holdout must be in [0.05, 0.5], got {holdout}")
    if max_effects < 0 or blocks < 3:
        raise InputError(f"max_effects must be >= 0 and blocks >= 3 (got {max_effects}, {blocks})")
    if not (z > 0 and min_gain >= 0):
        raise InputError(f"z must be > 0 and min_gain >= 0, got z={z}, min_gain={min_gain}")
    names = list(STRUCTURE_CANDIDATES) if candidates is None else list(candidates)
    for nm in names:
        if nm not in STRUCTURE_CANDIDATES:
            raise InputError(f"unknown structure candidate {nm!r}; choose from "
                             f"{', '.join(STRUCTURE_CANDIDATES)}")  # fmt: skip
    n = t.size
    for name, a in (("u", u), ("y", y)):
        if not np.ptp(a) > 0:
            raise InputError(f"the {name} channel is constant: nothing to diagnose")
    dt_all = np.diff(t)
    if n < 64:
        raise InputError(f"the record has {n} samples; at least 64 are needed")
    if np.any(dt_all <= 0):
        raise InputError("t must be strictly increasing")
    dt = float(np.median(dt_all))
    if np.any(np.abs(dt_all - dt) > 1e-3 * dt):
        raise InputError("t must be uniformly sampled for the structure diagnosis")
    return names, dt


def _try_candidate(
    name: str, model: Any, cur: Any, d: Any, sigma: float,
    thresholds: tuple[float, float, float], max_nfev: int, verdicts: list[StructureCandidate],
) -> tuple[float, Any] | None:  # fmt: skip
    """Fit candidate ``name`` on top of the current model ``cur``; its verdict is appended to
    ``verdicts``; ``(gain, fit)`` when it is accepted."""
    z, min_gain, min_share = thresholds
    if model.excitation == "force" and name in ("joint_damping", "base_coupling"):
        why = ("a dashpot on the mass's velocity is the structure's C under force "
               "excitation (refitted with the base): not distinguishable"
               if name == "joint_damping" else "needs base excitation")  # fmt: skip
        verdicts.append(StructureCandidate(name, False, why))
        return None
    effects = (*cur.effects, name)
    fits = []
    for extra in _extra_starts(name, model, cur, d):
        ps = _base_params(model, cur.values)
        for e in cur.effects:  # parameters of effects added before
            for key, unit in _EXTRA[e]:
                val = cur.values[key]
                ps.append(Parameter(key, val, min=0.0 if key != "e" else -np.inf,
                                    unit=unit, scale=abs(val) or None))  # fmt: skip
        try:
            fits.append(_fit(model, effects, ps + extra, d, max_nfev)[0])
        except ContactLabError as exc:
            verdicts.append(StructureCandidate(name, False, f"fit failed: {exc}"))
    if not fits:
        return None
    cand = min(fits, key=lambda f: f.train_rss)
    ok, reason, gain, tstat = _judge(name, cur, cand, d, sigma, z, min_gain, min_share)
    why = _implausible(name, cand, model, d)
    if ok and why:
        ok, reason = False, f"implausible: {why}"
    keys = [k for k, _ in _EXTRA[name]]
    loose = [k for k in keys if not _determined(cand.values[k], cand.stderr.get(k))]
    if ok and loose:
        ok, reason = (
            False,
            "not determined by the record: "
            + ", ".join(f"{k} = {cand.values[k]:.4g} ± {_fmt(cand.stderr.get(k))}" for k in loose),
        )
    verdicts.append(StructureCandidate(
        name, ok, reason, cand.heldout_rms(d), gain, tstat,
        {k: cand.values[k] for k in keys}, {k: cand.stderr.get(k) for k in keys},
    ))  # fmt: skip
    return (gain, cand) if ok else None


def _joint_force(model: Any, f: Any, d: Any, n: int) -> np.ndarray | None:
    """The joint force of fit ``f`` over the whole record (None when it does not simulate)."""
    try:
        return np.asarray(_simulate(model, f.effects, f.values, d, n).joint_force)
    except ContactLabError:
        return None
