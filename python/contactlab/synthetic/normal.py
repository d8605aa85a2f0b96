"""Synthetic normal-contact recordings with realistic sensor noise (for tests, docs, demos).

The pressure is ``p(t) = p0 + pa sin(ω t)`` (Pa), the displacement δ(t) (m, zeroed at the
static state under p0) is either

- ``model="nonlinear"`` (default): Konowalski's eq. 17 with ``k_s(δ)`` from the centre curve
  of Table 2 and ψ computed from the Table 2 loop by eq. 7 (see :func:`table2_model` for
  other p0);
- ``model="linear"``: Kelvin-Voigt with the paper's linear-model inputs (k = 1.206 MPa/µm,
  ψ = 0.0887);
- ``model="table2"``: the quasi-static loop of Table 2 itself — δ on the loading curve while
  dp/dt > 0 and on the unloading curve otherwise (rate-independent; used for round-trip tests;
  samples are offset by half a sample so that none falls exactly on a turning point);
- any object with ``simulate(t, p, p0=..., dpdt=...)`` (e.g. :class:`KelvinVoigt`).

Dynamic models are run for ``lead_cycles`` extra cycles first, which are dropped, so that the
returned recording is in steady state as the paper's (recorded after 1500 cycles).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from .._arrays import positive
from ..errors import InputError
from ..normal import paper as _paper
from ..normal.models import KelvinVoigt, NonlinearContact


@functools.lru_cache(maxsize=1)
def table2_psi() -> float:
    """ψ by eq. 7 of the Table 2 loop (computed from the loop, not the paper's 0.0887)."""
    from ..normal.loop import analyze_loop

    t, p, d = synthetic_recording(model="table2", n_cycles=3, noise=None)
    return analyze_loop(t, p, d).psi


def table2_model(p0: float | None = _paper.TABLE2_P0) -> NonlinearContact:
    """Eq. 17 with k_s(δ) from the Table 2 centre curve and ψ from the Table 2 loop (eq. 7).

    Table 2 holds for p0 = 0.5 MPa. For another p0 the stiffness is scaled by
    ``sqrt(p0 / 0.5 MPa)`` — an illustrative trend (joints stiffen with mean pressure, as the
    paper's Fig. 8 shows), not a fit to the paper's data.
    """
    c = _paper.loop_poly_to_si(_paper.TABLE2_MPA_UM["centre"])
    scale = 1.0 if p0 is None else float(np.sqrt(positive(p0, "p0") / _paper.TABLE2_P0))
    return NonlinearContact(
        k_s_delta=scale * c[1:], psi=table2_psi(), omega=_paper.TABLE2_OMEGA, p0=p0
    )


def _monotone_bracket(c: np.ndarray, span: float = 5e-6) -> tuple[float, float]:
    """The interval around δ = 0 on which ``poly`` increases (between the nearest real roots
    of its derivative on either side, within ±span)."""
    r = np.polynomial.polynomial.polyroots(np.polynomial.polynomial.polyder(c))
    r = r[np.abs(r.imag) < 1e-12 * span].real
    lo = max([v for v in r if v < 0], default=-span)
    hi = min([v for v in r if v > 0], default=span)
    return float(lo), float(hi)


def _invert_branch(c: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Solve ``poly(δ) = target`` on the monotone stretch around δ = 0 (vectorised bisection
    polished by Newton)."""
    lo, hi = _monotone_bracket(c)
    if np.any(target < np.polynomial.polynomial.polyval(lo, c)) or np.any(
        target > np.polynomial.polynomial.polyval(hi, c)
    ):
        raise InputError("pa is outside the range the Table 2 curves cover monotonically")
    a = np.full(target.shape, lo)
    b = np.full(target.shape, hi)
    for _ in range(60):
        m = 0.5 * (a + b)
        f = np.polynomial.polynomial.polyval(m, c) - target
        a = np.where(f < 0, m, a)
        b = np.where(f < 0, b, m)
    x = 0.5 * (a + b)
    pv = np.polynomial.polynomial.polyval
    dc = np.polynomial.polynomial.polyder(c)
    for _ in range(3):
        x = x - (pv(x, c) - target) / pv(x, dc)
    return x


def _noise_levels(noise: Any, pa: float, dpp: float) -> tuple[float, float, int | None]:
    """(σ_p in Pa, σ_δ in m, ADC bits or None)."""
    if noise is None or (np.isscalar(noise) and not isinstance(noise, str) and noise == 0):
        return 0.0, 0.0, None
    if isinstance(noise, str):
        if noise != "realistic":
            raise InputError(f"noise must be 'realistic', a number, a dict or None, got {noise!r}")
        # Strain-gauge force channel ~0.2 % of the dynamic range, inductive displacement
        # sensor ~2 nm RMS, both through a 16-bit converter.
        return 0.002 * pa, 2e-9, 16
    if isinstance(noise, dict):
        unknown = set(noise) - {"p", "delta", "bits"}
        if unknown:
            raise InputError(f"unknown noise keys {sorted(unknown)}; use 'p', 'delta', 'bits'")
        sp = float(noise.get("p", 0.0))
        sd = float(noise.get("delta", 0.0))
        bits = noise.get("bits")
        if sp < 0 or sd < 0 or not (np.isfinite(sp) and np.isfinite(sd)):
            raise InputError("noise levels must be finite and >= 0")
        if bits is not None and (int(bits) != bits or not 4 <= int(bits) <= 32):
            raise InputError(f"noise bits must be an integer in 4..32, got {bits!r}")
        return sp, sd, None if bits is None else int(bits)
    rel = float(noise)
    if not np.isfinite(rel) or rel < 0:
        raise InputError(f"relative noise must be finite and >= 0, got {noise!r}")
    return rel * 2 * pa, rel * dpp, None


def _quantize(x: np.ndarray, lo: float, hi: float, bits: int) -> np.ndarray:
    lsb = (hi - lo) / (2**bits - 1)
    return lo + np.round((x - lo) / lsb) * lsb


def synthetic_recording(
    p0: float = _paper.TABLE2_P0,
    pa: float = _paper.TABLE2_PA,
    omega: float = _paper.TABLE2_OMEGA,
    n_cycles: int = 128,
    samples_per_cycle: int = 256,
    model: Any = "nonlinear",
    noise: Any = "realistic",
    seed: int | None = None,
    *,
    lead_cycles: int = 2,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A recording ``(t, p, delta)`` of a joint under ``p = p0 + pa sin ω t``.

    Parameters
    ----------
    p0, pa : float
        Static pressure and dynamic amplitude, Pa (defaults: the paper's 0.5 and 0.4 MPa);
        ``pa > p0`` (the joint would separate) is an error.
    omega : float
        Angular frequency, rad/s (default 1, as the paper).
    n_cycles, samples_per_cycle : int
        Length of the record (the paper: 128 cycles × 256 samples = 32768).
    model : str or model
        ``"nonlinear"``, ``"linear"``, ``"table2"`` or a model object (see module docstring).
    noise : "realistic", float, dict or None
        ``"realistic"``: Gaussian noise of 0.2 % of pa on p and 2 nm on δ, then 16-bit
        quantisation of each channel over its range; a float: relative Gaussian noise (of the
        peak-to-peak value of each channel); a dict ``{"p": σ_Pa, "delta": σ_m, "bits": n}``;
        None or 0: exact samples.
    seed : int, optional
        Seed of the noise generator (``numpy.random.default_rng``).
    lead_cycles : int
        Cycles simulated and dropped before the record starts (dynamic models only).

    Returns
    -------
    t, p, delta : ndarray
        Times (s), total pressure (Pa), displacement (m).

    Examples
    --------
    >>> from contactlab.synthetic.normal import synthetic_recording
    >>> t, p, d = synthetic_recording(n_cycles=8, seed=1)
    >>> t.size, round(float(p.mean()) / 1e6, 2)
    (2048, 0.5)
    """
    p0 = positive(p0, "p0")
    pa = positive(pa, "pa")
    omega = positive(omega, "omega")
    if pa > p0:
        raise InputError(f"pa = {pa:g} Pa exceeds p0 = {p0:g} Pa: the joint would separate")
    for name, v, lo in (("n_cycles", n_cycles, 1), ("samples_per_cycle", samples_per_cycle, 8)):
        if isinstance(v, bool) or int(v) != v or v < lo:
            raise InputError(f"{name} must be an integer >= {lo}, got {v!r}")
    if isinstance(lead_cycles, bool) or int(lead_cycles) != lead_cycles or lead_cycles < 0:
        raise InputError(f"lead_cycles must be an integer >= 0, got {lead_cycles!r}")
    n_cycles, spc, lead = int(n_cycles), int(samples_per_cycle), int(lead_cycles)
    n = n_cycles * spc
    dt = 2 * np.pi / omega / spc

    if isinstance(model, str) and model == "table2":
        t = (np.arange(n) + 0.5) * dt
        phase = omega * t
        pdyn = pa * np.sin(phase)
        c = _paper.table2_si()
        loading = np.cos(phase) > 0
        delta = np.where(
            loading, _invert_branch(c["load"], pdyn), _invert_branch(c["unload"], pdyn)
        )
        t = t - 0.5 * dt  # start the record at 0 s; the samples stay off the turning points
    else:
        if isinstance(model, str):
            if model == "nonlinear":
                mdl: Any = table2_model(p0)
            elif model == "linear":
                mdl = KelvinVoigt(_paper.PAPER_K_TAN, _paper.PAPER_PSI, omega, p0=p0)
            else:
                raise InputError(
                    "model must be 'nonlinear', 'linear', 'table2' or a model object, "
                    f"got {model!r}"
                )
        else:
            if not hasattr(model, "simulate"):
                raise InputError("model must have a simulate(t, p, ...) method")
            mdl = model
        m = (n_cycles + lead) * spc
        tt = np.arange(m) * dt
        p_tot = p0 + pa * np.sin(omega * tt)
        res = mdl.simulate(tt, p_tot, p0=p0, dpdt=pa * omega * np.cos(omega * tt))
        if not res.success:
            raise InputError(f"the model could not be simulated: {res.message}")
        t = tt[lead * spc :] - tt[lead * spc]
        pdyn = pa * np.sin(omega * tt[lead * spc :])
        delta = np.asarray(res.delta[lead * spc :])

    p = p0 + pdyn
    dpp = float(delta.max() - delta.min())
    sp, sd, bits = _noise_levels(noise, pa, dpp)
    if sp or sd or bits:
        rng = np.random.default_rng(seed)
        p = p + sp * rng.standard_normal(n)
        delta = delta + sd * rng.standard_normal(n)
        if bits:
            p = _quantize(p, 0.0, 2.0 * (p0 + pa), bits)
            delta = _quantize(delta, -5e-6, 5e-6, bits)
    return t, p, delta
