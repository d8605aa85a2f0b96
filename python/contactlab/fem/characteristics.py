"""Joint characteristics for finite-element models, from a ``contactlab analyze --json`` result.

Normal contact (Konowalski 2009, PHYSICS.md §2): the loading branch ``p_load(δ)`` (eq. 1)
about the static pressure p0 becomes a pressure–overclosure table that starts at zero
pressure; the tangent stiffness k_tan (eq. 4) and the dissipation coefficient ψ (eq. 7) give
the Kelvin–Voigt viscous coefficient per unit area ``c = ψ k / (2π ω)`` (eq. 13) at a stated
angular frequency ω.

Tangential contact (Masing, PHYSICS.md §1): the friction coefficient μ = h0 / W and the stick
slope ``λ = h0·ac / A_c`` (initial stiffness per unit contact area, eq. 18) for an elastic
Coulomb law; for dynamics the secant stiffness ``k_global(A) = f(A)/A`` (eq. 19) and the
equivalent viscous coefficient ``c_e(A) = E(A) / (π A² ω)`` (eq. 17) at a named amplitude A and
angular frequency ω.

A value whose parameters the fit could not identify is refused with
:class:`NotIdentifiableError` carrying the analysis' own reason; nothing is guessed.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..masing import Masing
from .units import UnitSystem, unit_system


class NotIdentifiableError(InputError):
    """A requested joint value rests on parameters the fit did not identify (reason given)."""


#: bounds of ``points`` (rows of the pressure–overclosure table): the table samples the fitted
#: loading polynomial over the measured range, so three rows are the least that show its
#: curvature; FE solvers interpolate linearly between rows, and beyond a few thousand rows
#: the table only grows the input deck (10000 rows ≈ 0.6 MB of CalculiX input)
MIN_POINTS = 3
MAX_POINTS = 10_000


def check_points(points: object, where: str = "points") -> int:
    """``points`` as an int in ``MIN_POINTS..MAX_POINTS``, else :class:`InputError`."""
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)):
        raise InputError(
            f"{where} must be an integer in {MIN_POINTS}..{MAX_POINTS}, got {points!r}"
        )
    if not MIN_POINTS <= int(points) <= MAX_POINTS:
        raise InputError(f"{where} must be in {MIN_POINTS}..{MAX_POINTS}, got {points}")
    return int(points)


@dataclass(frozen=True)
class Value:
    """One exported number: SI value, its standard error (NaN if none), dimension and origin.

    ``dim`` is a key of :data:`contactlab.fem.units.DIMENSIONS` (``"pressure"``,
    ``"stiffness_per_area"``, ...); ``source`` says which fit or formula produced it.
    """

    name: str
    value: float
    stderr: float
    dim: str
    source: str

    def converted(self, units: UnitSystem) -> tuple[float, float, str]:
        f = units.factor(self.dim)
        return self.value * f, self.stderr * f, units.label(self.dim)


@dataclass
class JointCharacteristics:
    """What :func:`joint_characteristics` extracted: a normal or a tangential joint.

    ``table`` (normal only) is the pressure–overclosure table in SI, ``(pressure, overclosure)``
    rows starting at (0, 0), pressure strictly increasing; ``extrapolated_below`` is the
    pressure under which the rows are the tangent extension, not the measured branch.
    ``provenance`` lists ``(label, text)`` lines for the comment header (source file, fitted
    values ± stderr, identifiability); ``notes`` are caveats the user must read.
    """

    kind: str
    source: str
    values: list[Value]
    provenance: list[tuple[str, str]]
    table: np.ndarray | None = None
    extrapolated_below: float = 0.0
    notes: list[str] = field(default_factory=list)
    #: normal only: (absolute pressure, secant stiffness k_s) rows, eq. 6 along the centre curve
    ks_table: np.ndarray | None = None

    def get(self, name: str) -> Value | None:
        for v in self.values:
            if v.name == name:
                return v
        return None


# --- reading the analysis JSON ---------------------------------------------------------------


def load_result(path: str | Path, recording: str | None = None) -> dict[str, Any]:
    """One recording's object from an ``analyze --json`` file.

    A file with several recordings (``{"recordings": [...]}``) needs ``recording``: the index
    (0-based) or the recording's file name.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise InputError(
            f"{path}: a binary file, not the JSON `contactlab analyze --json` writes (export "
            "reads that JSON, not the recording: run `contactlab analyze FILE --json OUT` first)"
        ) from None
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{path}: not a JSON file (line {exc.lineno}): export reads the JSON "
            "`contactlab analyze --json` writes"
        ) from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: expected a JSON object from `contactlab analyze --json`")
    _not_other_result(doc, path)
    if "recordings" in doc:
        recs = doc["recordings"]
        if not isinstance(recs, list) or not recs:
            raise InputError(f"{path}: 'recordings' is empty")
        names = [str(r.get("file", i)) for i, r in enumerate(recs)]
        if recording is None:
            if len(recs) == 1:
                return recs[0]
            raise InputError(
                f"{path}: holds {len(recs)} recordings; choose one with --recording "
                f"(an index 0..{len(recs) - 1} or one of: {', '.join(names)})"
            )
        if recording.isdigit() and int(recording) < len(recs):
            return recs[int(recording)]
        for r, n in zip(recs, names, strict=True):
            if n == recording or Path(n).name == recording:
                return r
        raise InputError(f"{path}: no recording {recording!r} (have: {', '.join(names)})")
    if recording not in (None, "0"):
        raise InputError(f"{path}: holds one recording; --recording {recording} does not apply")
    return doc


def _not_other_result(doc: dict[str, Any], path: str | Path) -> None:
    """Refuse the JSON of another verb (track, diagnose, identify) by what it holds."""
    if "windows" in doc and "every" in doc:
        what = "a track result (`contactlab track --json`)"
    elif "final_model" in doc and "steps" in doc:
        what = "a diagnose result (`contactlab diagnose --json`)"
    elif "recordings" in doc or "model" in doc:
        return
    else:
        what = "not one recording's result of `contactlab analyze --json` (it has no 'model' key)"
        raise InputError(f"{path}: {what}; export needs the JSON of `contactlab analyze --json`")
    raise InputError(
        f"{path}: is {what}; export needs the JSON of `contactlab analyze --json` (one "
        "recording's fit: 'model' normal or tangential)"
    )


def _num(d: dict[str, Any], key: str, where: str, *, positive: bool = False) -> float:
    v = d.get(key)
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise InputError(f"{where}: key {key!r} is missing or not a finite number")
    if positive and not v > 0:
        raise InputError(f"{where}: {key} = {v} must be > 0")
    return float(v)


def _se(d: dict[str, Any], key: str) -> float:
    v = d.get(f"{key}_stderr")
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else math.nan


def _pm(value: float, stderr: float, unit: str) -> str:
    s = f" ± {stderr:.3g}" if math.isfinite(stderr) else " (no stderr)"
    return f"{value:.6g}{s} {unit}".rstrip()


# --- normal contact --------------------------------------------------------------------------


def _poly(c: list[float], x: np.ndarray) -> np.ndarray:
    return np.polynomial.polynomial.polyval(x, np.asarray(c, float))


def _normal(
    d: dict[str, Any], where: str, *, frequency: float | None, points: int
) -> JointCharacteristics:
    p0 = _num(d, "p0", where, positive=True)
    pa = _num(d, "pa", where, positive=True)
    dmin = _num(d, "delta_min", where)
    dmax = _num(d, "delta_max", where)
    load = d.get("poly_load")
    if not isinstance(load, list) or len(load) < 2:
        raise InputError(f"{where}: key 'poly_load' (loading-branch polynomial) is missing")
    if not dmax > dmin:
        raise NotIdentifiableError(f"{where}: delta_max ≤ delta_min: the loop has no extent")
    # The branch must rise monotonically over the measured range: a table cannot fold back.
    grid = np.linspace(dmin, dmax, 2001)
    slope = _poly(list(np.polynomial.polynomial.polyder(load)), grid)
    if not np.all(slope > 0):
        bad = float(grid[int(np.argmax(slope <= 0))])
        raise NotIdentifiableError(
            f"{where}: the fitted loading branch p_load(δ) is not increasing at δ = "
            f"{bad:.4g} m: no pressure–overclosure table can follow it (refit the loop with "
            "a lower polynomial degree or check the recording)"
        )
    p_abs = p0 + _poly(load, grid)
    notes: list[str] = []
    if p_abs[0] > 0:
        # Below the measured range: tangent continuation down to zero pressure (stated).
        u0 = p_abs[0] / slope[0]
        lo = float(p_abs[0])
        notes.append(
            f"pressures below {lo:.6g} Pa (p0 - pa) were not measured: the first segment is the "
            f"tangent of the loading branch at that point continued to zero pressure"
        )
        d_at_zero = dmin - u0
    else:
        i = int(np.argmax(p_abs > 0))
        d_at_zero = float(np.interp(0.0, p_abs[i - 1 : i + 1], grid[i - 1 : i + 1]))
        lo = 0.0
    n = check_points(points)
    dd = np.linspace(max(dmin, d_at_zero), dmax, n)
    pp = p0 + _poly(load, dd)
    if p_abs[0] > 0:
        table = np.vstack([[0.0, 0.0], np.column_stack([pp, dd - d_at_zero])])
    else:  # the branch itself reaches zero pressure: its first row is the origin
        table = np.column_stack([pp, dd - d_at_zero])
        table[0] = (0.0, 0.0)
    if not (np.all(np.diff(table[:, 0]) > 0) and np.all(np.diff(table[:, 1]) > 0)):
        raise NotIdentifiableError(f"{where}: the pressure–overclosure table is not monotone")
    notes.append(
        f"above {table[-1, 0]:.6g} Pa (p0 + pa, the highest measured pressure) CalculiX keeps "
        "the pressure constant and Abaqus extrapolates: stay inside the table"
    )
    k_tan = _num(d, "k_tan", where, positive=True)
    psi = d.get("psi")
    omega_test = _num(d, "omega", where, positive=True)
    omega = omega_test if frequency is None else 2 * math.pi * frequency
    src = f"loop fit (eq. 1, degree {d.get('degree', '?')}, {d.get('n_cycles', '?')} cycles)"
    values = [
        Value("k_tan", k_tan, math.nan, "stiffness_per_area", "eq. 4: slope of the centre curve"),
        Value(
            "k_s_p0",
            float(np.interp(p0, table[:, 0], np.gradient(table[:, 0], table[:, 1]))),
            math.nan,
            "stiffness_per_area",
            "tangent of the exported loading table at p0",
        ),
    ]
    if not isinstance(psi, (int, float)) or not math.isfinite(psi) or psi <= 0:
        notes.append(f"no damping exported: ψ = {psi} is not a positive number")
    else:
        e_d, e_se = _num(d, "E_d", where), _se(d, "E_d")
        rel = e_se / e_d if math.isfinite(e_se) and e_d > 0 else 0.0
        if rel > 0.5:
            raise NotIdentifiableError(
                f"{where}: the dissipated energy E_d = {e_d:.3g} ± {e_se:.2g} J/m² is not "
                f"identified (relative error {100 * rel:.0f}% > 50%): no damping can be exported"
            )
        c = float(psi) * k_tan / (2 * math.pi * omega)
        values.append(Value("psi", float(psi), float(psi) * rel, "1", "eq. 7: 2 E_d/(E_pd+E_pu)"))
        values.append(
            Value(
                "c_contact",
                c,
                c * rel,
                "damping_per_area",
                f"eq. 13: ψ·k_tan/(2π ω) at ω = {omega:.6g} rad/s ({omega / 2 / math.pi:.6g} Hz)",
            )
        )
    ks = _ks_table(d, where, dmin, dmax, n)
    prov = [
        ("source", str(d.get("file", where))),
        ("analysis", f"normal-contact loop, {src}"),
        ("p0, pa", f"{p0:.6g} Pa, {pa:.6g} Pa; test ω = {omega_test:.6g} rad/s"),
        ("poly_load", ", ".join(f"{c:.6g}" for c in load) + " (Pa, ascending powers of δ in m)"),
        ("E_d", _pm(_num(d, "E_d", where), _se(d, "E_d"), "J/m^2")),
        ("cycle scatter", f"{100 * float(d.get('cycle_scatter_rel', math.nan)):.3g}% of Δδ"),
    ]
    return JointCharacteristics(
        "normal", str(d.get("file", where)), values, prov, table, lo, notes, ks
    )


def _ks_table(d: dict[str, Any], where: str, dmin: float, dmax: float, n: int) -> np.ndarray:
    """k_s(p): eq. 6, ``k_s = p_centre(δ)/δ``, tabulated against p = p0 + p_centre(δ)."""
    centre = d.get("poly_centre")
    if not isinstance(centre, list) or len(centre) < 2:
        raise InputError(f"{where}: key 'poly_centre' (centre-curve polynomial) is missing")
    c = np.asarray(centre, float)
    dd = np.linspace(dmin, dmax, n)
    ks = np.polynomial.polynomial.polyval(dd, c[1:])  # (p_centre(δ) - a0)/δ, a0 ≈ 0 by eq. 1
    return np.column_stack([float(d["p0"]) + _poly(list(c), dd), ks])


# --- tangential contact ----------------------------------------------------------------------


def _dyn_grad(h0: float, ac: float, fn: Any) -> tuple[float, np.ndarray]:
    v = fn(h0, ac)
    g = np.empty(2)
    for i, (a, b) in enumerate(((h0 * 1e-6, 0.0), (0.0, ac * 1e-6))):
        g[i] = (fn(h0 + a, ac + b) - fn(h0 - a, ac - b)) / (2 * (a + b))
    return v, g


def _tag(d: dict[str, Any], keys: tuple[str, ...], where: str) -> float | None:
    """A numeric tag (a manifest column without a unit arrives as text, already SI)."""
    for k in keys:
        v = d.get(k)
        if v is None or v == "" or isinstance(v, bool):
            continue
        try:
            return float(v)
        except (TypeError, ValueError):
            raise InputError(f"{where}: tag {k} = {v!r} is not a number") from None
    return None


def _amplitude_values(
    d: dict[str, Any],
    where: str,
    fitted_values: tuple[float, float, float, float],
    ac_ok: bool,
    reason: str,
    amplitude: float,
    frequency: float | None,
    values: list[Value],
    notes: list[str],
) -> None:
    """The amplitude-dependent characteristics of a Masing fit at ``amplitude`` (k_global,
    c_e, the energy per cycle), appended to ``values``; a note when the amplitude is far from
    the tested one."""
    h0, h0_se, ac, ac_se = fitted_values
    ident = d.get("identifiable") if isinstance(d.get("identifiable"), dict) else {}
    if frequency is None:
        raise InputError(f"{where}: --amplitude needs --frequency (for the dashpot c_e)")
    if not ac_ok:
        raise NotIdentifiableError(
            f"{where}: k_global(A) and c_e(A) need h0 and ac; ac is not identified: {reason}"
        )
    m = Masing(h0, ac)
    omega = 2 * math.pi * frequency
    rho = float(ident.get("correlation_h0_ac", 0.0) or 0.0)
    cov = np.array([[h0_se**2, rho * h0_se * ac_se], [rho * h0_se * ac_se, ac_se**2]])

    def kg(a: float, b: float) -> float:
        return float(Masing(a, b).global_stiffness(amplitude))

    def ce(a: float, b: float) -> float:
        return float(Masing(a, b).loop_energy(amplitude)) / (math.pi * amplitude**2 * omega)

    for name, fn, dim, src in (
        ("k_global", kg, "stiffness", f"eq. 19: f(A)/A at A = {amplitude:.4g} m"),
        (
            "c_e",
            ce,
            "damping",
            f"eq. 17: E(A)/(π A² ω) at A = {amplitude:.4g} m, f = {frequency:.6g} Hz",
        ),
    ):
        v, g = _dyn_grad(h0, ac, fn)
        se = math.sqrt(max(float(g @ cov @ g), 0.0)) if np.all(np.isfinite(cov)) else math.nan
        values.append(Value(name, v, se, dim, src))
    fitted = d.get("amplitude")
    if isinstance(fitted, float) and not 0.25 * fitted <= amplitude <= 4 * fitted:
        notes.append(
            f"amplitude {amplitude:.3g} m is far from the tested {fitted:.3g} m: k_global and "
            "c_e extrapolate the exponential virgin curve"
        )
    values.append(
        Value(
            "energy_per_cycle",
            float(m.loop_energy(amplitude)),
            math.nan,
            "energy",
            f"Masing E(A) at A = {amplitude:.4g} m",
        )
    )


def _tangential(
    d: dict[str, Any],
    where: str,
    *,
    area: float | None,
    normal_load: float | None,
    amplitude: float | None,
    frequency: float | None,
) -> JointCharacteristics:
    ident = d.get("identifiable") if isinstance(d.get("identifiable"), dict) else {}
    reason = str(ident.get("message", "the analysis did not state its identifiability"))
    if normal_load is None:
        normal_load = _tag(d, ("normal_load",), where)
    if area is None:
        area = _tag(d, ("contact_area", "area"), where)
    if normal_load is None or not normal_load > 0:
        raise InputError(
            f"{where}: no normal load: give --normal-load (e.g. 50N) or tag the recording "
            "(file name W50N, or the manifest's 'normal_load [N]' column)"
        )
    if area is None or not area > 0:
        raise InputError(f"{where}: no contact area: give --area (e.g. 50cm2 or 5e-3m2)")
    if not (ident.get("h0", False) and d.get("h0") is not None):
        raise NotIdentifiableError(
            f"{where}: the friction coefficient needs h0, which is not identified: {reason}"
        )
    notes: list[str] = []
    h0, h0_se = _num(d, "h0", where, positive=True), _se(d, "h0")
    values = [
        Value("mu", h0 / normal_load, h0_se / normal_load, "1", "h0 / W"),
        Value("slip_force", h0, h0_se, "force", "μ·W = h0 (Jenkins F_s)"),
    ]
    if ident.get("h0_ac", False) and d.get("h0_ac") is not None:
        k0, k0_se = _num(d, "h0_ac", where, positive=True), _se(d, "h0_ac")
        values += [
            Value(
                "stick_slope", k0 / area, k0_se / area, "stiffness_per_area", "h0·ac / A_c (eq. 18)"
            ),
            Value(
                "elastic_slip",
                h0 / k0,
                h0 / k0 * math.hypot(h0_se / h0, k0_se / k0),
                "length",
                "μp/λ = h0/(h0·ac) = 1/ac",
            ),
            Value("k_stick", k0, k0_se, "stiffness", "h0·ac (Jenkins k)"),
        ]
    else:
        k0, k0_se = math.nan, math.nan
        lb = d.get("ac_lower_bound")
        bound = (
            f"; the data only bound it: ac ≥ {lb:.3g} 1/m, i.e. an elastic slip ≤ {1 / lb:.3g} m"
            if isinstance(lb, (int, float)) and lb > 0
            else ""
        )
        notes.append(f"no stick slope: h0·ac is not identified{bound} ({reason})")
    ac_ok = bool(ident.get("ac", False)) and d.get("ac") is not None
    ac, ac_se = (_num(d, "ac", where, positive=True), _se(d, "ac")) if ac_ok else (math.nan,) * 2
    if amplitude is not None:
        _amplitude_values(
            d, where, (h0, h0_se, ac, ac_se), ac_ok, reason, amplitude, frequency, values, notes
        )
    prov = [
        ("source", str(d.get("file", where))),
        (
            "analysis",
            f"tangential Masing fit ({d.get('on', '?')}, {d.get('history', '?')}"
            f"{', regime ' + str(d['regime']) if d.get('regime') else ''})",
        ),
        ("h0", _pm(h0, h0_se, "N")),
        ("ac", _pm(ac, ac_se, "1/m") if ac_ok else "not identified"),
        ("h0·ac", _pm(k0, k0_se, "N/m") if math.isfinite(k0) else "not identified"),
        ("identifiability", reason),
        ("normal load W", f"{normal_load:.6g} N"),
        ("contact area A_c", f"{area:.6g} m^2"),
    ]
    notes.append(
        "the elastic-Coulomb law is bilinear (Jenkins): its loop energy 4·F_s·(A - F_s/k) "
        "differs from the fitted Masing energy; compare both at your amplitude"
    )
    return JointCharacteristics(
        "tangential", str(d.get("file", where)), values, prov, None, 0.0, notes
    )


def joint_characteristics(
    result: dict[str, Any],
    *,
    where: str = "result",
    area: float | None = None,
    normal_load: float | None = None,
    amplitude: float | None = None,
    frequency: float | None = None,
    points: int = 25,
) -> JointCharacteristics:
    """Joint characteristics (SI) from one recording's ``analyze --json`` object.

    Parameters
    ----------
    result : dict
        One recording's object (see :func:`load_result`), ``model`` ``"normal"`` or
        ``"tangential"``.
    area, normal_load : float, optional
        Contact area (m²) and normal load (N) of a tangential test; default from the tags.
    amplitude, frequency : float, optional
        Tangential: the amplitude (m) and frequency (Hz) of the spring/dashpot values. Normal:
        the frequency (Hz) of the viscous coefficient (default the test's).
    points : int
        Rows of the pressure–overclosure table over the measured range (3..10000;
        :data:`MIN_POINTS`, :data:`MAX_POINTS`).

    Raises
    ------
    NotIdentifiableError
        A value rests on parameters that are not identified (the reason is in the message).

    Examples
    --------
    >>> from contactlab.fem import joint_characteristics
    >>> d = {"model": "tangential", "h0": 40.0, "h0_stderr": 0.1, "ac": 4e4,
    ...      "ac_stderr": 40.0, "h0_ac": 1.6e6, "h0_ac_stderr": 1e3,
    ...      "identifiable": {"h0": True, "ac": True, "h0_ac": True, "message": "ok"}}
    >>> jc = joint_characteristics(d, area=1e-4, normal_load=50.0)
    >>> round(jc.get("mu").value, 3), jc.get("stick_slope").value
    (0.8, 16000000000.0)
    """
    if not isinstance(result, dict):
        raise InputError(f"{where}: expected one recording's JSON object")
    kind = result.get("model")
    if kind == "normal":
        if frequency is not None and not frequency > 0:
            raise InputError("frequency must be > 0")
        return _normal(result, where, frequency=frequency, points=check_points(points))
    if kind == "tangential":
        return _tangential(
            result,
            where,
            area=area,
            normal_load=normal_load,
            amplitude=amplitude,
            frequency=frequency,
        )
    if kind is None:
        raise InputError(
            f"{where}: no 'model' key: not one recording's result of `contactlab analyze "
            "--json` (export needs 'model' normal or tangential)"
        )
    raise InputError(f"{where}: 'model' is {kind!r}; expected 'normal' or 'tangential'")


__all__ = [
    "JointCharacteristics",
    "NotIdentifiableError",
    "Value",
    "joint_characteristics",
    "load_result",
    "unit_system",
]
