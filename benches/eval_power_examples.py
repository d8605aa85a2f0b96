"""The stated power bounds of ``contactlab diagnose`` on three example records (issue 29,
item 2, for the closing note): one clean rig record (``contactlab.synthetic.rig``), one
record of the package's own generator (``hidden_effect_recording``) and one measured record
(``../shared/data/friction_frame/frame_disc250g.csv``, force reconstructed from the frame).

For each record: what diagnose names, the two channels' noise, and per candidate not named
the smallest size the record would have revealed (95 % power at the calibrated false-alarm
rate), in the effect's own unit, or why no bound is stated.

    nice .venv/bin/python benches/eval_power_examples.py --out benches/results/power_examples.md
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


def records() -> list[tuple[str, str, object]]:
    import contactlab
    from contactlab.synthetic.diagnosis import hidden_effect_recording
    from contactlab.synthetic.rig import rig_recording

    out = []
    rig = rig_recording(
        {}, "tangential", seed=7, fs=5000.0, f=10.0, cycles=20, acA=2.0, x_noise=0.01,
        F_noise=0.01,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        path = rig.to_csv(Path(tmp) / "rig.csv")
        out.append(
            ("rig, clean (seed 7: 5 kHz, 10 Hz, 20 cycles, ac·A 2, x and F noise 1 %)", "",
             contactlab.read_recording(str(path)))
        )  # fmt: skip
    pkg = hidden_effect_recording([], seed=3, input_noise=0.01, start="rest")
    out.append(("package generator, clean (seed 3, F noise 1 %, x noise 1 %)", "", pkg))
    frame = DATA / "friction_frame" / "frame_disc250g.csv"
    if frame.is_file():
        from contactlab.tangential import read_frame

        rec = read_frame(str(frame), 3.0799, 0.669, 1191.0).recording(str(frame))
        out.append(("measured: friction_frame/frame_disc250g.csv (frame reconstruction)", "",
                    rec))  # fmt: skip
    return out


def table(label: str, rep: object, seconds: float) -> list[str]:
    from contactlab.diagnose.power import _display

    cn = rep.channel_noise
    lines = [f"### {label}", ""]
    lines.append(
        f"named: {', '.join(rep.effect_names) or 'nothing'}; noise: input {cn.input:.3g} "
        f"{cn.input_unit}, output {cn.output:.3g} {cn.output_unit}; {seconds:.1f} s CPU"
    )
    lines.append("")
    lines.append(
        "| candidate | size (distance from absent) | would be seen above | % of output RMS | note |"
    )
    lines.append("|---|---|---|---|---|")
    for b in rep.not_detected:
        if b.detectable_above is None:
            lines.append(f"| {b.effect} | {b.parameter} | – | – | {b.reason[:90]} |")
            continue
        v, u = _display(b.detectable_above, b.unit)
        dev = f"{b.parameter} − {b.null:g}" if b.null else b.parameter
        lines.append(f"| {b.effect} | {dev} | {v:.3g} {u} | {100 * (b.relative_size or 0):.2g} | |")
    lines.append("")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    import contactlab

    warnings.simplefilter("ignore")
    lines = [
        "# Stated power on three example records (`benches/eval_power_examples.py`, "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})",
        "",
    ]
    for label, _, rec in records():
        t0 = time.process_time()
        rep = contactlab.diagnose(rec, model="tangential")
        lines += table(label, rep, time.process_time() - t0)
    text = "\n".join(lines)
    print(text)
    if a.out:
        a.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
