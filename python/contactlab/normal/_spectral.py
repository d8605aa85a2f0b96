"""The loop energy of a normal recording from its spectrum, and its standard error: the
harmonics that stand out of the noise, the band-limited energy, a jackknife over cycles and
the χ² bound on the noise's share (helpers of :func:`contactlab.normal.loop.analyze_loop`)."""

from __future__ import annotations

import numpy as np

#: a harmonic of the averaged cycle is signal when its power exceeds this many times the
#: variance the cycle-to-cycle scatter gives it (complex Gaussian noise exceeds it with
#: probability e^-3 = 5 %). A harmonic of the loop left out shifts the extremes by its
#: amplitude, one of noise kept only by the square of its slope: on 5-cycle windows with
#: 1 % noise the range of δ came out 0.09 % short at 6, within 0.03 % at 3, 0.9 % long at 1
_SIGNIFICANT = 3.0
#: the harmonics kept end after this many insignificant ones in a row (odd-only spectra of
#: symmetric loops skip one)
_GAP = 3


def _noise_power(X: np.ndarray) -> np.ndarray:
    """Variance of each harmonic of the averaged cycle (row mean of the spectra ``X``, one
    row a cycle, column k the k-th harmonic), from the cycle-to-cycle scatter pooled over
    neighbouring harmonics (``|j - k| <= max(2, k/4)``: noise spectra are smooth, and a few
    cycles hold few degrees of freedom per harmonic). One cycle: the median power of the
    upper half of the spectrum, taken as white."""
    n, m = X.shape
    if n < 2:
        upper = np.abs(X[0, max(1, m // 2) :]) ** 2
        floor = float(np.median(upper)) / np.log(2) if upper.size else 0.0
        return np.full(m, floor)
    v = np.sum(np.abs(X - X.mean(axis=0)) ** 2, axis=0) / (n * (n - 1))
    v[0] = 0.0
    c = np.concatenate(([0.0], np.cumsum(v[1:])))  # c[j] = v[1] + ... + v[j]
    k = np.arange(m)
    w = np.maximum(2, k // 4)
    lo = np.clip(k - w, 1, m - 1)
    hi = np.clip(k + w, 1, m - 1)
    return (c[hi] - c[lo - 1]) / (hi - lo + 1)


def _harmonics_kept(X: np.ndarray, bins: int) -> int:
    """Highest harmonic of the averaged cycle that a channel (spectra ``X`` of its cycles)
    holds above its noise: harmonics 1..K are kept, from the first on until ``_GAP`` in a
    row are noise. Each channel has its own: a noiseless one keeps all it holds."""
    kmax = (bins - 1) // 2  # no Nyquist term (no defined derivative)
    power = np.abs(X.mean(axis=0)) ** 2
    v = _noise_power(X)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(v > 0, power / np.where(v > 0, v, 1.0), np.where(power > 0, np.inf, 0))
    last, gap = 1, 0
    for k in range(1, kmax + 1):
        if ratio[k] > _SIGNIFICANT:
            last, gap = k, 0
        else:
            gap += 1
            if gap >= _GAP:
                break
    return last


def _band_limited(X: np.ndarray, K: int, bins: int) -> np.ndarray:
    """The averaged cycle from the mean spectrum ``X`` (rfft / bins) with harmonics 0..K."""
    Y = np.zeros(bins // 2 + 1, dtype=complex)
    Y[: K + 1] = X[: K + 1]
    return np.fft.irfft(Y * bins, n=bins)


def _energy_spectral(Pk: np.ndarray, Dk: np.ndarray, K: int) -> np.ndarray:
    """∮ p dδ from the spectra (rfft / bins, last axis) over the harmonics 1..K."""
    k = np.arange(1, K + 1)
    prod = np.conj(Pk[..., 1 : K + 1]) * Dk[..., 1 : K + 1]
    return -4 * np.pi * np.sum(k * prod.imag, axis=-1)


def _energy_jackknife_std(Ps: np.ndarray, Ds: np.ndarray, K: int) -> float:
    """Scatter of the cycles' contributions to E_d of the averaged cycle: √n times the
    jackknife standard error of E_d (the averaged cycles' loop energy is bilinear in p and
    δ, so the product of the two channels' noise falls as 1/n², not 1/n as in the energies
    of single cycles)."""
    n = Ps.shape[0]
    if n < 2:
        return 0.0
    Pm, Dm = Ps.mean(axis=0), Ds.mean(axis=0)
    P_out = (n * Pm - Ps) / (n - 1)  # the mean spectra without cycle i (row i)
    D_out = (n * Dm - Ds) / (n - 1)
    e = _energy_spectral(P_out, D_out, K)
    var = (n - 1) / n * float(np.sum((e - e.mean()) ** 2))
    return float(np.sqrt(n * var))


def _noise_cross(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Covariance ``E[(Ȳ_k - Y_k) conj(X̄_k - X_k)]`` of the averaged cycles' harmonics of two
    channels (spectra ``X``, ``Y``, one row a cycle), pooled over neighbouring harmonics as
    :func:`_noise_power` pools the variances."""
    n, m = X.shape
    c = np.sum((Y - Y.mean(axis=0)) * np.conj(X - X.mean(axis=0)), axis=0) / (n * (n - 1))
    c[0] = 0.0
    cs = np.concatenate(([0.0], np.cumsum(c[1:])))
    k = np.arange(m)
    w = np.maximum(2, k // 4)
    lo = np.clip(k - w, 1, m - 1)
    hi = np.clip(k + w, 1, m - 1)
    return (cs[hi] - cs[lo - 1]) / (hi - lo + 1)


#: the jackknife's variance of E_d replaces the noise spectra's when it exceeds it by more
#: than noise on n - 1 degrees of freedom does 1 % of the time (the loop itself changing
#: from cycle to cycle, which the pooled spectra of noise do not see); the normal quantile
_JACKKNIFE_Z = 2.326


def _chi2_over_dof(nu: int, z: float = _JACKKNIFE_Z) -> float:
    """Upper quantile of χ²_ν / ν (Wilson-Hilferty: within 1 % of the exact value for
    ν >= 1 at the 99 % point)."""
    a = 2.0 / (9.0 * nu)
    return float((1.0 - a + z * np.sqrt(a)) ** 3)


def _energy_std(Ps: np.ndarray, Ds: np.ndarray, K: int) -> float:
    """Scatter of the cycles' contributions to E_d of the averaged cycle (√n times E_d's
    standard error), from the noise of each harmonic of both channels.

    E_d = -4π Σ k Im(conj(P̄_k) D̄_k) over the harmonics kept. With noise a, b on P̄_k, D̄_k
    (variances v_p, v_d, covariance c = E[b conj(a)], circular), its variance is
    Σ (4πk)² (|P_k|² v_d + |D_k|² v_p − 2 Re(conj(P_k) D_k conj(c)) + v_p v_d) / 2, and
    |P̄_k|² over-reads |P_k|² by v_p. The noise variances are pooled over neighbouring
    harmonics (:func:`_noise_power`): on 3-5 cycles the jackknife over cycles had 2-4
    degrees of freedom, so its errors scattered by a factor of two and more (track windows
    of the audit's rig record: stated errors 0.5-3.4 % for a window scatter of 0.7 %). When
    the jackknife reads clearly more (the loop itself changing from cycle to cycle), it is
    taken."""
    n = Ps.shape[0]
    if n < 2:
        return 0.0
    vp, vd = _noise_power(Ps), _noise_power(Ds)
    c = _noise_cross(Ps, Ds)
    Pm, Dm = Ps.mean(axis=0), Ds.mean(axis=0)
    k = np.arange(1, K + 1)
    sl = slice(1, K + 1)
    per = (
        np.abs(Pm[sl]) ** 2 * vd[sl]
        + np.abs(Dm[sl]) ** 2 * vp[sl]
        - 2 * np.real(np.conj(Pm[sl]) * Dm[sl] * np.conj(c[sl]))
        - vp[sl] * vd[sl]
    )
    var = float(np.sum((4 * np.pi * k) ** 2 * np.maximum(per, 0.0) / 2))
    jack = _energy_jackknife_std(Ps, Ds, K) ** 2 / n
    if jack > var * _chi2_over_dof(n - 1):
        var = jack
    return float(np.sqrt(n * var))
