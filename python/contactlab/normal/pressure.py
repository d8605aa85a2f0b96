"""The static pressure of a normal recording whose pressure channel holds only the dynamic
part (a piezo sensor): add it, and compare the pressure's half range with a nominal ``pa``."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..io import Recording
from .loop import dynamic_only

__all__ = ["with_static_pressure"]


def with_static_pressure(
    rec: Any, p0: float | None = None, pa: float | None = None, *, source: str = "the recording"
) -> tuple[Any, list[str]]:
    """``(recording, notes)``: ``rec`` with the static pressure ``p0`` added to its pressure
    channel when that channel holds only the dynamic part; unchanged otherwise.

    Parameters
    ----------
    rec : contactlab.io.Recording
        A normal recording (channel ``p`` in Pa).
    p0 : float, optional
        Static pressure (Pa); needed only when the channel is dynamic only.
    pa : float, optional
        Nominal pressure amplitude (Pa): a half range of the channel that misses it by more
        than 10 % gives a note naming both.
    source : str
        How the messages name the recording (a file name).

    Returns
    -------
    tuple of (Recording, list of str)
        The recording (a new one when ``p0`` was added) and the notes for the user.

    Raises
    ------
    InputError
        When the channel holds only the dynamic pressure and no ``p0`` is given.

    Examples
    --------
    >>> import numpy as np
    >>> from contactlab.io import Recording
    >>> t = np.linspace(0.0, 4 * np.pi, 200)
    >>> data = {"p": 0.4e6 * np.sin(t), "delta": 1e-7 * np.sin(t)}
    >>> rec = Recording(t, data, {"p": "Pa", "delta": "m"})
    >>> out, notes = with_static_pressure(rec, p0=1e6, pa=0.5e6, source="run.csv")
    >>> round(float(np.mean(out["p"])) / 1e6, 2), notes[0][:40]
    (1.0, "run.csv: the pressure's half range 4e+05")
    """
    p = np.asarray(rec["p"], dtype=float)
    # mean and half range on p / max|p|: a channel near 1e308 overflowed numpy's sum (fuzz
    # target diagnose) before the channel range check could name it
    big = float(np.max(np.abs(p))) if p.size and np.all(np.isfinite(p)) else 0.0
    unit = p / big if big > 0 else p
    notes = []
    if pa is not None:
        measured = big * 0.5 * float(np.ptp(unit)) if big > 0 else 0.0
        if abs(measured - pa) > 0.1 * pa:
            notes.append(
                f"{source}: the pressure's half range {measured:.4g} Pa differs "
                f"from the nominal pa = {pa:.4g} Pa"
            )
    if not dynamic_only(p):
        return rec, notes
    if p0 is None:
        mean = big * float(np.mean(unit)) if big > 0 else 0.0
        raise InputError(
            f"{source}: the pressure channel holds only the dynamic pressure (mean "
            f"{mean:.3g} Pa): give the static pressure with --p0 (e.g. 0.5MPa) "
            "or a file-name tag such as p0-0.5MPa"
        )
    data = dict(rec.data)
    data["p"] = p + p0
    return Recording(rec.t, data, dict(rec.units), rec.source, dict(rec.meta or {})), notes
