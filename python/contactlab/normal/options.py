"""The typed options of a normal-contact analysis (issue 32): :class:`Options`."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Options"]


@dataclass(frozen=True)
class Options:
    """Settings of a normal recording that every entry point takes the same way:
    :func:`~contactlab.normal.analyze_loop` (``options=``), :func:`~contactlab.track`
    (``options=``) and :func:`~contactlab.studies.run_study` (``normal_options=``). A field
    left at None keeps the function's own default.

    Attributes
    ----------
    p0 : float, optional
        Static pressure (Pa), for a pressure channel that holds only the dynamic part.
    pa : float, optional
        Nominal pressure amplitude (Pa).
    degree : int, optional
        Degree of the loop polynomials (eq. 1).
    omega : float, optional
        Angular frequency (1/s); default estimated from the record.
    discard_cycles : int, optional
        Start-up cycles left out.
    zero_delta : bool, optional
        Zero the displacement at the static state.
    n_bins : int, optional
        Bins of the averaged loop.

    Examples
    --------
    >>> from contactlab.normal import Options
    >>> from contactlab._options import as_dict
    >>> as_dict(Options(p0=0.5e6, pa=0.4e6))
    {'p0': 500000.0, 'pa': 400000.0}
    """

    p0: float | None = None
    pa: float | None = None
    degree: int | None = None
    omega: float | None = None
    discard_cycles: int | None = None
    zero_delta: bool | None = None
    n_bins: int | None = None
