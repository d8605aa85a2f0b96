"""``contactlab simulate tangential|normal OUT [parameters]``: write a synthetic recording.

Tangential: Masing hysteresis with an exponential virgin curve under a sine displacement
(:func:`contactlab.synthetic.tangential.synthetic_recording`). Normal: Konowalski's contact under
``p = pa sin(ω t)`` about p0 (:func:`contactlab.synthetic.normal.synthetic_recording`). The format
follows OUT's extension (.csv .tdms .h5 .mat); values are SI, quantities on the command line
may carry a unit (``--amplitude 20um``, ``--p0 0.5MPa``).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from ..errors import InputError
from .common import DefaultsShown, describe, quantity

if TYPE_CHECKING:
    from ..io import Recording

#: most samples one run may generate: ~160 MB per float64 channel, several working copies
#: while the signal is made, and a CSV of ~1 GB; a longer record is better made in pieces
MAX_SAMPLES = 20_000_000


#: physically meaningful ranges of the simulation's quantities, SI: ``(low, high, what)``;
#: ``low`` None for a signed quantity bounded in magnitude by ``high``. Found by audit:
#: ``--amplitude 1e30`` (m) was accepted and written as a recording.
RANGES: dict[str, tuple[float | None, float, str]] = {
    "h0": (1e-6, 1e8, "a saturation force"),
    "ac": (1e-2, 1e10, "a curvature (saturation within 0.1 nm to 100 m)"),
    "amplitude": (1e-9, 1.0, "a displacement amplitude of a contact"),
    "frequency": (1e-6, 1e6, "an excitation frequency"),
    "fs": (1e-3, 1e9, "a sampling rate"),
    "offset": (None, 1e8, "a load-cell zero offset"),
    "x_offset": (None, 1.0, "a displacement-sensor zero offset"),
    "p0": (1.0, 1e10, "a contact pressure"),
    "pa": (1.0, 1e10, "a pressure amplitude"),
    "omega": (1e-6, 1e7, "an angular frequency"),
}


def finite_quantity(
    default_unit: str, *, positive: bool = False, bounds: str | None = None
) -> Callable[[str], float]:
    """argparse ``type=``: :func:`quantity` that also refuses non-finite values (``1e400``)
    and, with ``bounds`` (a key of :data:`RANGES`), values outside the physical range."""
    parse = quantity(default_unit, positive=positive)
    rng = "a finite number > 0" if positive else "a finite number"

    def check(text: str) -> float:
        value = parse(text)
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text!r}: must be {rng} ({default_unit})")
        if bounds is not None:
            lo, hi, what = RANGES[bounds]
            if lo is None and not abs(value) <= hi:
                raise argparse.ArgumentTypeError(
                    f"{text!r} = {value:g} {default_unit}: {what} must be within "
                    f"±{hi:g} {default_unit}"
                )
            if lo is not None and not lo <= value <= hi:
                raise argparse.ArgumentTypeError(
                    f"{text!r} = {value:g} {default_unit}: {what} must be in "
                    f"{lo:g}..{hi:g} {default_unit}"
                )
        return value

    check.__name__ = parse.__name__
    return check


def real(*, minimum: float | None = None, maximum: float | None = None) -> Callable[[str], float]:
    """argparse ``type=``: a finite float, ``>= minimum`` and ``<= maximum`` when given."""
    rng = "a finite number" + ("" if minimum is None else f" >= {minimum:g}")
    rng += "" if maximum is None else f"{' and' if minimum is not None else ''} <= {maximum:g}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number (give {rng})") from None
        if (
            not math.isfinite(value)
            or (minimum is not None and value < minimum)
            or (maximum is not None and value > maximum)
        ):
            raise argparse.ArgumentTypeError(f"{text!r}: must be {rng}")
        return value

    parse.__name__ = "number"
    return parse


def integer(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """argparse ``type=``: an integer in ``minimum..maximum`` (no upper bound when None)."""
    rng = f"an integer >= {minimum}" if maximum is None else f"an integer in {minimum}..{maximum}"

    def parse(text: str) -> int:
        try:
            value = int(text.strip())
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {rng}") from None
        if value < minimum or (maximum is not None and value > maximum):
            raise argparse.ArgumentTypeError(f"{text!r}: must be {rng}")
        return value

    parse.__name__ = "integer"
    return parse


def _check_length(args: argparse.Namespace) -> None:
    """Refuse a record too long to generate before any memory is spent on it."""
    if args.model == "tangential":
        n = args.cycles * args.fs / args.frequency
        how = "--cycles × --fs / --frequency"
    else:
        n = args.cycles * args.samples_per_cycle
        how = "--cycles × --samples-per-cycle"
    if not n <= MAX_SAMPLES:
        raise InputError(
            f"{how} = {n:.4g} samples; at most {MAX_SAMPLES:,} can be generated in one run "
            "(make fewer cycles or a lower rate)"
        )


def _check_finite(rec: Recording, args: argparse.Namespace) -> None:
    """The generated channels must be finite: magnitudes that overflow are refused."""
    import numpy as np

    for name in ["t", *rec.channels]:
        data = rec.t if name == "t" else rec[name]
        if not np.all(np.isfinite(data)):
            flags = (
                "--h0, --amplitude, --noise, --offset, --x-offset, --drift"
                if args.model == "tangential"
                else "--p0, --pa, --noise"
            )
            raise InputError(
                f"channel {name!r} of the simulated recording is not finite (the magnitudes "
                f"overflow double precision): give smaller values of {flags}; nothing written"
            )


def _handler(args: argparse.Namespace) -> int:
    from ..io import Recording, write_recording

    if args.model == "structure":
        from .structure import simulate_structure

        return simulate_structure(args)
    import numpy as np

    _check_length(args)
    if args.model == "tangential":
        from ..synthetic.tangential import synthetic_recording

        with np.errstate(over="ignore", invalid="ignore"):  # overflow is refused below
            rec = synthetic_recording(
                h0=args.h0,
                ac=args.ac,
                amplitude=args.amplitude,
                frequency=args.frequency,
                n_cycles=args.cycles,
                fs=args.fs,
                noise=0.01 if args.noise is None else args.noise,
                seed=args.seed,
                offset=args.offset,
                x_offset=args.x_offset,
                drift=args.drift,
                adc_bits=args.adc_bits,
            )
    else:
        from ..synthetic.normal import synthetic_recording as normal_synthetic

        kwargs = {"noise": "realistic" if args.noise is None else args.noise, "seed": args.seed}
        if args.normal_model:
            kwargs["model"] = args.normal_model
        with np.errstate(over="ignore", invalid="ignore"):  # overflow is refused below
            t, p, delta = normal_synthetic(
                args.p0, args.pa, args.omega, args.cycles, args.samples_per_cycle, **kwargs
            )
        rec = Recording(
            t,
            {"p": p, "delta": delta},
            {"p": "Pa", "delta": "m"},
            source="contactlab simulate normal",
            meta={"p0": args.p0, "pa": args.pa, "omega": args.omega},
        )
    _check_finite(rec, args)
    path = write_recording(args.out, rec)
    print(f"wrote {path} ({len(rec.t)} samples)")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "simulate",
        help="write a synthetic recording (tangential Masing or normal contact)",
        description=describe(__doc__),
        formatter_class=DefaultsShown,
    )
    p.add_argument("model", choices=("tangential", "normal", "structure"))
    p.add_argument("out", metavar="OUT", help="output file (.csv .tdms .h5 .mat)")
    _tangential_flags(p.add_argument_group("tangential"))
    _normal_flags(p.add_argument_group("normal"))
    p.add_argument(
        "--cycles",
        type=integer(1),
        default=5,
        help=f"number of cycles (an integer >= 1; at most {MAX_SAMPLES:,} samples in all)",
    )
    p.add_argument(
        "--noise",
        type=real(minimum=0.0, maximum=10.0),
        default=None,
        help="tangential: force noise as a fraction of the peak force (default "
        "0.01); normal: relative to each channel's peak-to-peak value (default: "
        "realistic sensor noise and 16-bit quantisation); 0 = exact, 0..10",
    )
    p.add_argument(
        "--seed",
        type=integer(0),
        default=0,
        help="noise generator seed (a non-negative integer; default 0)",
    )
    _structure_flags(p.add_argument_group("structure (a model from `contactlab identify --json`)"))
    p.set_defaults(handler=_handler)


def _tangential_flags(g: argparse._ArgumentGroup) -> None:
    """The flags of a tangential recording."""
    g.add_argument(
        "--h0",
        type=finite_quantity("N", positive=True, bounds="h0"),
        default=40.0,
        help="saturation force (N, > 0)",
    )
    g.add_argument(
        "--ac",
        type=finite_quantity("1/m", positive=True, bounds="ac"),
        default=4e4,
        help="curvature (1/m, > 0)",
    )
    g.add_argument(
        "--amplitude",
        type=finite_quantity("m", positive=True, bounds="amplitude"),
        default=20e-6,
        help="displacement amplitude (m, 1nm..1m: 20um)",
    )
    g.add_argument(
        "--frequency",
        type=finite_quantity("Hz", positive=True, bounds="frequency"),
        default=1.0,
        help="Hz, 1e-6..1e6",
    )
    g.add_argument(
        "--fs",
        type=finite_quantity("Hz", positive=True, bounds="fs"),
        default=500.0,
        metavar="RATE",
        help="sampling rate (Hz, > 0)",
    )
    g.add_argument(
        "--offset",
        type=finite_quantity("N", bounds="offset"),
        default=0.0,
        help="load-cell zero offset (N)",
    )
    g.add_argument(
        "--x-offset",
        type=finite_quantity("m", bounds="x_offset"),
        default=0.0,
        help="displacement-sensor zero offset (m)",
    )
    g.add_argument(
        "--drift",
        type=real(),
        default=0.0,
        help="force drift (N/s, a finite number of either sign)",
    )
    g.add_argument(
        "--adc-bits", type=integer(4, 32), default=None, help="quantise to this many bits (4..32)"
    )


def _normal_flags(n: argparse._ArgumentGroup) -> None:
    """The flags of a normal-contact recording."""
    n.add_argument(
        "--p0",
        type=finite_quantity("Pa", positive=True, bounds="p0"),
        default=0.5e6,
        help="static pressure (Pa, > 0)",
    )
    n.add_argument(
        "--pa",
        type=finite_quantity("Pa", positive=True, bounds="pa"),
        default=0.4e6,
        help="pressure amplitude (Pa, > 0 and <= p0)",
    )
    n.add_argument(
        "--omega",
        type=finite_quantity("1/s", positive=True, bounds="omega"),
        default=1.0,
        help="angular frequency (1/s, 1e-6..1e7)",
    )
    n.add_argument(
        "--samples-per-cycle",
        type=integer(8),
        default=400,
        help="samples per cycle (an integer >= 8; default 400)",
    )
    n.add_argument(
        "--normal-model",
        default=None,
        choices=("nonlinear", "linear", "table2"),
        help="eq. 17 (default), Kelvin-Voigt, or the Table 2 loop itself",
    )


def _structure_flags(s: argparse._ArgumentGroup) -> None:
    """The flags of a structure's response."""
    s.add_argument(
        "--structure", metavar="MODEL.json", help="model JSON (identified model or Structure.save)"
    )
    s.add_argument(
        "--input", metavar="FILE", help="CSV with the input column and a time column (else --fs)"
    )
    s.add_argument("--u", metavar="COLUMN", help="input column name")
    s.add_argument("--base", action="store_true", help="the input is base displacement")
    s.add_argument(
        "--periodic",
        action="store_true",
        help="periodic steady state (input repeated until the response repeats)",
    )
    s.add_argument(
        "--partial",
        action="store_true",
        help="if the integration stops early, write the samples it reached (exit 1 all the "
        "same); without it a failed run writes nothing",
    )
