"""``contactlab simulate tangential|normal OUT [parameters]``: write a synthetic recording.

Tangential: Masing hysteresis with an exponential virgin curve under a sine displacement
(:func:`contactlab.tangential.synthetic_recording`). Normal: Konowalski's contact under
``p = pa sin(ω t)`` about p0 (:func:`contactlab.normal.synthetic_recording`). The format
follows OUT's extension (.csv .tdms .h5 .mat); values are SI, quantities on the command line
may carry a unit (``--amplitude 20um``, ``--p0 0.5MPa``).
"""

from __future__ import annotations

import argparse

from ._common import describe, quantity


def _handler(args: argparse.Namespace) -> int:
    from ..io import Recording, write_recording

    if args.model == "structure":
        from .structure import simulate_structure

        return simulate_structure(args)
    if args.model == "tangential":
        from ..tangential import synthetic_recording

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
        from ..normal import synthetic_recording as normal_synthetic

        kwargs = {"noise": "realistic" if args.noise is None else args.noise, "seed": args.seed}
        if args.normal_model:
            kwargs["model"] = args.normal_model
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
    path = write_recording(args.out, rec)
    print(f"wrote {path} ({len(rec.t)} samples)")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "simulate",
        help="write a synthetic recording (tangential Masing or normal contact)",
        description=describe(__doc__),
    )
    p.add_argument("model", choices=("tangential", "normal", "structure"))
    p.add_argument("out", metavar="OUT", help="output file (.csv .tdms .h5 .mat)")
    g = p.add_argument_group("tangential")
    g.add_argument("--h0", type=quantity("N"), default=40.0, help="saturation force (N)")
    g.add_argument("--ac", type=quantity("1/m"), default=4e4, help="curvature (1/m)")
    g.add_argument("--amplitude", type=quantity("m"), default=20e-6,
                   help="displacement amplitude (m; e.g. 20um)")  # fmt: skip
    g.add_argument("--frequency", type=quantity("Hz", positive=True), default=1.0, help="Hz")
    g.add_argument(
        "--fs", type=quantity("Hz", positive=True), default=500.0, help="sampling rate (Hz)"
    )
    g.add_argument("--offset", type=quantity("N"), default=0.0, help="load-cell zero offset (N)")
    g.add_argument("--x-offset", type=quantity("m"), default=0.0,
                   help="displacement-sensor zero offset (m)")  # fmt: skip
    g.add_argument("--drift", type=float, default=0.0, help="force drift (N/s)")
    g.add_argument("--adc-bits", type=int, default=None, help="quantise to this many bits")
    n = p.add_argument_group("normal")
    n.add_argument("--p0", type=quantity("Pa"), default=0.5e6, help="static pressure (Pa)")
    n.add_argument("--pa", type=quantity("Pa"), default=0.4e6, help="pressure amplitude (Pa)")
    n.add_argument("--omega", type=quantity("1/s"), default=1.0, help="angular frequency (1/s)")
    n.add_argument("--samples-per-cycle", type=int, default=400)
    n.add_argument("--normal-model", default=None, choices=("nonlinear", "linear", "table2"),
                   help="eq. 17 (default), Kelvin-Voigt, or the Table 2 loop itself")  # fmt: skip
    p.add_argument("--cycles", type=int, default=5, help="number of cycles")
    p.add_argument("--noise", type=float, default=None,
                   help="tangential: force noise as a fraction of the peak force (default "
                   "0.01); normal: relative to each channel's peak-to-peak value (default: "
                   "realistic sensor noise and 16-bit quantisation); 0 = exact")  # fmt: skip
    p.add_argument("--seed", type=int, default=0)
    s = p.add_argument_group("structure (a model from `contactlab identify --json`)")
    s.add_argument("--structure", help="model JSON (identified model or Structure.save)")
    s.add_argument("--input", help="CSV with the input column and a time column (else --fs)")
    s.add_argument("--u", help="input column name")
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
    p.set_defaults(handler=_handler)
