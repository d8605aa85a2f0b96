"""A normal-contact measurement chain written for the diagnosis's power study (issue 29).

Not the package's generator: the joint of docs/effects.md §2 driven by an actuator that
starts from rest, seen through a displacement sensor (LVDT: first-order low-pass), a
pressure cell (second order), a Bessel anti-alias filter on both channels, mains hum,
sampling jitter, independent white noise of 0.5-2 % of each channel's range and a 14/16-bit
ADC. Single tone (``pa/p0`` 0.2-0.8). Also the noncentrality that an effect makes on the
clean chain: its signal with the base model's directions and the nearest other candidate's
projected out, over the noise (``noncentrality``).

    from chain_normal import chain_record, noncentrality
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, signal

EFFECTS = ("stiffness_nonlinearity", "creep_drift", "asymmetric_branches", "channel_delay")
#: noncentrality at which a single-parameter effect is "visible" (z 5.05 two-sided + 95 %)
LAMBDA_VISIBLE = 44.8


def draw_factors(rng: np.random.Generator) -> dict:
    """Random chain settings of one record."""
    return {
        "fs": float(rng.choice([1000.0, 2000.0, 5000.0, 10000.0])),
        "f": float(np.exp(rng.uniform(np.log(0.5), np.log(20.0)))),
        "cycles": int(rng.integers(5, 51)),
        "ratio": float(rng.uniform(0.2, 0.8)),
        "noise_p": float(rng.uniform(0.005, 0.02)),
        "noise_d": float(rng.uniform(0.005, 0.02)),
        "bits": int(rng.choice([14, 16])),
        "psi": float(rng.uniform(0.05, 0.3)),
    }


def _joint(t, pdyn, k, psi, omega, eff):
    """δ of the joint (docs/effects.md §2) under the dynamic pressure on grid t.

    ``eff``: ``a2``, ``a3`` (the stiffness law k + a2 δ + a3 δ²), ``a`` (loss asymmetry),
    ``follow`` (the damping follows the stiffness, ψ k_s / (2π ω): the paper's eq. 17,
    instead of the constant c of docs/effects.md), ``bp`` (a stiffness that depends on the
    pressure instead, k_s = k (1 + bp p/pa): the paper's eq. 16, ``pa`` the amplitude)."""
    c = psi * k / (2 * math.pi * omega)
    a2 = eff.get("a2", 0.0)
    a3 = eff.get("a3", 0.0)
    asym = eff.get("a", 0.0)
    follow = bool(eff.get("follow", False))
    bp = eff.get("bp", 0.0)
    pa = float(np.max(np.abs(pdyn))) or 1.0
    pf = lambda tt: np.interp(tt, t, pdyn)  # noqa: E731

    def rhs(tt, y):
        d = y[0]
        p = pf(tt)
        ks = k + a2 * d + a3 * d * d + k * bp * p / pa
        r = p - ks * d
        ce = c * ks / k if follow else c
        return [r / (ce * (1 + asym * math.copysign(1.0, r)))]

    if a2 == 0.0 and a3 == 0.0 and asym == 0.0 and bp == 0.0:  # exact for piecewise-linear p
        h = float(t[1] - t[0])
        tau = c / k
        E = math.exp(-h / tau)
        g = tau * (1 - E) / h
        b = np.array([(1 - g) / k, (g - E) / k])
        a = np.array([1.0, -E])
        zi = signal.lfiltic(b, a, y=[pdyn[0] / k], x=[pdyn[0]])
        out, _ = signal.lfilter(b, a, pdyn, zi=zi)
        return out
    sol = integrate.solve_ivp(rhs, (t[0], t[-1]), [pdyn[0] / k], method="LSODA", t_eval=t,
                              rtol=1e-9, atol=1e-12 * abs(np.max(pdyn)) / k,
                              max_step=4 * float(t[1] - t[0]))  # fmt: skip
    return sol.y[0]


def chain_record(effect: str | None, size: float, fac: dict, seed: int, k: float = 1.3e12):
    """One record ``(t, p, delta, clean)`` with ``effect`` of ``size`` (its docs parameter:
    ``a2`` relative, i.e. a2 = size·k/D; creep D relative to D_amp; ``a``; tau in s).

    ``clean``: the noise-free measured channels and settings (for the noncentrality)."""
    rng = np.random.default_rng(seed)
    fs, f = fac["fs"], fac["f"]
    p0 = 5e5
    pa = fac["ratio"] * p0
    psi = fac["psi"]
    over = 4
    fsi = fs * over
    # (at most 150 000 samples: the chain's joint is integrated in Python)
    T = min(fac["cycles"], max(5, int(150_000 * f / fs))) / f
    ti = np.arange(int(T * fsi) + 1) / fsi
    # actuator from rest: a second-order servo (fn 12 f, ζ 0.7) following a sine command
    # (``ramp``: the command's amplitude rises over that many cycles, a raised cosine;
    # ``tones``: blocks of the frequencies f·r, as many cycles each, phase continuous)
    fn, z = 12.0 * f, 0.7
    wn = 2 * math.pi * fn
    act = signal.lti([wn * wn], [1, 2 * z * wn, wn * wn])
    tones = fac.get("tones") or (1.0,)
    rate = np.full(ti.size, f)
    edge = T / len(tones)
    for j, r in enumerate(tones):
        rate[ti >= j * edge] = f * r
    phase = 2 * math.pi * np.concatenate([[0.0], np.cumsum(rate[:-1]) / fsi])
    ramp = float(fac.get("ramp", 0.0))
    env = 0.5 - 0.5 * np.cos(math.pi * np.clip(ti * f / ramp, 0, 1)) if ramp > 0 else 1.0
    _, pdyn, _ = signal.lsim(act, pa * env * np.sin(phase), ti)
    omega = 2 * math.pi * f
    damp = pa / k
    eff = {}
    if effect == "stiffness_nonlinearity":
        # law "a2" (default): κ1-type, a2 = size·k/D; "a3": both sides harden alike,
        # a3 = size·k/D²; "a23": both, each of the size
        # "eq17": "a2" with the damping following the stiffness; "p": k_s depends on the
        # pressure, k (1 + size p/pa)
        law = fac.get("law", "a2")
        eff = {"a2": size * k / damp} if law in ("a2", "a23", "eq17") else {}
        if law in ("a3", "a23"):
            eff["a3"] = size * k / damp**2
        if law == "eq17":
            eff["follow"] = True
        if law == "p":
            eff["bp"] = size
    elif effect == "asymmetric_branches":
        eff = {"a": size}
    delta = _joint(ti, pdyn, k, psi, omega, eff)
    if effect == "creep_drift":
        tc = fac.get("tau_c", 0.25 * T)
        delta = delta + size * damp * -np.expm1(-ti / tc)
    if effect == "channel_delay":
        delta = np.interp(ti - size, ti, delta, left=delta[0])
    # sensors: LVDT first-order (corner 40 f, at most fs/4), pressure cell (fn 60 f, ζ 0.05)
    lv = min(40 * f, fs / 4)
    b, a = signal.butter(1, lv / (fsi / 2))
    dm = signal.lfilter(b, a, delta, zi=signal.lfilter_zi(b, a) * delta[0])[0]
    wc = 2 * math.pi * min(60 * f, fs)
    cell = signal.cont2discrete(([wc * wc], [1, 2 * 0.05 * wc, wc * wc]), 1 / fsi, "bilinear")
    pm = p0 + signal.lfilter(cell[0].ravel(), cell[1], pdyn)
    # Bessel 4th-order anti-alias at 0.35 fs on both channels
    bb, ab = signal.bessel(4, 0.35 * fs / (fsi / 2), norm="delay")
    # ``noise_stage`` "analog": the sensors' white noise enters before the anti-alias filter
    # (at the oversampled rate, scaled so that its SD after the filter is the stated
    # fraction of the range): the recorded noise is then band-limited, not white
    analog = fac.get("noise_stage") == "analog"
    if analog:
        imp = signal.lfilter(bb, ab, np.r_[1.0, np.zeros(4095)])
        gain = float(np.sqrt(np.sum(imp**2)))
        ep = signal.lfilter(bb, ab, rng.normal(0, 1.0 / gain, ti.size))
        ed = signal.lfilter(bb, ab, rng.normal(0, 1.0 / gain, ti.size))
    pm = signal.lfilter(bb, ab, pm, zi=signal.lfilter_zi(bb, ab) * pm[0])[0]
    dm = signal.lfilter(bb, ab, dm, zi=signal.lfilter_zi(bb, ab) * dm[0])[0]
    # sampling with jitter (0.5 % of a sample), hum at 50 Hz (0.1 % of range)
    n = int(T * fs)
    ts = np.arange(n) / fs
    tj = ts + rng.normal(0, 0.005 / fs, n)
    pc = np.interp(tj, ti, pm)
    dc = np.interp(tj, ti, dm)
    rp, rd = np.ptp(pc), np.ptp(dc)
    hum = np.sin(2 * math.pi * 50.0 * ts + rng.uniform(0, 2 * math.pi))
    clean = {"p": pc.copy(), "delta": dc.copy(), "fac": fac, "k": k, "psi": psi, "p0": p0,
             "pa": pa, "D": damp}  # fmt: skip
    # a slow drift of the displacement sensor (fraction of its range over the record,
    # straight or bowed), when the factors ask for one
    sd = fac.get("sensor_drift", 0.0)
    if sd:
        u = ts / ts[-1]
        dc = dc + sd * rd * (u + fac.get("sensor_bow", 0.0) * (u * u - u))
    if analog:
        pn = pc + 0.001 * rp * hum + fac["noise_p"] * rp * np.interp(tj, ti, ep)
        dn = dc + 0.001 * rd * hum + fac["noise_d"] * rd * np.interp(tj, ti, ed)
    else:
        pn = pc + 0.001 * rp * hum + rng.normal(0, fac["noise_p"] * rp, n)
        dn = dc + 0.001 * rd * hum + rng.normal(0, fac["noise_d"] * rd, n)
    q = 2.0 ** fac["bits"]
    lp, ld = 1.25 * rp / q, 1.25 * rd / q
    pn = np.round(pn / lp) * lp
    dn = np.round((dn - np.mean(dn)) / ld) * ld + np.mean(dn)
    clean["sigma_p"] = fac["noise_p"] * rp
    clean["sigma_d"] = fac["noise_d"] * rd
    return ts, pn, dn, clean


# ------------------------------------------------------------------------------------------
# noncentrality
# ------------------------------------------------------------------------------------------


def _kv(t, pd, k, psi, omega):
    from contactlab.diagnose.candidates_normal import kelvin_voigt_exact

    return kelvin_voigt_exact(t, pd, k, psi, omega)


def directions(t, p, k, psi, p0, omega, D):
    """Base model columns (k, ψ, p0) and the candidates' unit directions at the null, on the
    clean measured pressure: {name: column or matrix of columns}."""
    from contactlab.diagnose.candidates_normal import kelvin_voigt_asymmetric, nonlinear_viscous

    pd = p - p0
    y0 = _kv(t, pd, k, psi, omega)
    base = np.column_stack([
        (_kv(t, pd, k * 1.001, psi, omega) - y0) / 0.001,
        (_kv(t, pd, k, psi * 1.01, omega) - y0) / 0.01,
        (_kv(t, pd - 0.001 * np.std(pd), k, psi, omega) - y0) / 0.001,
    ])  # fmt: skip
    e = 1e-3
    cand = {}
    cand["stiffness_nonlinearity"] = np.column_stack([
        (nonlinear_viscous(t, pd, (k, e * k / D, 0.0), psi, omega) - y0) / e,
        (nonlinear_viscous(t, pd, (k, 0.0, e * k / D**2), psi, omega) - y0) / e,
    ])  # fmt: skip
    cand["asymmetric_branches"] = (
        kelvin_voigt_asymmetric(t, pd, k, psi, omega, 0.01, passes=20) - y0
    ) / 0.01
    T = t[-1] - t[0]
    per = 2 * math.pi / omega
    cand["creep_drift"] = np.column_stack(
        [-np.expm1(-(t - t[0]) / tc) * D for tc in np.geomspace(per, 3 * T, 6)]
    )
    cand["channel_delay"] = -np.gradient(y0, t)
    return y0, base, cand


def _resid(s, X):
    if X.ndim == 1:
        X = X[:, None]
    beta, *_ = np.linalg.lstsq(X, s, rcond=None)
    return s - X @ beta


def noncentrality(effect, size, fac, seed, k=1.3e12):
    """λ of ``effect`` at ``size``: ‖P s‖²/σ², s the clean measured δ with minus without the
    effect, P projecting out the base columns and the nearest other candidate (min over
    the others); σ² the output noise plus the input noise through the compliance 1/k. Also
    λ with only the base projected out."""
    t, _, _, c1 = chain_record(effect, size, fac, seed, k)
    _, _, _, c0 = chain_record(None, 0.0, fac, seed, k)
    s = c1["delta"] - c0["delta"]
    omega = 2 * math.pi * fac["f"]
    _, base, cand = directions(t, c0["p"], k, c0["psi"], c0["p0"], omega, c0["D"])
    # the input noise reaches δ through the Kelvin-Voigt low-pass (corner f·2π/ψ): its
    # white share is the corner's noise bandwidth over the Nyquist band
    share = min(1.0, math.pi * fac["f"] * 2 * math.pi / c0["psi"] / fac["fs"])
    var = c0["sigma_d"] ** 2 + share * (c0["sigma_p"] / k) ** 2
    lam_base = float(_resid(s, base) @ _resid(s, base)) / var
    lams = {}
    for other, X in cand.items():
        if other == effect:
            continue
        M = np.column_stack([base, X])
        r = _resid(s, M)
        lams[other] = float(r @ r) / var
    nearest = min(lams, key=lams.get)
    return lams[nearest], lam_base, nearest
