"""Pressure-dependent contact stiffness across tests (Konowalski 2009, eq. 16).

For each test (one mean pressure p0, amplitude pa), the displacement-dependent secant
stiffness of eq. 6, ``k_s(δ) = p_centre(δ) / δ``, is re-expressed along the centre curve as a
function of the dynamic pressure ``p = p_centre(δ)`` and fitted with

    k_s(p) = b1 p³ + b2 p² + b3 p + b4                       (eq. 16)

over the loop's range. The coefficients b1..b4 are reported against p0 (the paper's Fig. 8
shows k_s(p) for p0 = 0.5-2.5 MPa at pa = 0.4 MPa); :meth:`PressureStiffnessFit.at`
interpolates them linearly in p0 between tests.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from ..errors import ContactLabWarning, InputError
from . import paper as _paper
from .loop import LoopResult, analyze_loop
from .models import NonlinearContact


@dataclass
class PressureStiffnessFit:
    """b1..b4 of eq. 16 per test, sorted by p0. SI: k_s in Pa/m, p in Pa.

    ``b[i] = [b1, b2, b3, b4]`` of test ``i``; ``rms[i]`` the RMS residual of the cubic
    (Pa/m); ``psi[i]`` ψ (eq. 7) and ``omega[i]`` of that test.
    """

    p0: np.ndarray
    pa: np.ndarray
    b: np.ndarray
    rms: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    p_range: np.ndarray

    def b_display(self) -> np.ndarray:
        """b1..b4 in the paper's units (k_s in MPa/µm, p in MPa)."""
        return np.array([_paper.ks_pressure_to_display(row) for row in self.b])

    def at(self, p0: float) -> np.ndarray:
        """b1..b4 at mean pressure ``p0`` (linear interpolation between tests; a warning
        outside the tested range, where the end values are used)."""
        p0 = float(p0)
        if not np.isfinite(p0):
            raise InputError(f"p0 must be finite, got {p0}")
        if self.p0.size > 1 and (p0 < self.p0[0] or p0 > self.p0[-1]):
            warnings.warn(
                f"p0 = {p0:g} Pa is outside the tested range [{self.p0[0]:g}, {self.p0[-1]:g}] Pa",
                ContactLabWarning,
                stacklevel=2,
            )
        return np.array([np.interp(p0, self.p0, self.b[:, j]) for j in range(self.b.shape[1])])

    def model(
        self, p0: float, psi: float | None = None, omega: float | None = None
    ) -> NonlinearContact:
        """Eq. 17 with k_s(p) at ``p0``; ψ and ω default to the interpolated test values."""
        ps = float(np.interp(p0, self.p0, self.psi)) if psi is None else psi
        om = float(np.interp(p0, self.p0, self.omega)) if omega is None else omega
        return NonlinearContact(b=self.at(p0), psi=ps, omega=om, p0=p0)

    def to_dict(self) -> dict[str, Any]:
        return {
            "p0": self.p0.tolist(),
            "pa": self.pa.tolist(),
            "b": self.b.tolist(),
            "b_display": self.b_display().tolist(),
            "rms": self.rms.tolist(),
            "psi": self.psi.tolist(),
            "omega": self.omega.tolist(),
            "units": {
                "p0": "Pa",
                "pa": "Pa",
                "b": "k_s in Pa/m with p in Pa: [b1 (p^3), b2 (p^2), b3 (p), b4]",
                "b_display": "k_s in MPa/um with p in MPa",
                "rms": "Pa/m",
            },
        }

    def table(self) -> str:
        """b1..b4 against p0 in the paper's units."""
        rows = [f"{'p0 [MPa]':>9} {'b1':>11} {'b2':>11} {'b3':>11} {'b4':>11}"]
        for p0, bd in zip(self.p0, self.b_display(), strict=True):
            rows.append(f"{p0 / 1e6:9.3f} " + " ".join(f"{v:11.5f}" for v in bd))
        return "\n".join(rows)


def _as_result(item: Any, kwargs: Mapping[str, Any]) -> LoopResult:
    if isinstance(item, LoopResult):
        return item
    if isinstance(item, Mapping):
        try:
            t, p, d = item["t"], item["p"], item["delta"]
        except KeyError as exc:
            raise InputError(
                f"a test given as a dict needs keys t, p, delta: missing {exc}"
            ) from None
        kw = dict(kwargs)
        if "p0" in item:
            kw["p0"] = item["p0"]
        return analyze_loop(t, p, d, **kw)
    if isinstance(item, (tuple, list)) and len(item) in (3, 4):
        kw = dict(kwargs)
        if len(item) == 4:
            kw["p0"] = item[3]
        return analyze_loop(item[0], item[1], item[2], **kw)
    raise InputError(
        "each test must be a LoopResult, a (t, p, delta[, p0]) tuple or a dict with t, p, delta"
    )


def fit_pressure_stiffness(
    tests: Iterable[Any], *, n_points: int = 201, **analyze_kwargs: Any
) -> PressureStiffnessFit:
    """Fit eq. 16, ``k_s(p) = b1 p³ + b2 p² + b3 p + b4``, for each of several tests.

    Parameters
    ----------
    tests : iterable
        :class:`LoopResult` objects from :func:`analyze_loop`, or recordings
        ``(t, p, delta)`` / ``(t, p, delta, p0)`` tuples or dicts with keys ``t, p, delta``
        (and optionally ``p0``), which are analysed with ``analyze_kwargs``.
    n_points : int
        Points along the centre curve (between δ_min and δ_max) used for each cubic fit.

    Returns
    -------
    PressureStiffnessFit
        Per-test b1..b4 (SI) sorted by p0, with residuals, ψ and ω.

    Examples
    --------
    >>> from contactlab.normal import fit_pressure_stiffness
    >>> from contactlab.synthetic.normal import synthetic_recording
    >>> recs = [synthetic_recording(p0=p0, n_cycles=4, noise=None) for p0 in (0.5e6, 1.0e6)]
    >>> fit = fit_pressure_stiffness(recs)
    >>> fit.b.shape
    (2, 4)
    """
    results = [_as_result(item, analyze_kwargs) for item in tests]
    if not results:
        raise InputError("no tests given")
    if int(n_points) < 8:
        raise InputError(f"n_points must be >= 8, got {n_points}")
    rows = []
    for r in results:
        d = np.linspace(r.delta_min, r.delta_max, int(n_points))
        pc = np.polynomial.polynomial.polyval(d, np.asarray(r.poly_centre))
        ks = np.polynomial.polynomial.polyval(d, np.asarray(r.k_s_delta))
        if np.any(ks <= 0):
            raise InputError(
                f"k_s(δ) of the test at p0 = {r.p0:g} Pa is not positive over its loop"
            )
        if np.any(np.diff(pc) <= 0):
            warnings.warn(
                f"the centre curve of the test at p0 = {r.p0:g} Pa is not monotone; "
                "k_s as a function of p is then not single-valued",
                ContactLabWarning,
                stacklevel=2,
            )
        asc = np.asarray(_core.poly_fit(pc, ks, 3))
        res = ks - np.polynomial.polynomial.polyval(pc, asc)
        rows.append(
            (r.p0, r.pa, asc[::-1], float(np.sqrt(np.mean(res**2))), r.psi, r.omega, pc[[0, -1]])
        )
    rows.sort(key=lambda x: x[0])
    return PressureStiffnessFit(
        p0=np.array([x[0] for x in rows]),
        pa=np.array([x[1] for x in rows]),
        b=np.array([x[2] for x in rows]),
        rms=np.array([x[3] for x in rows]),
        psi=np.array([x[4] for x in rows]),
        omega=np.array([x[5] for x in rows]),
        p_range=np.array([x[6] for x in rows]),
    )
