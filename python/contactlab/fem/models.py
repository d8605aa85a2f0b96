"""Small CalculiX/Abaqus input decks for checking exported joint characteristics (no mesher).

- :func:`two_block_deck`: two elastic blocks (hexahedral C3D8 mesh, ``n × n × m`` elements
  each) stacked along z and joined by a contact pair carrying the exported behaviour.
  ``mode="normal"``: symmetry planes x = 0 and y = 0 and a roller base, a pressure ramp on the
  top face; the stress is then exactly uniaxial, so the top displacement is the analytic series
  ``2·p·H/E + u_joint(p)``. ``mode="shear"``: every node held in y, the lower block held in x,
  the upper block driven in x by a cyclic amplitude under a constant pressure; the blocks only
  deform in z, so the interface carries the whole tangential displacement.
- :func:`beam_deck`: a B31 beam along x, pinned at x = 0 (y, z, torsion), held in z along its
  length, its tip tied to ground by the exported joint spring (SPRINGA, ELSET JOINT_SPRING) and
  dashpot (DASHPOTA, ELSET JOINT_DASHPOT), and a ``*FREQUENCY`` step.

Decks are in whatever consistent unit system the caller's numbers are in (the checks use
mm-N-s: mm, N, s, t, MPa).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class Block:
    """Two identical stacked blocks: footprint ``size × size``, each ``height`` tall."""

    size: float = 10.0
    height: float = 5.0
    n: int = 2  # elements along x and y
    m: int = 2  # elements along z per block
    E: float = 210000.0
    nu: float = 0.3

    @property
    def area(self) -> float:
        return self.size * self.size


def _ids_lines(ids: Sequence[int]) -> list[str]:
    a = sorted(set(int(i) for i in ids))
    return [", ".join(map(str, a[i : i + 8])) for i in range(0, len(a), 8)]


def _mesh(b: Block) -> tuple[list[str], dict[str, np.ndarray], dict[str, list[int]]]:
    if b.n < 1 or b.m < 1 or not (b.size > 0 and b.height > 0 and b.E > 0):
        raise InputError("block: size, height, E must be > 0 and n, m ≥ 1")
    lines = ["*NODE"]
    grids: dict[str, np.ndarray] = {}
    nid = 0
    for name, z0 in (("A", 0.0), ("B", b.height)):
        ids = np.zeros((b.n + 1, b.n + 1, b.m + 1), int)
        for k in range(b.m + 1):
            for j in range(b.n + 1):
                for i in range(b.n + 1):
                    nid += 1
                    ids[i, j, k] = nid
                    x, y, z = i * b.size / b.n, j * b.size / b.n, z0 + k * b.height / b.m
                    lines.append(f"{nid}, {x:.9g}, {y:.9g}, {z:.9g}")
        grids[name] = ids
    sets: dict[str, list[int]] = {"EA": [], "EB": [], "EATOP": [], "EBBOT": [], "EBTOP": []}
    eid = 0
    for name in ("A", "B"):
        ids = grids[name]
        lines.append(f"*ELEMENT, TYPE=C3D8, ELSET=E{name}")
        for k in range(b.m):
            for j in range(b.n):
                for i in range(b.n):
                    eid += 1
                    c = [
                        ids[i, j, k],
                        ids[i + 1, j, k],
                        ids[i + 1, j + 1, k],
                        ids[i, j + 1, k],
                        ids[i, j, k + 1],
                        ids[i + 1, j, k + 1],
                        ids[i + 1, j + 1, k + 1],
                        ids[i, j + 1, k + 1],
                    ]
                    lines.append(f"{eid}, " + ", ".join(map(str, c)))
                    sets[f"E{name}"].append(eid)
                    if name == "A" and k == b.m - 1:
                        sets["EATOP"].append(eid)
                    if name == "B" and k == 0:
                        sets["EBBOT"].append(eid)
                    if name == "B" and k == b.m - 1:
                        sets["EBTOP"].append(eid)
    return lines, grids, sets


def two_block_deck(
    block: Block,
    interaction: Sequence[str],
    *,
    mode: str,
    pressure: float,
    increments: int = 20,
    amplitudes: Sequence[float] = (),
    cycles: int = 1,
    increment: float = 0.025,
) -> str:
    """Input deck of the two-block model.

    ``interaction`` holds the keyword lines after ``*SURFACE INTERACTION, NAME=JOINT`` (the
    exported behaviour). ``mode="normal"``: a static ramp to ``pressure`` in ``increments``
    equal steps, node-to-surface contact (CalculiX 2.20 converges with a tabular law there),
    ``*NODE PRINT`` of the top face and ``*CONTACT PRINT`` (CDIS, CSTR) at every increment.
    ``mode="shear"``: ``pressure`` applied first, then for each amplitude a triangular cycle
    0 → A → −A → A repeated ``cycles`` times more (steps of at most ``increment`` of a quarter
    cycle), surface-to-surface contact; ``*NODE PRINT`` of the upper block's total reaction
    force and the top face displacements.
    """
    if mode not in ("normal", "shear"):
        raise InputError(f"mode must be 'normal' or 'shear', not {mode!r}")
    lines, g, sets = _mesh(block)
    A, B = g["A"], g["B"]

    def nset(name: str, ids: np.ndarray) -> None:
        lines.append(f"*NSET, NSET={name}")
        lines.extend(_ids_lines(ids.ravel().tolist()))

    def elset(name: str) -> None:
        lines.append(f"*ELSET, ELSET={name}")
        lines.extend(_ids_lines(sets[name]))

    nset("NTOP", B[:, :, -1])
    nset("NBASE", A[:, :, 0])
    nset("NA", A)
    nset("NB", B)
    nset("NX0", np.r_[A[0].ravel(), B[0].ravel()])
    nset("NY0", np.r_[A[:, 0].ravel(), B[:, 0].ravel()])
    nset("NALL", np.r_[A.ravel(), B.ravel()])
    for s in ("EA", "EB", "EATOP", "EBBOT", "EBTOP"):
        if s not in ("EA", "EB"):
            elset(s)
    lines += [
        "*SURFACE, NAME=SMASTER, TYPE=ELEMENT",
        "EATOP, S2",
        "*SURFACE, NAME=SSLAVE, TYPE=ELEMENT",
        "EBBOT, S1",
        "*MATERIAL, NAME=BLOCK",
        "*ELASTIC",
        f"{block.E:.9g}, {block.nu:.9g}",
        "*SOLID SECTION, ELSET=EA, MATERIAL=BLOCK",
        "*SOLID SECTION, ELSET=EB, MATERIAL=BLOCK",
        "*SURFACE INTERACTION, NAME=JOINT",
        *interaction,
    ]
    kind = "NODE TO SURFACE" if mode == "normal" else "SURFACE TO SURFACE"
    lines += [f"*CONTACT PAIR, INTERACTION=JOINT, TYPE={kind}", "SSLAVE, SMASTER"]
    if mode == "normal":
        if increments < 2:
            raise InputError("increments must be ≥ 2")
        lines += [
            "*BOUNDARY",
            "NX0, 1",
            "NY0, 2",
            "NBASE, 3",
            "*STEP, INC=1000",
            "*STATIC, DIRECT",
            f"{1 / increments:.9g}, 1.0",
            "*DLOAD",
            f"EBTOP, P2, {pressure:.9g}",
            "*NODE PRINT, NSET=NTOP",
            "U",
            "*CONTACT PRINT",
            "CDIS, CSTR",
            "*END STEP",
        ]
        return "\n".join(lines) + "\n"
    if not amplitudes or any(not a > 0 for a in amplitudes) or cycles < 1:
        raise InputError("shear: give positive amplitudes and cycles ≥ 1")
    t = [0.0, 1.0] + [v for c in range(cycles) for v in (3.0 + 4 * c, 5.0 + 4 * c)]
    a = [0.0, 1.0] + [v for _ in range(cycles) for v in (-1.0, 1.0)]
    lines.append("*AMPLITUDE, NAME=CYCLE")
    lines += [
        ", ".join(f"{ti:g}, {ai:g}" for ti, ai in zip(t[i : i + 4], a[i : i + 4], strict=True))
        for i in range(0, len(t), 4)
    ]
    lines += [
        "*BOUNDARY",
        "NBASE, 3",
        "NA, 1",
        "NALL, 2",
        "*STEP, INC=10000",
        "*STATIC, DIRECT",
        "0.25, 1.0",
        "*BOUNDARY",
        "NB, 1, 1, 0.",
        "*DLOAD",
        f"EBTOP, P2, {pressure:.9g}",
        "*END STEP",
    ]
    period = t[-1]
    for amp in amplitudes:
        lines += [
            "*STEP, INC=100000",
            "*STATIC",
            f"{increment:.9g}, {period:g}, 1e-7, {increment:.9g}",
            "*BOUNDARY, AMPLITUDE=CYCLE",
            f"NB, 1, 1, {amp:.9g}",
            "*NODE PRINT, NSET=NB, TOTALS=ONLY",
            "RF",
            "*NODE PRINT, NSET=NTOP",
            "U",
            "*END STEP",
        ]
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class Beam:
    """A prismatic beam of square section ``side`` along x, ``n`` B31 elements."""

    length: float
    side: float
    n: int = 40
    E: float = 210000.0
    nu: float = 0.3
    density: float = 7.85e-9

    @property
    def EI(self) -> float:
        return self.E * self.side**4 / 12.0

    @property
    def mass_per_length(self) -> float:
        return self.density * self.side**2


def beam_deck(beam: Beam, joint: Sequence[str], *, modes: int = 3) -> str:
    """Input deck of the beam with the joint spring/dashpot at its tip and a *FREQUENCY step.

    ``joint`` holds the exported ``*SPRING``/``*DASHPOT`` lines (ELSETs JOINT_SPRING and
    JOINT_DASHPOT); the spring element runs from the tip along −y to a fixed ground node.
    """
    if beam.n < 2 or not (beam.length > 0 and beam.side > 0):
        raise InputError("beam: length and side must be > 0 and n ≥ 2")
    n = beam.n
    tip, ground = n + 1, n + 2
    lines = ["*NODE"]
    lines += [f"{i + 1}, {beam.length * i / n:.9g}, 0, 0" for i in range(n + 1)]
    lines.append(f"{ground}, {beam.length:.9g}, {-beam.length / 10:.9g}, 0")
    lines.append("*ELEMENT, TYPE=B31, ELSET=EBEAM")
    lines += [f"{i + 1}, {i + 1}, {i + 2}" for i in range(n)]
    lines += [
        "*ELEMENT, TYPE=SPRINGA, ELSET=JOINT_SPRING",
        f"{n + 1}, {tip}, {ground}",
        "*ELEMENT, TYPE=DASHPOTA, ELSET=JOINT_DASHPOT",
        f"{n + 2}, {tip}, {ground}",
        "*NSET, NSET=NBEAM",
        *_ids_lines(list(range(1, n + 2))),
        "*MATERIAL, NAME=BEAM",
        "*ELASTIC",
        f"{beam.E:.9g}, {beam.nu:.9g}",
        "*DENSITY",
        f"{beam.density:.9g}",
        "*BEAM SECTION, ELSET=EBEAM, MATERIAL=BEAM, SECTION=RECT",
        f"{beam.side:.9g}, {beam.side:.9g}",
        "0, 0, 1",
        *joint,
        "*BOUNDARY",
        "1, 1, 3",
        "1, 4, 4",
        f"{ground}, 1, 3",
        "NBEAM, 3, 3",
        "*STEP",
        "*FREQUENCY",
        f"{modes}",
        "*END STEP",
    ]
    return "\n".join(lines) + "\n"
