"""Writers of joint characteristics: CalculiX / Abaqus keywords, ANSYS APDL, neutral CSV / JSON.

Every file starts with a comment header naming the source file, the fit (values ± stderr),
the unit system and the caveats; every number is followed by its unit and its origin.

- ``calculix``: ``*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR`` (pressure, overclosure
  rows), ``*CONTACT DAMPING`` (per unit area); ``*FRICTION`` with ``μ, λ`` (λ = stick slope,
  force/length³); ``*SPRING``/``*DASHPOT`` for SPRINGA/DASHPOTA elements. Checked by running
  CalculiX (:mod:`contactlab.fem.checks`).
- ``abaqus``: the same keywords in Abaqus' form: ``*CONTACT DAMPING,
  DEFINITION=DAMPING COEFFICIENT`` and ``*FRICTION, ELASTIC SLIP=1/ac`` (the slip at which
  the full friction force is reached; μp/λ = 1/ac whatever the area).
- ``ansys``: APDL commands: ``MP,MU`` (friction), contact real constants ``FKN`` (3) and
  ``FKT`` (12) given negative, which CONTA17x reads as absolute stiffness in force/length³,
  the table as an APDL array, and ``COMBIN14`` real constants (k, CV1 = c) for a spring/dashpot.
  Not run through a solver here.
- ``csv`` / ``json``: neutral forms for other tools (one row per value, then the table).
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

from .._io_atomic import write_text
from ..errors import InputError
from .characteristics import JointCharacteristics, NotIdentifiableError, Value
from .units import FORMATS, UnitSystem


def _g(x: float) -> str:
    return f"{x:.9g}"


def _value_line(v: Value, u: UnitSystem) -> str:
    val, se, lab = v.converted(u)
    pm = f" ± {se:.3g}" if math.isfinite(se) else ""
    return f"{v.name} = {val:.6g}{pm} {lab} ({v.source})"


def _header(jc: JointCharacteristics, u: UnitSystem, fmt: str, c: str, command: str) -> list[str]:
    from .._version import __version__

    lines = [f"contactlab {__version__} joint characteristics ({jc.kind}), format {fmt}"]
    if command:
        lines.append(f"made by: {command}")
    lines.append(f"units: {u.describe()}")
    lines += [f"{k}: {t}" for k, t in jc.provenance]
    lines.append("exported values:")
    lines += [f"  {_value_line(v, u)}" for v in jc.values]
    lines += [f"note: {n}" for n in jc.notes]
    if fmt == "calculix" and jc.kind == "normal":
        lines.append(
            "note: CalculiX 2.20 converges with this table in TYPE=NODE TO SURFACE "
            "contact pairs (checked); with SURFACE TO SURFACE it did not"
        )
    return [f"{c} {line}".rstrip() for line in lines]


def _table(jc: JointCharacteristics, u: UnitSystem) -> list[tuple[float, float]]:
    assert jc.table is not None
    fp, fl = u.factor("pressure"), u.factor("length")
    return [(float(p) * fp, float(d) * fl) for p, d in jc.table]


def _ks_comment(jc: JointCharacteristics, u: UnitSystem, c: str) -> list[str]:
    if jc.ks_table is None:
        return []
    fp, fk = u.factor("pressure"), u.factor("stiffness_per_area")
    out = [
        f"{c} contact stiffness k_s(p) (eq. 6, secant along the centre curve): "
        f"pressure [{u.label('pressure')}], k_s [{u.label('stiffness_per_area')}]"
    ]
    out += [f"{c}   {_g(p * fp)}, {_g(k * fk)}" for p, k in jc.ks_table]
    return out


def _keywords(jc: JointCharacteristics, u: UnitSystem, abaqus: bool) -> list[str]:
    out: list[str] = []
    if jc.kind == "normal":
        out += [
            "*SURFACE INTERACTION, NAME=JOINT",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR",
            f"** pressure [{u.label('pressure')}], overclosure [{u.label('length')}]",
        ]
        out += [f"{_g(p)}, {_g(d)}" for p, d in _table(jc, u)]
        out += _ks_comment(jc, u, "**")
        c = jc.get("c_contact")
        if c is not None:
            val, _, lab = c.converted(u)
            out.append(f"** contact damping per unit area [{lab}]: {c.source}")
            out.append(
                "*CONTACT DAMPING, DEFINITION=DAMPING COEFFICIENT" if abaqus else "*CONTACT DAMPING"
            )
            out.append(_g(val))
    else:
        mu, lam = jc.get("mu"), jc.get("stick_slope")
        assert mu is not None
        out.append("** place under your *SURFACE INTERACTION (it also needs a *SURFACE BEHAVIOR)")
        if lam is None and not abaqus:
            why = next((n for n in jc.notes if n.startswith("no stick slope")), "")
            raise NotIdentifiableError(
                f"CalculiX's *FRICTION needs a stick slope: {why}. The friction coefficient "
                f"alone (μ = {mu.value:.4g}) goes out with --format abaqus, ansys, csv or json"
            )
        if abaqus and lam is None:
            out += [
                "** friction coefficient [1]; stick slope not identified: Abaqus' default "
                "penalty (SLIP TOLERANCE) applies",
                "*FRICTION",
                _g(mu.value),
            ]
        elif abaqus:
            slip = jc.get("elastic_slip")
            assert slip is not None
            s, _, lab = slip.converted(u)
            out += [
                f"** elastic slip [{lab}] = μp/λ = 1/ac",
                f"*FRICTION, ELASTIC SLIP={_g(s)}",
                _g(mu.value),
            ]
        else:
            assert lam is not None
            lv, _, lab = lam.converted(u)
            out += [
                f"** friction coefficient [1], stick slope [{lab}]",
                "*FRICTION",
                f"{_g(mu.value)}, {_g(lv)}",
            ]
    k, c = jc.get("k_global"), jc.get("c_e")
    if k is not None and c is not None:
        kv, _, kl = k.converted(u)
        cv, _, cl = c.converted(u)
        out += [
            f"** joint spring [{kl}] ({k.source}) for SPRINGA elements in ELSET JOINT_SPRING",
            "*SPRING, ELSET=JOINT_SPRING",
            "",
            _g(kv),
            f"** joint dashpot [{cl}] ({c.source}) for DASHPOTA elements in ELSET JOINT_DASHPOT",
            "*DASHPOT, ELSET=JOINT_DASHPOT",
            "",
            _g(cv),
        ]
    return out


def _ansys(jc: JointCharacteristics, u: UnitSystem) -> list[str]:
    out = ["/PREP7", "! contact pair real-constant set 1 and material 1 are assumed; renumber"]
    if jc.kind == "normal":
        ks = jc.get("k_s_p0")
        assert ks is not None
        kv, _, kl = ks.converted(u)
        rows = _table(jc, u)
        out += [
            f"! FKN < 0: absolute normal contact stiffness [{kl}], linearised at p0",
            "R,1",
            f"RMODIF,1,3,{_g(-kv)}",
            f"! pressure [{u.label('pressure')}] vs overclosure [{u.label('length')}] "
            "(the exported loading curve)",
            f"*DIM,JOINT_PU,ARRAY,{len(rows)},2",
        ]
        for i, (p, d) in enumerate(rows, 1):
            out.append(f"JOINT_PU({i},1)={_g(p)}")
            out.append(f"JOINT_PU({i},2)={_g(d)}")
        out += _ks_comment(jc, u, "!")
        c = jc.get("c_contact")
        if c is not None:
            cv, _, cl = c.converted(u)
            out += [f"! viscous coefficient per unit area [{cl}] ({c.source})", f"JOINT_C={_g(cv)}"]
    else:
        mu, lam = jc.get("mu"), jc.get("stick_slope")
        assert mu is not None
        out += ["! friction coefficient [1] (h0 / W)", f"MP,MU,1,{_g(mu.value)}"]
        if lam is None:
            out.append("! stick slope not identified: FKT left at the program default")
        else:
            lv, _, ll = lam.converted(u)
            out += [
                f"! FKT < 0: absolute tangential (stick) stiffness [{ll}] (h0·ac / A_c)",
                "R,1",
                f"RMODIF,1,12,{_g(-lv)}",
            ]
    k, c = jc.get("k_global"), jc.get("c_e")
    if k is not None and c is not None:
        kv, _, kl = k.converted(u)
        cv, _, cl = c.converted(u)
        out += [
            f"! COMBIN14 joint spring/dashpot: K [{kl}], CV1 [{cl}]",
            "ET,2,COMBIN14",
            f"R,2,{_g(kv)},{_g(cv)}",
        ]
    return out


def _rows(jc: JointCharacteristics, u: UnitSystem) -> list[dict[str, object]]:
    rows: list[dict[str, object]] = []
    for v in jc.values:
        val, se, lab = v.converted(u)
        rows.append(
            {
                "quantity": v.name,
                "index": "",
                "value": val,
                "stderr": se if math.isfinite(se) else None,
                "unit": lab,
                "source": v.source,
            }
        )
    if jc.table is not None:
        for i, (p, d) in enumerate(_table(jc, u)):
            p_si = float(jc.table[i, 0])
            src = (
                "loading branch"
                if p_si >= jc.extrapolated_below and p_si > 0
                else "zero pressure"
                if i == 0
                else "extrapolated (tangent)"
            )
            rows.append(
                {
                    "quantity": "table_pressure",
                    "index": i,
                    "value": p,
                    "stderr": None,
                    "unit": u.label("pressure"),
                    "source": src,
                }
            )
            rows.append(
                {
                    "quantity": "table_overclosure",
                    "index": i,
                    "value": d,
                    "stderr": None,
                    "unit": u.label("length"),
                    "source": src,
                }
            )
    if jc.ks_table is not None:
        src = "eq. 6: p_centre(δ)/δ along the centre curve"
        for i, (p, k) in enumerate(jc.ks_table):
            rows.append(
                {
                    "quantity": "ks_pressure",
                    "index": i,
                    "value": p * u.factor("pressure"),
                    "stderr": None,
                    "unit": u.label("pressure"),
                    "source": src,
                }
            )
            rows.append(
                {
                    "quantity": "ks",
                    "index": i,
                    "value": k * u.factor("stiffness_per_area"),
                    "stderr": None,
                    "unit": u.label("stiffness_per_area"),
                    "source": src,
                }
            )
    return rows


def render(jc: JointCharacteristics, fmt: str, units: UnitSystem, command: str = "") -> str:
    """The exported text in ``fmt`` (one of :data:`FORMATS`)."""
    if fmt in ("calculix", "abaqus"):
        lines = _header(jc, units, fmt, "**", command) + _keywords(jc, units, fmt == "abaqus")
    elif fmt == "ansys":
        lines = _header(jc, units, fmt, "!", command) + _ansys(jc, units)
    elif fmt == "csv":
        buf = io.StringIO()
        buf.write("\n".join(_header(jc, units, fmt, "#", command)) + "\n")
        w = csv.DictWriter(
            buf, ["quantity", "index", "value", "stderr", "unit", "source"], lineterminator="\n"
        )
        w.writeheader()
        for r in _rows(jc, units):
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})
        return buf.getvalue()
    elif fmt == "json":
        doc = {
            "kind": jc.kind,
            "units": units.name,
            "header": [line[2:] for line in _header(jc, units, fmt, "#", command)],
            "provenance": dict(jc.provenance),
            "notes": jc.notes,
            "values": [r for r in _rows(jc, units) if r["index"] == ""],
        }
        if jc.table is not None:
            doc["pressure_overclosure"] = [list(r) for r in _table(jc, units)]
        if jc.ks_table is not None:
            fp, fk = units.factor("pressure"), units.factor("stiffness_per_area")
            doc["ks_pressure"] = [[float(p) * fp, float(k) * fk] for p, k in jc.ks_table]
        return json.dumps(doc, indent=2, allow_nan=False) + "\n"
    else:
        raise InputError(f"unknown format {fmt!r}; choose one of {', '.join(FORMATS)}")
    return "\n".join(lines) + "\n"


def write(
    jc: JointCharacteristics, path: str | Path, fmt: str, units: UnitSystem, command: str = ""
) -> Path:
    """Render, then write atomically (never a half-written file)."""
    return write_text(path, render(jc, fmt, units, command))
