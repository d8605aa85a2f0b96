"""The typed options of a tangential analysis (issue 32): :class:`Options`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Options"]


@dataclass(frozen=True)
class Options:
    """Settings of a tangential recording that every entry point takes the same way:
    :func:`~contactlab.tangential.analyze_tangential`, :func:`~contactlab.diagnose`
    (``options=``), :func:`~contactlab.track` (``options=``) and
    :func:`~contactlab.studies.run_study` (``tangential_options=``). A field left at None
    keeps the function's own default.

    Attributes
    ----------
    delay : float, optional
        Known delay (s) of the force channel behind the displacement.
    force_sign : {"auto", +1, -1}, optional
        The force's sign (``"auto"``: the one that makes the loop dissipate).
    output_filter : array_like, optional
        Taps of a smoothing the force channel went through (diagnose only).
    output_noise : float, optional
        The force channel's noise RMS when known (diagnose only).
    on, history : str, optional
        What the Masing fit runs on and the loop history (analyze only).
    n_points, min_cycles : int, optional
        Averaged-loop bins and the fewest cycles (analyze and track).
    rel_threshold, max_rel_stderr : float, optional
        Reversal threshold and the identifiability limit (analyze and track).
    fit_offset, fit_x0, fit_amplitude, detrend : bool, optional
        Which nuisance terms the fit takes (analyze and track).

    Examples
    --------
    >>> from contactlab.tangential import Options
    >>> from contactlab._options import as_dict
    >>> as_dict(Options(delay=1.1e-3, force_sign=-1))
    {'delay': 0.0011, 'force_sign': -1}
    """

    delay: float | None = None
    force_sign: int | str | None = None
    output_filter: Any = None
    output_noise: float | None = None
    on: str | None = None
    history: str | None = None
    n_points: int | None = None
    min_cycles: int | None = None
    rel_threshold: float | None = None
    max_rel_stderr: float | None = None
    fit_offset: bool | None = None
    fit_x0: bool | None = None
    fit_amplitude: bool | None = None
    detrend: bool | None = None
