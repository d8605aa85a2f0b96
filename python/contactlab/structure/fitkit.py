"""What the single- and multi-DOF identifications share: the joint built from fitted values,
derivatives of measured displacements, the initial-state switch and the multi-start loop."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ..fitting import FitResult, Parameter, least_squares_fit, stderr_ratio, with_covariance
from .joints import iwan_uniform
from .model import Structure

#: elements of the uniform Iwan joint that ``joint="iwan"`` fits (slip forces spread evenly)
IWAN_ELEMENTS = 20


def add_fitted_joint(
    s: Structure, joint: str, v: dict[str, float], dof: int, dof2: int | None
) -> None:
    """Add the joint of fitted values ``v`` (names as in :mod:`.identify`) to ``s``."""
    if joint == "bouc_wen":
        s.add_joint(
            "bouc_wen",
            dof,
            dof2,
            alpha=v["alpha"],
            beta=1.0,
            gamma=v["gamma"],
            delta=v["delta"],
            nu=v["nu"],
        )
    elif joint == "masing":
        s.add_joint("masing", dof, dof2, h0=v["h0"], ac=v["ac"], scale=v.get("scale", 2.0))
    elif joint == "jenkins":
        s.add_joint("jenkins", dof, dof2, k=v["kj"], fs=v["fs"])
    elif joint == "iwan":
        s.add_joint("iwan", dof, dof2, **iwan_uniform(v["kj"], v["fs"], IWAN_ELEMENTS))
    elif joint == "kelvin_voigt":
        s.add_joint("kelvin_voigt", dof, dof2, k=v["kj"], c=v["cj"])
    elif joint == "normal":
        s.add_joint("normal", dof, dof2, coeffs=[v["a1"], v["a2"], v["a3"]])


def hold_state(
    ps: list[Parameter], estimate: bool, prefixes: tuple[str, ...] = ("x0", "v0")
) -> list[Parameter]:
    """Hold the initial-state parameters at their start unless they are estimated."""
    if not estimate:
        for p in ps:
            if p.name.startswith(prefixes):
                p.vary = False
    return ps


def derivatives(t: np.ndarray, y: np.ndarray, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration of a sampled displacement (FFT for whole periods, else a
    Savitzky-Golay cubic or second-order differences)."""
    if periodic:
        n = y.size
        dt = float(t[1] - t[0])
        w = 2j * np.pi * np.fft.rfftfreq(n, dt)
        Y = np.fft.rfft(y)
        return np.fft.irfft(w * Y, n), np.fft.irfft(w * w * Y, n)
    dt = np.diff(t)
    win = 15
    if y.size > 2 * win and np.ptp(dt) <= 1e-6 * dt.mean():
        # Savitzky-Golay (cubic, 15 samples): second differences of raw samples amplify the
        # measurement noise by 1/dt², which biases the regression towards zero stiffness.
        from .._filters import savgol_filter

        h = float(dt.mean())
        return (
            savgol_filter(y, win, 3, deriv=1, delta=h),
            savgol_filter(y, win, 3, deriv=2, delta=h),
        )
    v = np.gradient(y, t, edge_order=2)
    return v, np.gradient(v, t, edge_order=2)


def column_derivatives(
    t: np.ndarray, y: np.ndarray, periodic: bool
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`derivatives` of each column of ``y`` (samples × channels)."""
    vs, acc = zip(*(derivatives(t, y[:, i], periodic) for i in range(y.shape[1])), strict=True)
    return np.stack(vs, axis=1), np.stack(acc, axis=1)


def best_start(
    plan: list[tuple[dict[str, Any], list[Parameter]]],
    residual: Any,
    records: list[dict[str, Any]],
    max_nfev: int = 25,
) -> list[Parameter] | None:
    """Fit every start of ``plan`` (``(description, parameters)``) briefly and return the
    parameters of the best one (as a new start: values fitted, bounds kept), None when every
    start failed; each start's short RMS error (or error) is appended to ``records``."""
    best_cost = math.inf
    best: list[Parameter] | None = None
    for st, ps in plan:
        try:
            fr = least_squares_fit(residual, ps, max_nfev=max_nfev, ftol=1e-5, xtol=1e-5, gtol=1e-8)
        except ContactLabError as exc:
            records.append({"start": st, "cost": None, "error": str(exc)})
            continue
        cost = float(np.sqrt(fr.chisqr / max(fr.ndata, 1)))
        records.append({"start": st, "rms_short": cost})
        if cost < best_cost:
            best_cost = cost
            best = [
                Parameter(
                    p.name,
                    fr.params[p.name].value,
                    vary=p.vary,
                    min=p.min,
                    max=p.max,
                    unit=p.unit,
                    scale=p.scale,
                )
                for p in ps
            ]
    return best


def _band_mean(p: np.ndarray, width: int) -> np.ndarray:
    """Means of ``p`` (frequencies × ...) over consecutive bands of ``width`` bins."""
    nb = p.shape[0] // width
    return p[: nb * width].reshape(nb, width, *p.shape[1:]).mean(axis=1)


def _white_only(fit: FitResult) -> FitResult:
    if fit.covar is None:
        return fit
    note = (
        "the noise model could not be evaluated: the standard errors assume white "
        "residuals and are likely too small"
    )
    return replace(fit, notes=[*fit.notes, note])


def noise_model_covariance(
    fit: FitResult,
    respond: Callable[[np.ndarray], np.ndarray],
    u: np.ndarray,
    channels: int = 1,
    *,
    probes: int = 32,
    seed: int = 0,
) -> tuple[FitResult, dict[str, Any]]:
    """The output-error fit's covariance with noise on the input as well as the output.

    An output-error fit takes the measured input as exact. White noise ``e_u`` on it reaches
    the residuals through the fitted model, ``r = G e_u − e_y`` (``G = ∂ simulated output /
    ∂ input``), correlated in time over the structure's ring-down and across DOFs; with
    light damping that is as long as the record, beyond what a lag-window (Newey-West)
    estimate can follow. So the residual covariance is modelled as
    ``Ω = σ_u² G Gᵀ + diag(σ_a²)`` (white input noise, white output noise on each channel
    ``a``) and the covariance is the sandwich ``A⁻¹ Jᵀ Ω J A⁻¹`` (``A = JᵀJ``).

    ``Jᵀ G Gᵀ J`` is the mean of ``zᵢ zᵢᵀ`` over ``probes`` white unit inputs ``wᵢ``, with
    ``zᵢ = Jᵀ G wᵢ`` and ``G wᵢ`` from simulating the fitted model with the input
    ``u + ε wᵢ`` (``respond(ε wᵢ)``: the change of the flattened output; ``ε`` 1 % of the
    input's RMS, the size of the noise it stands for) — the nonlinear model's own
    sensitivity, stick and slip included. The noise levels are estimated from the data: the
    residual's Hann-windowed periodogram of each channel, averaged in bands of 8 bins, is
    fitted by ``σ_u² S_G,a(f) + σ_a²`` (non-negative least squares on relative errors,
    reweighted by the fitted level), with ``S_G,a``
    the probes' mean response spectrum. Returns the new fit and
    ``{"input_noise": σ_u, "output_noise": [σ_a ...], "probes": probes}``.
    """
    J, r = fit.jac, np.asarray(fit.residual, dtype=float)
    k = len(fit.var_names)
    info: dict[str, Any] = {"input_noise": None, "output_noise": None, "probes": 0}
    if J is None or fit.covar is None or k == 0 or r.size != J.shape[0]:
        return _white_only(fit), info
    n = r.size // channels
    if n * channels != r.size or n < 32 or not np.all(np.isfinite(J)):
        return _white_only(fit), info
    eps = 0.01 * max(float(np.sqrt(np.mean(u * u))), 1e-300)
    rng = np.random.default_rng(seed)
    gw = []
    for _ in range(probes):
        w = rng.standard_normal(n)
        d = np.asarray(respond(eps * w), dtype=float) / eps
        if d.shape != r.shape or not np.all(np.isfinite(d)):
            return _white_only(fit), info
        gw.append(d)
    try:
        with np.errstate(all="ignore"):  # extreme records (fuzzing): overflow → white errors
            covar, su2, sy2 = _noise_sandwich(J, r, gw, n, channels, probes, fit.ndata)
    except (ValueError, np.linalg.LinAlgError):  # non-finite spectra refused by nnls / svd
        return _white_only(fit), info
    if not (np.all(np.isfinite(covar)) and math.isfinite(su2) and np.all(np.isfinite(sy2))):
        return _white_only(fit), info
    ratio = stderr_ratio(fit, covar)
    info = {
        "input_noise": math.sqrt(su2),
        "output_noise": [math.sqrt(float(v)) for v in sy2],
        "probes": probes,
    }
    note = (
        f"standard errors allow for input noise (σ_u ≈ {info['input_noise']:.3g}) as well as "
        "output noise (σ_y ≈ " + ", ".join(f"{v:.3g}" for v in info["output_noise"]) + "), "
        "estimated from the residual spectrum"
        + (f"; {ratio.min():.3g} to {ratio.max():.3g} × the white-noise ones" if ratio.size else "")
    )
    return with_covariance(fit, covar, note=note), info


def _noise_sandwich(
    J: np.ndarray,
    r: np.ndarray,
    gw: list[np.ndarray],
    n: int,
    channels: int,
    probes: int,
    ndata: int,
) -> tuple[np.ndarray, float, np.ndarray]:
    """:func:`noise_model_covariance`'s arithmetic: the covariance and ``σ_u²``, ``σ_a²``."""
    from scipy.optimize import nnls

    k = J.shape[1]
    Gw = np.stack(gw)  # probes × (n · channels)
    Z = Gw @ J  # probes × k: zᵢ = Jᵀ G wᵢ
    Bu = Z.T @ Z / probes
    # noise levels from the residual's spectrum
    # Hann taper: the records are not periodic, and the leakage of a rectangular window
    # (power falling as 1/f² from the strong low-frequency response) would swamp the
    # response's own 1/f⁴ fall above the resonances
    width = 8
    win = np.hanning(n)[:, None]
    w2 = float(np.sum(win * win))  # a white sequence of variance σ²: power σ² per bin
    Pr = _band_mean(np.abs(np.fft.rfft(win * r.reshape(n, channels), axis=0)) ** 2 / w2, width)
    Pg = _band_mean(
        np.mean(np.abs(np.fft.rfft(win * Gw.reshape(probes, n, channels), axis=1)) ** 2, axis=0)
        / w2,
        width,
    )
    # non-negative least squares on relative errors, reweighted by the model's own level
    # (weights 1/observed would pull the fit below the periodogram's mean)
    nb = Pr.shape[0]
    X = np.zeros((channels, nb, 1 + channels))
    X[:, :, 0] = Pg.T
    for a in range(channels):
        X[a, :, 1 + a] = 1.0
    X = X.reshape(channels * nb, 1 + channels)
    obs = Pr.T.reshape(-1)
    level = np.maximum(obs, 1e-300)
    var = np.zeros(1 + channels)
    for _ in range(6):
        wgt = 1.0 / level
        A_ls = X * wgt[:, None]
        colscale = np.linalg.norm(A_ls, axis=0)
        colscale[~(colscale > 0)] = 1.0
        sol, _ = nnls(A_ls / colscale, obs * wgt)
        var = sol / colscale
        model = X @ var
        if not np.all(model > 0):
            break
        level = model
    su2, sy2 = float(var[0]), var[1:]
    Jc = J.reshape(n, channels, k)
    By = np.einsum("a,nai,naj->ij", sy2, Jc, Jc)
    B = su2 * Bu + By
    norms = np.linalg.norm(J, axis=0)
    norms[~(norms > 0)] = 1.0
    _U, s, Vt = np.linalg.svd(J / norms, full_matrices=False)
    keep = s > 1e-8 * s[0] if s[0] > 0 else np.zeros_like(s, bool)
    Ainv = (Vt[keep].T / s[keep] ** 2) @ Vt[keep] / np.outer(norms, norms)
    covar = Ainv @ B @ Ainv * ndata / max(ndata - k, 1)
    covar = 0.5 * (covar + covar.T)
    return covar, su2, sy2
