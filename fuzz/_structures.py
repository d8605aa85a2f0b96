"""Random-but-plausible and adversarial structure records for the ``identify`` and
``simulate`` targets, decoded from fuzz bytes: a single-DOF structure with one joint (any of
contactlab.structure's laws, parameters over decades), driven by a force or a base motion
(sine, sweep, random, step, constant, extreme), its response simulated by contactlab itself,
then damaged now and then (noise, offsets, a constant or 1e±300 channel, the input as the
response, repeated times), written as the CSV the CLI reads (units in the column names)."""

from __future__ import annotations

import io
import math

import numpy as np
from _harness import Bytes

JOINTS = ("masing", "jenkins", "iwan", "bouc_wen", "kelvin_voigt", "normal", "linear")


def _pos(b: Bytes, typical: float, decades: float) -> float:
    v = b.positive(typical, decades)
    return v if math.isfinite(v) and v > 0 else typical


def joint_params(b: Bytes, joint: str, k: float, reach: float) -> dict[str, object]:
    """Parameters of ``joint`` scaled to a structure of stiffness ``k`` moving by ``reach``."""
    if joint == "masing":
        return {"h0": _pos(b, k * reach, 2.0), "ac": _pos(b, 2.0, 1.5) / reach}
    if joint == "jenkins":
        return {"k": _pos(b, k, 2.0), "fs": _pos(b, 0.5 * k * reach, 2.0)}
    if joint == "iwan":
        from contactlab.structure import iwan_uniform

        return dict(iwan_uniform(_pos(b, k, 2.0), _pos(b, 0.5 * k * reach, 2.0), b.int(1, 8)))
    if joint == "bouc_wen":
        return {
            "alpha": _pos(b, k, 2.0),
            "beta": 1.0,
            "gamma": b.float(-1.0, 1.0) / reach,
            "delta": b.float(0.0, 2.0) / reach,
            "nu": b.choice((1.0, 2.0, _pos(b, 1.0, 0.5))),
        }
    if joint == "kelvin_voigt":
        return {"k": _pos(b, k, 2.0), "c": _pos(b, 1.0, 3.0)}
    if joint == "normal":
        return {"coeffs": [_pos(b, k, 2.0), b.float(-1, 1) * k / reach]}
    return {}


def structure(b: Bytes, joint: str):
    """(Structure, mass, stiffness, reach): SDOF with ``joint`` (or none for ``linear``)."""
    from contactlab.structure import Structure

    m, k = _pos(b, 1.0, 3.0), _pos(b, 1e4, 4.0)
    c = _pos(b, 0.02, 1.5) * 2.0 * math.sqrt(m * k)
    reach = _pos(b, 1e-4, 3.0)
    s = Structure(m, c, k)
    if joint != "linear":
        from contactlab.errors import ContactLabError

        try:
            s.add_joint(joint, 0, **joint_params(b, joint, k, reach))
        except ContactLabError:  # parameters the law refuses (e.g. ac = 2/reach overflowing)
            pass  # a linear structure then: the record is still plausible
    return s, m, k, reach


def excitation(b: Bytes, t: np.ndarray, scale: float) -> np.ndarray:
    n = t.size
    f = _pos(b, 5.0, 1.0)
    kind = b.int(0, 5)
    if kind == 0:
        u = np.sin(2 * np.pi * f * t)
    elif kind == 1:  # sweep
        u = np.sin(2 * np.pi * f * t * (1.0 + t / max(t[-1] if n else 1.0, 1e-12)))
    elif kind == 2:
        u = np.random.default_rng(b.int(0, 2**16)).standard_normal(n)
    elif kind == 3:
        u = (t > t[n // 3]).astype(float) if n else t.copy()
    elif kind == 4:
        u = np.full(n, b.float(-1, 1))
    else:
        u = np.array([b.float(-1, 1) for _ in range(n)])
    return scale * u


def record(b: Bytes, joint: str, exc: str) -> tuple[str, dict[str, float]]:
    """(CSV text, the true parameters) of one record."""
    from contactlab.errors import ContactLabError

    n = b.choice((0, 1, 2, 19, 20, 21, 64, b.int(20, 300)))
    fs = b.choice((200.0, 1000.0, _pos(b, 500.0, 2.0)))
    t = np.arange(n) / fs
    s, m, k, reach = structure(b, joint)
    u = excitation(b, t, k * reach if exc == "force" else reach)
    with np.errstate(all="ignore"):
        try:
            kw = {"force": u} if exc == "force" else {"base": u}
            y = np.zeros(n)
            if n >= 2:  # a run that stops early gives the samples reached: hold the last
                r = s.simulate(t, **kw)
                x = np.asarray(r.x).reshape(r.t.size, -1)[:, 0]
                y[: x.size] = x
                y[x.size :] = x[-1] if x.size else 0.0
        except ContactLabError:  # a structure or input the simulator refuses: a plain response
            y = u / k if exc == "force" else u.copy()
        mode = b.int(0, 15)
        ry = float(np.ptp(y)) if n else 0.0
        y = y + b.float(0.0, 0.05) * ry * np.random.default_rng(b.int(0, 255)).standard_normal(n)
        if mode == 1:
            y = np.full(n, b.float(-1, 1))  # a constant response
        elif mode == 2:
            y = y * b.choice((1e300, 1e-300, 1e150))
        elif mode == 3:
            u = u * b.choice((1e300, 1e-300, 1e150))
        elif mode == 4:
            y = u.copy()  # the input taken for the response
        elif mode == 5 and n:
            y[b.int(0, n - 1)] = b.choice(Bytes.SPECIAL)
        elif mode == 6 and n > 3:
            t[2] = t[1]  # a repeated time stamp
        elif mode == 7:
            y = y + b.float(-1, 1) * 10 * ry  # an offset
    yu = b.choice(("m", "mm", "um"))
    yf = {"m": 1.0, "mm": 1e3, "um": 1e6}[yu]
    uname = "u_force [N]" if exc == "force" else "y_base [m]"
    buf = io.StringIO()
    buf.write(f"t [s],{uname},y_disp [{yu}]\n")
    with np.errstate(all="ignore"):
        for row in zip(t, u, y * yf, strict=True):
            buf.write(",".join(repr(float(v)) for v in row) + "\n")
    return buf.getvalue(), {"m": m, "k": k}
