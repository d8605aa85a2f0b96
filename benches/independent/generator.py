"""An independent generator of contact recordings for evaluating ``contactlab diagnose``.

Eval-only code (not part of the package). Written from ``docs/effects.md`` and
``PHYSICS.md`` alone, without reading the package's own generators or its diagnosis, so that
the diagnosis cannot have been tuned to it. Its measurement chain differs from the package's
rig simulator where the physics allows:

* tangential: an electrodynamic shaker (moving armature mass on a suspension, coil force from
  a sine command switched on at t = 0 from rest) pushes the specimen; the contact force acts
  back on the armature, so x carries a start-up transient at the armature's natural frequency
  and small drive harmonics. The armature is integrated on a fine time grid (oversampling 8)
  with an exact exponential step of the linear part (zero-order hold of the contact force);
* the contact is a plain-Python Masing operator with the Madelung wiping-out rules
  (``PHYSICS.md`` §1), evaluated at every fine step;
* sensors: an LVDT with a second-order demodulator low-pass on x; a piezo load cell (charge
  amplifier high-pass, cell resonance) or a strain-gauge cell (resonance plus a conditioning
  low-pass) on F; the relative phase of the two chains at the drive frequency is compensated
  (the skew calibration of a real acquisition), so a clean record has no channel delay;
* identical Bessel anti-alias filters on both channels, mains hum at 50 Hz, white noise on
  both channels (independent streams) at 0.5-2 % of the channel's range, sampling with clock
  jitter (signals interpolated at the jittered instants), ADC quantisation (14-16 bits);
* normal: p = p0 + pa sin(wt) from t = 0, delta from the Kelvin-Voigt ODE (or the effect's
  ODE) solved with an adaptive stiff integrator (LSODA) and read on the fine grid, then the
  same sensor chain (strain-gauge pressure cell, capacitive displacement sensor).

The effects are those of ``docs/effects.md``, implemented from their definitions, with their
parameters in the document's units. Misfits that no candidate models: a tanh virgin curve, a
rational virgin curve ``h0 ac u / (1 + ac u)`` and a "gamma" virgin curve
``h0 (1 - (1 + ac u) exp(-ac u))`` (zero initial slope), each under Masing's rules. (A Jenkins
virgin curve was dropped: it is exactly a rigid-plastic Masing element, ac -> inf, in series
with a spring, i.e. nameable as ``series_compliance``.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import signal
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

TANGENTIAL_EFFECTS = (
    "viscous_damping",
    "inertia",
    "parallel_stiffness",
    "series_compliance",
    "force_offset",
    "force_drift",
    "displacement_offset",
    "channel_delay",
    "asymmetry",
    "non_masing_scaling",
    "parameter_drift",
    "stribeck",
    "position_friction",
    "stick_slip",
    "normal_load",
)
NORMAL_EFFECTS = ("stiffness_nonlinearity", "creep_drift", "channel_delay", "asymmetric_branches")
MISFITS = ("tanh_virgin", "rational_virgin", "gamma_virgin")
OVERSAMPLE = 8


# --------------------------------------------------------------------------- virgin curves
def virgin_function(kind: str, h0: float, ac: float):
    """Odd virgin curve f(u) of the named kind (scalar)."""
    if kind == "exponential":
        return lambda u: math.copysign(h0 * (1.0 - math.exp(-ac * abs(u))), u)
    if kind == "tanh_virgin":
        return lambda u: h0 * math.tanh(ac * u)
    if kind == "rational_virgin":
        return lambda u: h0 * ac * u / (1.0 + ac * abs(u))
    if kind == "gamma_virgin":
        # zero initial slope (a contact that stiffens as it closes), then saturation
        return lambda u: math.copysign(h0 * (1.0 - math.exp(-ac * abs(u)) * (1.0 + ac * abs(u))), u)
    raise ValueError(f"unknown virgin curve {kind!r}")


class Masing:
    """Masing operator with non-local memory, evaluated one sample at a time.

    ``lam`` is the branch scale (2 for Masing). For ``lam != 2`` every branch is anchored at
    the last actual turning point and there is no wiping-out (``docs/effects.md``,
    non_masing_scaling); the virgin curve is followed only from rest to the first turn.
    """

    def __init__(self, virgin, lam: float = 2.0):
        self.f = virgin
        self.lam = lam
        self.memory = lam == 2.0
        self.stack: list[tuple[float, float]] = []
        self.x = 0.0
        self.F = 0.0
        self.d = 0

    def _state_after(self, x: float):
        dx = x - self.x
        stack = self.stack
        d = self.d
        if dx != 0.0:
            nd = 1 if dx > 0 else -1
            if d != 0 and nd != d:
                stack = [*stack, (self.x, self.F)]
            d = nd
            if self.memory:
                stack = list(stack)
                while stack:
                    xo = stack[-2][0] if len(stack) >= 2 else -stack[-1][0]
                    if (x - xo) * d >= 0.0:
                        del stack[-2:]
                    else:
                        break
        if not stack:
            F = self.f(x)
        else:
            xr, fr = stack[-1]
            F = fr + self.lam * self.f((x - xr) / self.lam)
        return stack, d, F

    def peek(self, x: float) -> float:
        """Force at x without changing the state."""
        return self._state_after(x)[2]

    def __call__(self, x: float) -> float:
        stack, d, F = self._state_after(x)
        self.stack, self.d, self.x, self.F = stack, d, x, F
        return F


def masing_series(x: np.ndarray, virgin, lam: float = 2.0) -> np.ndarray:
    """The Masing force for a whole displacement history (starting from rest at x = 0)."""
    op = Masing(virgin, lam)
    return np.fromiter((op(float(v)) for v in x), float, count=len(x))


def series_compliance_force(x: np.ndarray, virgin, k_s: float) -> np.ndarray:
    """F with x = u + F/k_s and F = M[u]: solved for u at every sample (secant steps)."""
    op = Masing(virgin)
    out = np.empty(len(x))
    u_prev = 0.0
    x_prev = 0.0
    slope = virgin(1e-12) / 1e-12 if virgin(1e-12) != 0 else 1.0
    for i, xv in enumerate(x):
        xv = float(xv)
        u = u_prev + (xv - x_prev) / (1.0 + slope / k_s)
        d = 1.0 if xv >= x_prev else -1.0
        for _ in range(30):
            fu = op.peek(u)
            g = u + fu / k_s - xv
            h = d * (1e-7 * max(abs(u), abs(xv), 1e-12))
            dg = 1.0 + (op.peek(u + h) - fu) / h / k_s
            step = g / max(dg, 1e-12)
            u -= step
            if abs(step) <= 1e-13 * max(abs(xv), 1e-12):
                break
        F = op(u)
        du = u - u_prev
        if du != 0:
            slope = max((F - out[i - 1]) / du if i else slope, 0.0)
        out[i] = F
        u_prev, x_prev = u, xv
    return out


# --------------------------------------------------------------------------- effects
def last_turning_travel(x: np.ndarray) -> np.ndarray:
    """|x - x_r| since the last turning point of x (x_r = 0 before the first turn)."""
    s = np.empty(len(x))
    xr = 0.0
    d = 0
    for i in range(len(x)):
        if i:
            dx = x[i] - x[i - 1]
            if dx != 0:
                nd = 1 if dx > 0 else -1
                if d != 0 and nd != d:
                    xr = x[i - 1]
                d = nd
        s[i] = abs(x[i] - xr)
    return s


def tangential_output(
    effect: str | None,
    p: dict,
    t: np.ndarray,
    x: np.ndarray,
    v: np.ndarray,
    a: np.ndarray,
    h0: float,
    ac: float,
    virgin_kind: str = "exponential",
) -> tuple[np.ndarray, np.ndarray]:
    """The reported displacement and the force for an effect (``docs/effects.md`` §1).

    x, v, a: the contact side's true displacement (from rest at 0), velocity, acceleration.
    Returns (x as the displacement sensor reads it, force before the force sensor).
    """
    f = virgin_function(virgin_kind, h0, ac)
    x_rep = x
    if effect == "non_masing_scaling":
        return x_rep, masing_series(x, f, lam=p["lam"])
    if effect == "series_compliance":
        # the sensor reads slip plus elastic deformation: x_sensor = u + F/k_s with u the
        # armature-driven contact displacement's counterpart; the drive sets x_sensor
        return x_rep, series_compliance_force(x, f, p["k_s"])
    if effect == "displacement_offset":
        # contact at rest at the sensor's reading x0: the sensor reads x + x0
        return x + p["x0"], masing_series(x, f)
    M = masing_series(x, f)
    if effect is None:
        return x_rep, M
    if effect == "viscous_damping":
        return x_rep, M + p["c"] * v
    if effect == "inertia":
        return x_rep, M + p["m"] * a
    if effect == "parallel_stiffness":
        return x_rep, M + p["k_p"] * x
    if effect in ("force_offset", "force_drift"):
        return x_rep, M  # amplifier-side errors: added after the cell (chain)
    if effect == "channel_delay":
        return x_rep, M  # the delay is applied in the force channel (chain)
    if effect == "asymmetry":
        return x_rep, (1.0 + p["a"] * np.sign(M)) * M
    if effect == "parameter_drift":
        tm = 0.5 * (t[0] + t[-1])
        return x_rep, (1.0 + p["beta"] * (t - tm)) * M
    if effect == "stribeck":
        return x_rep, (1.0 + p["s"] * np.exp(-((v / p["v_s"]) ** 2))) * M
    if effect == "position_friction":
        g = 1.0 + p["a_k"] * np.cos(2 * np.pi * x / p["L"] + p["phi"])
        return x_rep, g * M
    if effect == "stick_slip":
        s = last_turning_travel(x)
        bump = p["b"] * h0 * np.sign(v) * (s / p["d_c"]) * np.exp(1.0 - s / p["d_c"])
        return x_rep, M + bump
    if effect == "normal_load":
        g = 1.0 + p["eps"] * np.cos(2 * np.pi * p["f_N"] * t + p["phi"])
        return x_rep, g * M
    raise ValueError(f"unknown tangential effect {effect!r}")


# --------------------------------------------------------------------------- chain pieces
def _lowpass2(f_c: float, zeta: float, fs: float):
    w = 2 * np.pi * f_c
    return signal.bilinear([w * w], [1.0, 2 * zeta * w, w * w], fs)


def _filt(ba, y: np.ndarray) -> np.ndarray:
    b, a = ba
    zi = signal.lfilter_zi(b, a) * y[0]
    return signal.lfilter(b, a, y, zi=zi)[0]


def _phase_delay(ba_list, f: float, fs: float) -> float:
    """Phase delay (s) at frequency f of a cascade of digital filters."""
    ph = 0.0
    for b, a in ba_list:
        _, h = signal.freqz(b, a, worN=[f], fs=fs)
        ph += float(np.angle(h[0]))
    return -ph / (2 * np.pi * f)


def _shift(t: np.ndarray, y: np.ndarray, tau: float) -> np.ndarray:
    """y(t - tau) by cubic interpolation; the first value before the start."""
    if tau == 0.0:
        return y
    cs = CubicSpline(t, y)
    ts = np.clip(t - tau, t[0], t[-1])
    return cs(ts)


@dataclass
class Chain:
    """The drawn measurement chain of one recording (all SI)."""

    fs: float
    f: float
    cycles: int
    noise_x: float  # fraction of the x channel's range
    noise_y: float  # fraction of the output channel's range
    bits_x: int
    bits_y: int
    jitter: float  # rms clock jitter, fraction of the sample interval
    hum_x: float  # 50 Hz hum amplitude, fraction of range
    hum_y: float
    aa_fc: float  # anti-alias corner (Hz), 4th-order Bessel on both channels
    lvdt_fc: float  # LVDT demodulator corner (Hz)
    cell: str  # "piezo" or "strain"
    cell_fn: float  # load-cell natural frequency (Hz)
    cell_zeta: float
    cell_hp_tau: float  # piezo charge-amplifier time constant (s); 0 for strain gauge
    cond_fc: float  # strain-gauge conditioning low-pass corner (Hz)
    pretrigger: float  # fraction of a period of rest before the drive starts
    shaker_ratio: float  # armature natural frequency / drive frequency
    shaker_zeta: float
    shaker_stiff: float  # suspension stiffness / contact's initial stiffness
    extras: dict = field(default_factory=dict)


def draw_chain(rng: np.random.Generator, fs=None, cycles=None, noise_x=None) -> Chain:
    """Draw a measurement chain: fs 1-10 kHz, 5-50 cycles, drive 1-50 Hz, noise 0.5-2 %."""
    fs = float(fs if fs is not None else rng.choice([1000.0, 2000.0, 5000.0, 10000.0]))
    cycles = int(cycles if cycles is not None else rng.choice([5, 8, 12, 20, 35, 50]))
    # drive frequency: 1-50 Hz with 40-2000 samples per cycle and at most 20 000 samples
    f_lo = max(1.0, fs * cycles / 20000.0, fs / 2000.0)
    f_hi = min(50.0, fs / 40.0)
    f = float(np.exp(rng.uniform(np.log(f_lo), np.log(f_hi))))
    nx = float(noise_x if noise_x is not None else rng.uniform(0.005, 0.02))
    piezo = bool(rng.random() < 0.5)
    return Chain(
        fs=fs,
        f=f,
        cycles=cycles,
        noise_x=nx,
        noise_y=float(rng.uniform(0.005, 0.02)),
        bits_x=int(rng.choice([14, 16])),
        bits_y=int(rng.choice([14, 16])),
        jitter=float(rng.uniform(0.0, 0.02)),
        hum_x=float(rng.uniform(0.0, 0.002)),
        hum_y=float(rng.uniform(0.0, 0.003)),
        aa_fc=float(rng.uniform(0.2, 0.4) * fs),
        lvdt_fc=float(min(max(rng.uniform(0.05, 0.2) * fs, 20.0 * f), 0.4 * fs)),
        cell="piezo" if piezo else "strain",
        cell_fn=float(rng.uniform(0.5, 2.0) * fs),
        cell_zeta=float(rng.uniform(0.02, 0.1)),
        cell_hp_tau=float(rng.uniform(200.0, 2000.0)) if piezo else 0.0,
        cond_fc=0.0 if piezo else float(min(max(rng.uniform(0.1, 0.3) * fs, 20.0 * f), 0.4 * fs)),
        pretrigger=float(rng.uniform(0.0, 0.1)),
        shaker_ratio=float(rng.uniform(6.0, 15.0)),
        shaker_zeta=float(rng.uniform(0.2, 0.5)),
        shaker_stiff=float(rng.uniform(20.0, 100.0)),
    )


def shaker_drive(ch: Chain, amplitude: float, k_contact: float, contact_force) -> tuple:
    """Integrate the armature on the fine grid; return t, x, v, a (fine grid, from rest).

    m x'' + c x' + k x = G V(t) - F_contact(x, x'), G V = k A sin(w t) switched on at t = 0.
    Exact step of the linear oscillator with the contact force held over the step.
    """
    fs_f = ch.fs * OVERSAMPLE
    dt = 1.0 / fs_f
    w = 2 * np.pi * ch.f
    t_pre = ch.pretrigger / ch.f
    n = math.ceil((ch.cycles / ch.f + t_pre) * fs_f) + 1
    t = np.arange(n) * dt
    k = ch.shaker_stiff * k_contact
    wn = ch.shaker_ratio * w
    m = k / wn**2
    c = 2 * ch.shaker_zeta * math.sqrt(k * m)
    # static gain correction so that the steady amplitude is close to A (armature dynamics)
    r = w / wn
    gain = math.sqrt((1 - r * r) ** 2 + (2 * ch.shaker_zeta * r) ** 2)
    drive = np.where(t >= t_pre, k * amplitude * gain * np.sin(w * (t - t_pre)), 0.0)
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    from scipy.linalg import expm

    E = expm(A * dt)
    # particular response to a unit constant force over one step: (E - I) A^-1 [0, 1/m]
    Bd = (E - np.eye(2)) @ np.linalg.solve(A, np.array([0.0, 1.0 / m]))
    x = np.zeros(n)
    v = np.zeros(n)
    a = np.zeros(n)
    state = np.zeros(2)
    for i in range(n):
        x[i], v[i] = state
        fc = contact_force(state[0], state[1])
        a[i] = (drive[i] - c * state[1] - k * state[0] - fc) / m
        if i + 1 < n:
            state = E @ state + Bd * (drive[i] - fc)
    return t, x, v, a, {"m_armature": m, "k_suspension": k, "t_pre": t_pre}


def _amplifier_terms(effect, params, t):
    if effect == "force_offset":
        return params["F0"] + 0.0 * t
    if effect == "force_drift":
        return params["Fdot"] * t
    return 0.0 * t


def _adc(y: np.ndarray, rng_range: float, bits: int) -> np.ndarray:
    q = rng_range / 2**bits
    return np.round(y / q) * q


# --------------------------------------------------------------------------- records
@dataclass
class Record:
    """One generated recording with its truth."""

    kind: str  # "tangential" or "normal"
    label: str  # effect name, "clean" or a misfit name
    truth: dict
    chain: Chain
    t: np.ndarray
    x: np.ndarray  # input channel (x or p)
    y: np.ndarray  # output channel (F or delta)
    ideal: dict  # noise-free sample-grid signals for the visibility criterion

    def write_csv(self, path) -> None:
        if self.kind == "tangential":
            header = "t [s],x [m],F [N]"
        else:
            header = "t [s],p [Pa],delta [m]"
        data = np.column_stack([self.t, self.x, self.y])
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.10g")


def _contact_feedback(h0: float, ac: float, virgin_kind: str):
    op = Masing(virgin_function(virgin_kind, h0, ac))

    def force(xv, vv):
        return op(float(xv))

    return force


def _sample(ch: Chain, t_f, ys, rng_jit):
    """Sample fine-grid signals at jittered instants of the ADC clock."""
    n = math.floor(t_f[-1] * ch.fs)
    tk = np.arange(n) / ch.fs
    tj = np.clip(tk + rng_jit.normal(0.0, ch.jitter / ch.fs, n), t_f[0], t_f[-1])
    return tk, [CubicSpline(t_f, y)(tj) for y in ys]


def _noise_and_adc(ch, clean_x, clean_y, tk, rng_nx, rng_ny, rng_hum):
    """Add hum, white noise (independent streams) and quantisation; return x, y, levels."""
    rx = float(np.ptp(clean_x))
    ry = float(np.ptp(clean_y))
    ph = rng_hum.uniform(0, 2 * np.pi, 2)
    hum_x = ch.hum_x * rx * np.sin(2 * np.pi * 50.0 * tk + ph[0])
    hum_y = ch.hum_y * ry * np.sin(2 * np.pi * 50.0 * tk + ph[1])
    nx = rng_nx.normal(0.0, ch.noise_x * rx, len(tk))
    ny = rng_ny.normal(0.0, ch.noise_y * ry, len(tk))
    span_x = 1.3 * max(abs(clean_x).max(), 1e-30) * 2
    span_y = 1.3 * max(abs(clean_y).max(), 1e-30) * 2
    x = _adc(clean_x + hum_x + nx, span_x, ch.bits_x)
    y = _adc(clean_y + hum_y + ny, span_y, ch.bits_y)
    return (
        x,
        y,
        {"range_x": rx, "range_y": ry, "sigma_x": ch.noise_x * rx, "sigma_y": ch.noise_y * ry},
    )


def tangential_record(
    rng_seed: int,
    label: str,
    params: dict | None = None,
    chain: Chain | None = None,
    acA: float | None = None,
    base: dict | None = None,
) -> Record:
    """A tangential recording: ``label`` is "clean", an effect name or a misfit name.

    ``params`` gives the effect's parameters (document units); ``base`` (h0, ac, A) and
    ``chain`` may be given to make a twin of another record (same noise streams).
    """
    ss = np.random.SeedSequence(rng_seed)
    r_draw, r_nx, r_ny, r_hum, r_jit = (np.random.default_rng(s) for s in ss.spawn(5))
    ch = chain if chain is not None else draw_chain(r_draw)
    if base is None:
        lo = 1.5 if label in MISFITS else 0.3  # a virgin curve's shape shows past the knee
        acA = float(acA if acA is not None else np.exp(r_draw.uniform(np.log(lo), np.log(5.0))))
        A = float(np.exp(r_draw.uniform(np.log(5e-6), np.log(200e-6))))
        h0 = float(np.exp(r_draw.uniform(np.log(1.0), np.log(500.0))))
        base = {"h0": h0, "ac": acA / A, "A": A}
    h0, ac, A = base["h0"], base["ac"], base["A"]
    params = dict(params or {})
    virgin_kind = label if label in MISFITS else "exponential"
    effect = label if label in TANGENTIAL_EFFECTS else None
    t_f, x_f, v_f, a_f, drive_info = shaker_drive(
        ch, A, h0 * ac, _contact_feedback(h0, ac, virgin_kind)
    )
    t_pre = drive_info["t_pre"]
    # the effect's time origin is the drive's start (from rest)
    x_rep_f, F_f = tangential_output(effect, params, t_f, x_f, v_f, a_f, h0, ac, virgin_kind)
    if effect == "channel_delay":
        F_f = _shift(t_f, F_f, params["tau"])
    # sensors
    fs_f = ch.fs * OVERSAMPLE
    x_chain = [_lowpass2(ch.lvdt_fc, 1 / math.sqrt(2), fs_f)]
    if ch.cell == "piezo":
        b, a = signal.bilinear([1.0, 0.0], [1.0, 1.0 / ch.cell_hp_tau], fs_f)
        F_chain = [(b, a), _lowpass2(ch.cell_fn, ch.cell_zeta, fs_f)]
    else:
        F_chain = [
            _lowpass2(ch.cell_fn, ch.cell_zeta, fs_f),
            _lowpass2(ch.cond_fc, 1 / math.sqrt(2), fs_f),
        ]
    aa = signal.bessel(4, ch.aa_fc, fs=fs_f, norm="delay")
    xs = _filt(aa, _filt(x_chain[0], x_rep_f))
    Fs = F_f
    for ba in F_chain:
        if ba is F_chain[0] and ch.cell == "piezo":
            # the charge amplifier was reset with the record's start value (no step)
            Fs = signal.lfilter(ba[0], ba[1], Fs - Fs[0]) + Fs[0]
        else:
            Fs = _filt(ba, Fs)
    if effect == "force_offset":
        Fs = Fs + params["F0"]
    elif effect == "force_drift":
        Fs = Fs + params["Fdot"] * t_f
    Fs = _filt(aa, Fs)
    # skew calibration: align the two chains' phase delays at the drive frequency
    skew = _phase_delay(F_chain, ch.f, fs_f) - _phase_delay(x_chain, ch.f, fs_f)
    Fs = _shift(t_f, Fs, -skew)
    tk, (xk, Fk) = _sample(ch, t_f, [xs, Fs], r_jit)
    x_meas, F_meas, levels = _noise_and_adc(ch, xk, Fk, tk, r_nx, r_ny, r_hum)
    # ideal sample-grid signals (no chain, no noise) for the visibility criterion
    idx = np.round(tk * fs_f).astype(int)
    t_id = t_f[idx]
    ideal = {
        "t": t_id,
        "x_true": x_f[idx],
        "v": v_f[idx],
        "a": a_f[idx],
        "x_rep": x_rep_f[idx],
        "F": F_f[idx] + _amplifier_terms(effect, params, t_f[idx]),
        "F_meas_clean": Fk,
        "x_meas_clean": xk,
    }
    amp = float(0.5 * np.ptp(x_f[idx][len(idx) // 2 :]))
    truth = {
        "effect": label,
        "params": params,
        "h0": h0,
        "ac": ac,
        "A_target": A,
        "A": amp,
        "acA": ac * amp,
        "fs": ch.fs,
        "f": ch.f,
        "cycles": ch.cycles,
        "noise_x": ch.noise_x,
        "noise_y": ch.noise_y,
        "skew_compensated": skew,
        "virgin": virgin_kind,
        **levels,
        **{k: v for k, v in drive_info.items() if k != "t_pre"},
        "t_pre": t_pre,
    }
    return Record("tangential", label, truth, ch, tk, x_meas, F_meas, ideal)


def normal_delta(effect, p, t, pa, p0, k, psi, w, t_pre):
    """delta(t) of the Kelvin-Voigt base or an effect (``docs/effects.md`` §2), from rest."""
    c = psi * k / (2 * np.pi * w)

    def pres_at(tt):
        return p0 + (pa * math.sin(w * (tt - t_pre)) if tt >= t_pre else 0.0)

    if effect == "stiffness_nonlinearity":

        def rhs(tt, d):
            return [
                (pres_at(tt) - p0 - (p["a1"] + p["a2"] * d[0] + p["a3"] * d[0] ** 2) * d[0]) / c
            ]

    elif effect == "asymmetric_branches":

        def rhs(tt, d):
            r = pres_at(tt) - p0 - k * d[0]
            return [r / (c * (1.0 + p["a"] * np.sign(r)))]

    else:

        def rhs(tt, d):
            return [(pres_at(tt) - p0 - k * d[0]) / c]

    period = 2 * np.pi / w
    sol = solve_ivp(
        rhs,
        (t[0], t[-1]),
        [0.0],
        method="LSODA",
        t_eval=t,
        rtol=1e-9,
        atol=1e-8 * (pa / k),
        max_step=period / 200,
    )
    d = sol.y[0]
    if effect == "creep_drift":
        d = d + p["D"] * (1.0 - np.exp(-t / p["tau_c"]))
    return d, c


def normal_record(
    rng_seed: int,
    label: str,
    params: dict | None = None,
    chain: Chain | None = None,
    base: dict | None = None,
) -> Record:
    """A normal-contact recording: p (Pa) in, delta (m) out; ``label`` "clean" or an effect."""
    ss = np.random.SeedSequence(rng_seed)
    r_draw, r_nx, r_ny, r_hum, r_jit = (np.random.default_rng(s) for s in ss.spawn(5))
    ch = chain if chain is not None else draw_chain(r_draw)
    if base is None:
        p0 = float(r_draw.uniform(0.2e6, 1.0e6))
        base = {
            "p0": p0,
            "pa": float(r_draw.uniform(0.2, 0.8) * p0),
            "k": float(np.exp(r_draw.uniform(np.log(0.5e12), np.log(2e12)))),
            "psi": float(r_draw.uniform(0.05, 0.3)),
        }
    p0, pa, k, psi = base["p0"], base["pa"], base["k"], base["psi"]
    params = dict(params or {})
    effect = label if label in NORMAL_EFFECTS else None
    fs_f = ch.fs * OVERSAMPLE
    w = 2 * np.pi * ch.f
    t_pre = ch.pretrigger / ch.f
    n = math.ceil((ch.cycles / ch.f + t_pre) * fs_f) + 1
    t_f = np.arange(n) / fs_f
    pres = p0 + np.where(t_f >= t_pre, pa * np.sin(w * (t_f - t_pre)), 0.0)
    d_f, c = normal_delta(effect, params, t_f, pa, p0, k, psi, w, t_pre)
    if effect == "channel_delay":
        d_f = _shift(t_f, d_f, params["tau"])
    p_chain = [
        _lowpass2(ch.cell_fn, ch.cell_zeta, fs_f),
        _lowpass2(ch.lvdt_fc, 1 / math.sqrt(2), fs_f),
    ]
    d_chain = [_lowpass2(ch.lvdt_fc * 0.7, 1 / math.sqrt(2), fs_f)]
    aa = signal.bessel(4, ch.aa_fc, fs=fs_f, norm="delay")
    ps = pres
    for ba in p_chain:
        ps = _filt(ba, ps)
    ds = _filt(d_chain[0], d_f)
    ps, ds = _filt(aa, ps), _filt(aa, ds)
    skew = _phase_delay(d_chain, ch.f, fs_f) - _phase_delay(p_chain, ch.f, fs_f)
    ds = _shift(t_f, ds, -skew)
    tk, (pk, dk) = _sample(ch, t_f, [ps, ds], r_jit)
    # the pressure channel's range is its dynamic part; p0 rides on it
    p_meas, d_meas, levels = _noise_and_adc(ch, pk - p0, dk, tk, r_nx, r_ny, r_hum)
    p_meas = p_meas + p0
    idx = np.round(tk * fs_f).astype(int)
    ideal = {
        "t": t_f[idx],
        "p": pres[idx],
        "delta": d_f[idx],
        "p_meas_clean": pk,
        "d_meas_clean": dk,
    }
    truth = {
        "effect": label,
        "params": params,
        **base,
        "c": c,
        "pa_p0": pa / p0,
        "fs": ch.fs,
        "f": ch.f,
        "cycles": ch.cycles,
        "noise_x": ch.noise_x,
        "noise_y": ch.noise_y,
        "skew_compensated": skew,
        **levels,
        "t_pre": t_pre,
    }
    return Record("normal", label, truth, ch, tk, p_meas, d_meas, ideal)
