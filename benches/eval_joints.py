"""Evaluation of the joint-law fits on the measured data in ../shared/data (issue 30).

    python benches/eval_joints.py [--part friction|beam|tribo|speed|all] [--max-samples N]

Prints the tables of the issue's "Done when":

- **friction damper** (13 harmonic tests): every law (with a force offset and a
  direction-dependent gain, the same terms for all) fitted by leave-one-test-out
  cross-validation over the harmonic tests only; the law with the best pooled held-out SNR is
  chosen (nothing else is looked at), and its per-test and pooled held-out SNR / NRMSE are
  printed beside the LuGre baseline's predictions from the data folder. Earthquake histories
  are scored when the folder has them (the copy here holds only the harmonic tests).
- **Brake-Reuss beam**: the phase-resonance table (equivalent damping F ω / (ω² X) and
  frequency against amplitude) against the fitted law's (an amplitude-table fit and a
  stepped-sine fit of all sweeps; and a held-out check: fitted on the response-controlled
  sweeps, predicting the force-controlled ones), and the backbone.
- **micro-tribometer**: laws fitted on the first 25 cycles under load (the virgin loading
  excluded), predicting the last 25 cycles (NRMSE, energy per cycle) and the virgin curve.
- **speed**: a fit on 1e5 samples, against one evaluation of the same law (same run).

The data are read in place, never copied; missing folders are skipped with a note.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from contactlab.errors import ContactLabError
from contactlab.joints import JointRecord, Sweep, compare, fit, fit_amplitude, fit_stepped_sine

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: the laws of the friction-damper cross-validation (all with offset + asymmetry terms)
FRICTION_LAWS = [
    "jenkins",
    "iwan",
    "dahl",
    "lugre",
    "backlash:jenkins",
    "segalman",
    "masing",
    "bouc_wen",
    "maxwell_slip",
    "backlash:dahl",
    "backlash:lugre",
    "gms",
    "backlash:jenkins+cm",
    "dahl+cm",
]


#: the laws fitted to the micro-tribometer (its source fits LuGre)
TRIBO_LAWS = ["dahl", "lugre", "masing", "segalman", "jenkins", "bouc_wen", "maxwell_slip"]


def _fd_records(folder: Path) -> list[JointRecord]:
    recs = []
    for i in range(13):
        x = np.load(folder / f"harmonic_test{i}_x.npy").reshape(-1)
        F = np.load(folder / f"harmonic_test{i}_F.npy").reshape(-1)
        recs.append(JointRecord(np.arange(x.size) / 1024.0, x, F, f"test{i}"))
    return recs


def _row(name: str, r: dict) -> str:
    def num(k: str, fmt: str) -> str:
        v = r.get(k)
        return "-" if v is None else format(v, fmt)

    return (f"{name:<18} {num('snr_db', '7.2f')} {num('nrmse', '8.4f')} {num('rrse', '8.4f')} "
            f"{num('trac', '8.4f')} {num('energy_error', '+9.4f')}")  # fmt: skip


_RECS: list[JointRecord] = []


def _fold(law: str, k: int, max_samples: int) -> tuple[str, Any, str, float]:
    """One fold of the cross-validation (in a worker process): fit on every harmonic test
    but test k, predict test k. Returns (name, prediction or None, message, CPU s)."""
    if not _RECS:
        _RECS.extend(_fd_records(DATA / "friction_damper"))
    t0 = time.process_time()
    held = _RECS[k]
    train = [r for j, r in enumerate(_RECS) if j != k]
    name, _, extra = law.partition("+")  # "dahl+cm": with a parallel damping and inertia
    try:
        f = fit(train, law=name, offset=True, asymmetry=True, damping="c" in extra,
                mass="m" in extra, max_samples=max_samples)  # fmt: skip
        pred = f.force(held.t, held.x)
        msg = "" if f.success else f.message
    except ContactLabError as exc:
        pred, msg = None, str(exc)
    return held.name, pred, msg, time.process_time() - t0


def friction(max_samples: int, jobs: int = 1, laws: list[str] | None = None) -> None:
    folder = DATA / "friction_damper"
    if not folder.is_dir():
        print("friction damper: ../shared/data/friction_damper absent, skipped")
        return
    recs = _fd_records(folder)
    lugre = {
        f"test{i}": np.load(folder / f"lugre_baseline_harmonic_test{i}_F.npy").reshape(-1)
        for i in range(13)
    }
    print("=== friction damper: leave-one-test-out cross-validation over the 13 harmonic tests")
    print(f"    (each fold fitted on 12 tests, laws driven with ~{max_samples} samples; "
          "scores on every sample of the held-out test)")  # fmt: skip
    failed: dict[str, list[str]] = {}
    laws = laws or FRICTION_LAWS
    cv_pred: dict[str, dict[str, np.ndarray]] = {law: {} for law in laws}
    cv_time: dict[str, float] = dict.fromkeys(laws, 0.0)
    tasks = [(law, k) for law in laws for k in range(len(recs))]
    done = dict.fromkeys(laws, 0)
    with ProcessPoolExecutor(jobs) as ex:
        futs = {ex.submit(_fold, law, k, max_samples): (law, k) for law, k in tasks}
        for fut in as_completed(futs):
            law, _ = futs[fut]
            name, pred, msg, cpu = fut.result()
            cv_time[law] += cpu
            done[law] += 1
            if pred is not None:
                cv_pred[law][name] = pred
            if msg:
                failed.setdefault(law, []).append(f"{name}: {msg}")
            if done[law] == len(recs):
                if len(cv_pred[law]) == len(recs):
                    row = compare({law: cv_pred[law]}, recs).pooled(law)
                    print(_row(law, row) + f"   ({cv_time[law]:.0f} CPU s)", flush=True)
                else:
                    print(f"{law:<18} failed on {len(recs) - len(cv_pred[law])} folds",
                          flush=True)  # fmt: skip
    base = compare({"LuGre (authors)": lugre}, recs)
    print(_row("LuGre (authors)", base.pooled("LuGre (authors)")) + "   (published baseline)")
    complete = {k: v for k, v in cv_pred.items() if len(v) == len(recs)}
    table = compare(complete, recs)
    best = table.best("snr_db")
    print(f"\nchosen by pooled held-out SNR: {best}")
    for law, msgs in failed.items():
        print(f"  {law}: {len(msgs)} fold(s) not converged or failed, first: {msgs[0]}")
    both = compare({best: complete[best], "LuGre": lugre}, recs)
    print(f"\n{'test':<8} {'SNR ' + best:>24} {'SNR LuGre':>10} {'NRMSE ' + best:>24} "
          f"{'NRMSE LuGre':>12}")  # fmt: skip
    for r in recs:
        a, b = both.row(best, r.name), both.row("LuGre", r.name)
        print(f"{r.name:<8} {a['snr_db']:24.2f} {b['snr_db']:10.2f} {a['nrmse']:24.4f} "
              f"{b['nrmse']:12.4f}")  # fmt: skip
    a, b = both.pooled(best), both.pooled("LuGre")
    print(f"{'pooled':<8} {a['snr_db']:24.2f} {b['snr_db']:10.2f} {a['nrmse']:24.4f} "
          f"{b['nrmse']:12.4f}")  # fmt: skip
    print(f"held-out gain over LuGre: {a['snr_db'] - b['snr_db']:+.2f} dB")
    _per_test_all(complete, lugre, recs)
    name, _, extra = best.partition("+")
    final = fit(recs, law=name, offset=True, asymmetry=True, damping="c" in extra,
                mass="m" in extra, max_samples=max_samples)  # fmt: skip
    print(f"\n{best} fitted on all 13 harmonic tests (the model for other records):")
    print(final.report())
    quakes = sorted(folder.glob("*earthquake*"))
    if not quakes:
        print("earthquake histories: none in ../shared/data/friction_damper (only the harmonic "
              "tests are here); not scored")  # fmt: skip


def _per_test_all(complete: dict, lugre: dict, recs: list[JointRecord]) -> None:
    """Held-out SNR [dB] and NRMSE of every law on every test, LuGre's beside them."""
    models = {**complete, "LuGre": lugre}
    table = compare(models, recs)
    names = list(models)
    for metric, fmt in (("snr_db", "7.2f"), ("nrmse", "7.4f")):
        print(f"\nheld-out {metric} of every law (rows: tests; columns: laws)")
        print(f"{'test':<8} " + " ".join(f"{n[:12]:>12}" for n in names))
        for r in [*recs, None]:
            rows = [table.pooled(n) if r is None else table.row(n, r.name) for n in names]
            label = "pooled" if r is None else r.name
            print(f"{label:<8} " + " ".join(f"{format(x[metric], fmt):>12}" for x in rows))


def _brb_sweeps(path: Path) -> tuple[list[Sweep], list[Sweep]]:
    import scipy.io as sio

    d = sio.loadmat(path, squeeze_me=True, struct_as_record=False)["FRdata"]
    out: dict[str, list[Sweep]] = {}
    for key in ("ForceControl", "ResponseControl"):
        out[key] = [
            Sweep.from_acceleration(
                s.frequency, s.force, s.amplitude, s.phase, name=f"{key}{j + 1}"
            )
            for j, s in enumerate(getattr(d, key))
        ]
    return out["ForceControl"], out["ResponseControl"]


def _table(sweeps: list[Sweep]) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    pts = [(s.name, s.phase_resonance()) for s in sweeps]
    pts = [(n, p) for n, p in pts if p is not None]
    A = np.array([p["displacement"] for _, p in pts])
    c = np.array([p["c_eq"] for _, p in pts])
    f = np.array([p["frequency"] for _, p in pts])
    return A, c, f, [n for n, _ in pts]


def beam() -> None:
    path = DATA / "brake_reuss_beam" / "ForcedFrequencyResponses.mat"
    if not path.is_file():
        print("beam: ../shared/data/brake_reuss_beam absent, skipped")
        return
    fc, rc = _brb_sweeps(path)
    A, c, f, names = _table(fc + rc)
    order = np.argsort(A)
    print("\n=== Brake-Reuss beam: phase-resonance table (12 sweeps)")
    free = {"chi": (-0.99, 1.0)}  # Segalman's χ beyond its physical range (-1, 0]
    for law, bounds in (("segalman", None), ("segalman", free), ("iwan", None)):
        t0 = time.perf_counter()
        fa = fit_amplitude(A, damping=c, frequency=f, law=law, viscous=True, bounds=bounds)
        law = law + (" (chi free)" if bounds else "")
        out = [n for n in fa.result.notes if "outside the physical range" in n]
        print(f"amplitude-table fit, {law} + viscous c0: damping RMS error "
              f"{100 * fa.rms_relative_error('c_eq'):.2f} % ({time.perf_counter() - t0:.2f} s, "
              f"{'converged' if fa.success else 'NOT converged'}); {fa.law!r}, "
              f"c0 = {fa.result.params['c0'].value:.3f} ± {fa.result.params['c0'].stderr:.2g} "
              "N s/m" + "".join(f"; {n}" for n in out))  # fmt: skip
    for law, bounds in (("segalman", None), ("segalman", free), ("iwan", None)):
        t0 = time.perf_counter()
        ss = fit_stepped_sine(fc + rc, law=law, bounds=bounds)
        if bounds:
            law = law + " (chi free)"
        bb = ss.backbone(A)
        rel = bb["c_eq"] / c - 1.0
        print(f"stepped-sine fit of all 984 points, {law}: damping at phase resonance RMS "
              f"error {100 * math.sqrt(float(np.mean(rel**2))):.2f} %, worst "
              f"{100 * float(np.max(np.abs(rel))):.1f} %; frequency RMS error "
              f"{math.sqrt(float(np.mean((bb['f_n'] - f) ** 2))):.3f} Hz "
              f"({time.perf_counter() - t0:.2f} s, "
              f"{'converged' if ss.success else 'NOT converged'}); {ss.law!r}"
              + "".join(f"; {n}" for n in ss.result.notes if "physical range" in n))  # fmt: skip
        if law == "segalman":
            best, best_bb = ss, bb
    print(best_bb and f"segalman stepped-sine fit: {best.law!r}, modal "
          f"m = {best.modal['m']:.4g} kg, k = {best.modal['k']:.4g} N/m, "
          f"c0 = {best.modal['c0']:.4g} N s/m")  # fmt: skip
    for n, p in best.result.params.items():
        if n.startswith("dk_"):
            continue
        err = "fixed" if not p.vary else (f"± {p.stderr:.3g}" if p.stderr is not None
                                          else p.note)  # fmt: skip
        print(f"    {n} = {p.value:.6g} {p.unit} {err}")
    print(f"\n{'sweep':<18} {'A [um]':>8} {'f meas':>8} {'f_n pred':>9} {'c meas':>8} "
          f"{'c pred':>8} {'err %':>7} {'zeta pred':>10}")  # fmt: skip
    for i in order:
        print(f"{names[i]:<18} {A[i] * 1e6:8.1f} {f[i]:8.3f} {best_bb['f_n'][i]:9.3f} "
              f"{c[i]:8.3f} {best_bb['c_eq'][i]:8.3f} {100 * (best_bb['c_eq'][i] / c[i] - 1):7.2f}"
              f" {best_bb['zeta'][i]:10.5f}")  # fmt: skip
    # held out: fitted on the response-controlled sweeps, predicting the force-controlled ones
    Af, cf, _, nf = _table(fc)
    ho = fit_stepped_sine(rc, law="segalman")
    hb = ho.backbone(Af)
    rel = hb["c_eq"] / cf - 1.0
    print(
        f"\nheld out: segalman fitted on the 8 response-controlled sweeps predicts the 4 "
        f"force-controlled sweeps' phase-resonance damping at RMS error "
        f"{100 * math.sqrt(float(np.mean(rel**2))):.2f} % (per sweep: "
        + ", ".join(f"{n} {100 * r:+.1f} %" for n, r in zip(nf, rel, strict=True))
        + ")"
    )
    grid = np.geomspace(10e-6, 400e-6, 9)
    bb = best.backbone(grid)
    print("\npredicted backbone (segalman stepped-sine fit, ±1 standard error):")
    print(f"{'A [um]':>8} {'f_n [Hz]':>18} {'zeta':>20}")
    for i, a in enumerate(grid):
        print(f"{a * 1e6:8.1f} {bb['f_n'][i]:10.4f} ± {bb['f_n_stderr'][i]:.4f} "
              f"{bb['zeta'][i]:10.6f} ± {bb['zeta_stderr'][i]:.6f}")  # fmt: skip


def _tribo_record(path: Path) -> tuple[JointRecord, np.ndarray]:
    d = np.loadtxt(path, skiprows=1)
    t, N, P, F = d.T
    on = N > 0.5 * N.max()
    i0 = int(np.argmax(on))
    i1 = len(on) - int(np.argmax(on[::-1]))
    t, x, Fn = t[i0:i1], P[i0:i1] * 1e-3, -F[i0:i1] * 1e-6  # s, m, N (the source negates F)
    keep = np.concatenate([[True], np.diff(t) > 0])
    return JointRecord(t[keep] - t[keep][0], x[keep], Fn[keep], "microtribometer"), np.array(0)


def tribo() -> None:
    from contactlab.reversals import excursions

    path = DATA / "microtribometer" / "test_data_2.txt"
    if not path.is_file():
        print("tribometer: ../shared/data/microtribometer absent, skipped")
        return
    rec, _ = _tribo_record(path)
    x = rec.x
    lo, hi = float(x.min()), float(x.max())
    ex = excursions(x, 0.5 * (lo + hi), 0.25 * (hi - lo))
    peaks = np.asarray(ex.extreme[ex.sign > 0], dtype=np.int64)
    print(f"\n=== micro-tribometer: {rec.n} samples under load, {peaks.size} stroke maxima")
    # the stage rests at its lower end when the load comes on, then strokes up: the virgin
    # loading ends at the first maximum; cycles run from maximum to maximum
    first_rev = int(peaks[0])
    mid = int(peaks[min(25, peaks.size - 1)])  # the end of cycle 25
    train = np.zeros(rec.n, bool)
    train[first_rev:mid] = True
    test = np.zeros(rec.n, bool)
    test[mid:] = True
    virgin = np.zeros(rec.n, bool)
    virgin[:first_rev] = True
    fit_rec = JointRecord(rec.t, rec.x, rec.F, "cycles 1-25", train)
    print(f"fit window: samples {first_rev}-{mid} (the 25 cycles after the virgin loading); "
          f"test: the {rec.n - mid} samples after; virgin curve: the first {first_rev} "
          "samples")  # fmt: skip
    print(f"{'law':<14} {'NRMSE last25':>12} {'SNR last25':>10} {'E/cycle err':>11} "
          f"{'NRMSE virgin':>12} {'fit s':>6}")  # fmt: skip
    for law in TRIBO_LAWS:
        t0 = time.perf_counter()
        try:
            # every sample where the law has forward sensitivities (a fast fit, and the rate
            # terms see the recorded steps, as in the prediction); every 5th otherwise
            full = law in ("dahl", "lugre", "jenkins", "maxwell_slip")
            f = fit([fit_rec], law=law, offset=True, max_samples=None if full else 8000)
        except ContactLabError as exc:
            print(f"{law:<14} failed: {exc}")
            continue
        P = f.force(rec.t, rec.x, x0=float(rec.x[0]))
        tl = compare({law: [P]}, [JointRecord(rec.t, rec.x, rec.F, "last25", test)]).pooled(law)
        vg = compare({law: [P]}, [JointRecord(rec.t, rec.x, rec.F, "virgin", virgin)])
        vrow = vg.pooled(law)
        print(f"{law:<14} {tl['nrmse']:12.4f} {tl['snr_db']:10.2f} "
              f"{tl['energy_error'] if tl['energy_error'] is not None else float('nan'):+11.4f} "
              f"{vrow['nrmse']:12.4f} {time.perf_counter() - t0:6.1f}"
              + ("" if f.success else "  (fit NOT converged)"))  # fmt: skip


def speed() -> None:
    from contactlab.joints import LuGre

    n = 100_000
    t = np.arange(n) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * 1.0 * t) * (1 + 0.3 * np.sin(0.2 * t))
    law = LuGre(sigma0=2e5, sigma1=30.0, sigma2=5.0, Fc=10.0, Fs=12.0, vs=2e-3)
    F = law.force(t, x) + np.random.default_rng(1).normal(0, 0.05, n)
    t0 = time.process_time()
    for _ in range(5):
        law.force(t, x)
    one = (time.process_time() - t0) / 5
    for ms in (None, 20000):
        t0 = time.process_time()
        f = fit(t, x, F, law="lugre", max_samples=ms)
        dt = time.process_time() - t0
        print(
            f"\nspeed: LuGre fit on 1e5 samples (max_samples={ms}): {dt:.2f} CPU s = "
            f"{dt / one:.0f} evaluations of the law on all samples ({one * 1e3:.1f} ms each); "
            f"{f.result.nfev} evaluations, {'converged' if f.success else 'NOT converged'}"
        )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--part", default="all", choices=("friction", "beam", "tribo", "speed", "all"))
    ap.add_argument("--max-samples", type=int, default=20000)
    ap.add_argument("--jobs", type=int, default=2, help="processes of the cross-validation")
    ap.add_argument("--laws", help="comma-separated laws of the cross-validation (default: all; "
                    "'<law>+cm' adds a parallel damping and inertia)")  # fmt: skip
    a = ap.parse_args(argv)
    if a.part in ("beam", "all"):
        beam()
    if a.part in ("tribo", "all"):
        tribo()
    if a.part in ("friction", "all"):
        friction(a.max_samples, a.jobs, a.laws.split(",") if a.laws else None)
    if a.part in ("speed", "all"):
        speed()
    return 0


if __name__ == "__main__":
    sys.exit(main())
