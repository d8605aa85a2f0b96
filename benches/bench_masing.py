"""``Masing.force(x, out=buf)`` against the anchor kernel, compiled and run in this run.

The anchor is ``../shared/bench/masing_anchor.rs`` (its ``masing_idx`` kernel: the plain
std-Rust loop of the same rules with libm ``exp``), included verbatim into a small driver and
built here the way a wheel is built, for generic x86-64 (``rustc -O``). The driver stays up
for the whole run and times one call per request, so that the rounds interleave: per round
and signal, contactlab then the anchor, the order swapped every round, and every round visits
every signal (a burst of load hits all three rows alike). Each call is timed by
wall clock and by the CPU time of the thread that ran it (``time.thread_time`` here,
``clock_gettime(CLOCK_THREAD_CPUTIME_ID)`` in the driver): on a shared, loaded machine the wall time
holds the time spent waiting for a core and the CPU time does not. Figures are medians over
``--rounds``; the ratios are contactlab's throughput over the anchor's. Beside the ratio of the
medians, the median of the per-round CPU ratios (each round's two calls run back to back, so
they share the load of the moment: steadier when the load changes during the run).

The signals are the anchor's own (``sine``, ``bandlim``, ``randwalk``, h0 = 1, ac = 3), written
by the driver with the anchor's generators; the checksums (sequential sums of the forces) of both
kernels are compared.
Each round's two calls run on one CPU, the CPU taking turns (see ``measure``); besides the
medians the spread of the per-round ratios is printed.
Run: ``.venv/bin/python benches/bench_masing.py [--n 10000000] [--rounds 12] [--signals bandlim]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import contactlab

ROOT = Path(__file__).resolve().parents[1]
ANCHOR = ROOT.parent / "shared" / "bench" / "masing_anchor.rs"
SIGNALS = ("sine", "bandlim", "randwalk")

# The driver: the anchor file verbatim in a module (so its private kernel is reachable from
# a function added to the module), one timed `masing_idx` call per stdin line.
DRIVER = r"""
mod anchor {
    include!(env!("ANCHOR_RS"));
    pub fn signal(kind: &str, n: usize) -> Vec<f64> { gen(kind, n) }
    pub const IDX: Kern = masing_idx;
    #[allow(dead_code)]
    pub fn unused() { main() }
}
use std::io::{BufRead, Write};
// The thread's CPU clock (CLOCK_THREAD_CPUTIME_ID), read exactly: /proc/thread-self/schedstat
// is brought up to date only at scheduler ticks (4 ms at HZ=250) and read up to 4 ms short.
#[repr(C)]
struct Timespec { sec: i64, nsec: i64 }
extern "C" { fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32; }
fn cpu_ns() -> u64 {
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: a valid pointer to a timespec; clock 3 is CLOCK_THREAD_CPUTIME_ID on Linux.
    if unsafe { clock_gettime(3, &mut ts) } != 0 { return 0; }
    ts.sec as u64 * 1_000_000_000 + ts.nsec as u64
}
fn main() {
    // every signal asked for so far, with its output buffer (the rounds visit them in turn)
    let mut cache: std::collections::HashMap<(String, usize), (Vec<f64>, Vec<f64>)> =
        std::collections::HashMap::new();
    let (mut xr, mut hr) = (Vec::new(), Vec::new());
    let stdout = std::io::stdout();
    for line in std::io::stdin().lock().lines() {
        let line = line.unwrap();
        let mut it = line.split_whitespace();
        let kind = it.next().unwrap().to_string();
        let n: usize = it.next().unwrap().parse().unwrap();
        if let Some(path) = it.next() {
            // "<signal> <n> <path>": write the signal (little-endian f64) to path
            let x = anchor::signal(&kind, n);
            let bytes: Vec<u8> = x.iter().flat_map(|v| v.to_le_bytes()).collect();
            std::fs::write(path, bytes).unwrap();
            writeln!(stdout.lock(), "ok").unwrap();
            continue;
        }
        let c = cache.entry((kind.clone(), n)).or_insert_with(|| {
            let x = anchor::signal(&kind, n);
            let mut out = vec![0.0; n];
            (anchor::IDX)(&x, &mut out, &mut xr, &mut hr); // warm-up: page faults
            (x, out)
        });
        let k = std::hint::black_box(anchor::IDX);
        let (c0, t0) = (cpu_ns(), std::time::Instant::now());
        k(std::hint::black_box(&c.0), &mut c.1, &mut xr, &mut hr);
        std::hint::black_box(&c.1);
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), (cpu_ns() - c0) as f64 * 1e-9);
        let chk: f64 = c.1.iter().sum();
        let mut o = stdout.lock();
        writeln!(o, "{wall:.9} {cpu:.9} {chk:.17e}").unwrap();
        o.flush().unwrap();
    }
}
"""


class Anchor:
    """The anchor driver, built for generic x86-64 and kept running."""

    def __init__(self, workdir: Path) -> None:
        src = workdir / "anchor_driver.rs"
        src.write_text(DRIVER)
        self.exe = workdir / "anchor_driver"
        env = dict(os.environ, ANCHOR_RS=str(ANCHOR.resolve()))
        env.pop("RUSTFLAGS", None)
        subprocess.run(
            ["rustc", "-O", "--edition", "2021", "-o", str(self.exe), str(src)],
            check=True,
            env=env,
            capture_output=True,
        )
        self.proc = subprocess.Popen(
            [str(self.exe)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )

    def time(self, kind: str, n: int) -> tuple[float, float, float]:
        """Wall seconds, CPU seconds and checksum of one call on signal ``kind``."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(f"{kind} {n}\n")
        self.proc.stdin.flush()
        wall, cpu, chk = self.proc.stdout.readline().split()
        return float(wall), float(cpu), float(chk)

    def signal(self, kind: str, n: int, workdir: Path) -> np.ndarray:
        """The anchor's own signal ``kind`` of ``n`` samples (generated by the driver)."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        path = workdir / f"{kind}.f64"
        self.proc.stdin.write(f"{kind} {n} {path}\n")
        self.proc.stdin.flush()
        if self.proc.stdout.readline().strip() != "ok":
            raise RuntimeError("the anchor driver did not write the signal")
        x = np.fromfile(path, dtype="<f8")
        path.unlink()
        return x

    def close(self) -> None:
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        self.proc.wait()


def ours_time(m: contactlab.Masing, x: np.ndarray, buf: np.ndarray) -> tuple[float, float]:
    """Wall and thread-CPU seconds of one ``m.force(x, out=buf)``."""
    c0, t0 = time.thread_time(), time.perf_counter()
    m.force(x, out=buf)
    return time.perf_counter() - t0, time.thread_time() - c0


def _cpus() -> list[int]:
    """The CPUs this process may run on (empty where affinity cannot be set)."""
    if not hasattr(os, "sched_getaffinity"):
        return []
    return sorted(os.sched_getaffinity(0))


def _pin(cpu: int | None, pids: tuple[int, ...], allowed: list[int]) -> None:
    """Pin this thread and the processes ``pids`` to ``cpu`` (all of ``allowed`` for None)."""
    if not allowed:
        return
    mask = set(allowed) if cpu is None else {cpu}
    for pid in (0, *pids):
        try:
            os.sched_setaffinity(pid, mask)
        except OSError:  # the driver has exited or the CPU went away: leave it as it is
            pass


def _spread(v: np.ndarray) -> tuple[float, float, float, float]:
    """Minimum, lower quartile, upper quartile and maximum of ``v``."""
    q1, q3 = np.quantile(v, [0.25, 0.75])
    return float(v.min()), float(q1), float(q3), float(v.max())


def measure(
    n: int, rounds: int, signals: tuple[str, ...] = SIGNALS, pin: bool = True
) -> list[dict[str, float | str]] | None:
    """Per signal: medians of wall/CPU seconds of both kernels over interleaved rounds.

    Each round visits every signal (the first one rotating) and runs contactlab and the
    anchor back to back on it (the order swapped every round), with both pinned to the same
    CPU, the CPU taking turns every two rounds (one of each order): a round's two calls
    then share one core's state and the load of the moment, and neither side keeps the
    faster or the busier core for the whole run (on this shared VM the two CPUs' speeds
    differ by up to a third from minute to minute). Besides the medians: ``cpu_ratio_paired``,
    the median over the rounds of the anchor's CPU time over contactlab's in the same round;
    ``cpu_ratio_spread``, the minimum, quartiles and maximum of those per-round ratios; and
    ``cpu_ratio_min``, the ratio of the two sides' fastest calls (the least disturbed).
    ``pin=False`` leaves the placement to the scheduler (for comparison). None when the
    anchor or ``rustc`` is absent.
    """
    if not ANCHOR.exists() or shutil.which("rustc") is None:
        return None
    m = contactlab.Masing(h0=1.0, ac=3.0)
    allowed = _cpus() if pin else []
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        anchor = Anchor(Path(tmp))
        try:
            xs, bufs = {}, {}
            for kind in signals:
                xs[kind] = anchor.signal(kind, n, Path(tmp))
                bufs[kind] = np.empty(n)
                m.force(xs[kind], out=bufs[kind])  # warm-up: page faults
                anchor.time(kind, n)
            t: dict[str, dict[str, list[float]]] = {
                kind: {"ow": [], "oc": [], "aw": [], "ac": []} for kind in signals
            }
            chk = dict.fromkeys(signals, np.nan)
            for r in range(rounds):
                cpu = allowed[(r // 2) % len(allowed)] if allowed else None
                _pin(cpu, (anchor.proc.pid,), allowed)
                first_ours = r % 2 == 0
                # the signals in turn, the first one rotating from round to round
                for j in range(len(signals)):
                    kind = signals[(j + r) % len(signals)]
                    if first_ours:
                        w, c = ours_time(m, xs[kind], bufs[kind])
                    wa, ca, chk[kind] = anchor.time(kind, n)
                    if not first_ours:
                        w, c = ours_time(m, xs[kind], bufs[kind])
                    for key, v in (("ow", w), ("oc", c), ("aw", wa), ("ac", ca)):
                        t[kind][key].append(v)
            _pin(None, (anchor.proc.pid,), allowed)
            for kind in signals:
                ow, oc, aw, ac = (np.array(t[kind][k]) for k in ("ow", "oc", "aw", "ac"))
                ours_chk = float(np.cumsum(bufs[kind])[-1])  # the anchor's sequential sum
                paired = ac / oc
                rows.append(
                    {
                        "signal": kind,
                        "ours_wall": float(np.median(ow)),
                        "ours_cpu": float(np.median(oc)),
                        "anchor_wall": float(np.median(aw)),
                        "anchor_cpu": float(np.median(ac)),
                        "cpu_ratio_paired": float(np.median(paired)),
                        "cpu_ratio_spread": _spread(paired),
                        "cpu_ratio_min": float(ac.min() / oc.min()),
                        "checksum_rel_diff": abs(ours_chk - chk[kind]) / abs(chk[kind]),
                    }
                )
        finally:
            _pin(None, (), allowed)
            anchor.close()
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--rounds", type=int, default=12)
    ap.add_argument(
        "--signals",
        nargs="+",
        choices=SIGNALS,
        default=list(SIGNALS),
        help="the anchor's signals to run (default: all three)",
    )
    ap.add_argument(
        "--no-pin",
        action="store_true",
        help="leave both sides' CPU to the scheduler (default: each round on one CPU)",
    )
    args = ap.parse_args()
    n = args.n
    from contactlab import _core

    load = ", ".join(f"{a:.2f}" for a in os.getloadavg())
    print(
        f"n = {n:.0e} samples, medians of {args.rounds} interleaved rounds"
        f"{' (not pinned)' if args.no_pin else ', each round on one CPU'}; SIMD level "
        f"{_core.simd_level()}; load {load}; {os.cpu_count()} CPUs"
    )
    rows = measure(n, args.rounds, tuple(args.signals), pin=not args.no_pin)
    if rows is None:
        print("anchor absent (../shared/bench/masing_anchor.rs or rustc missing)")
        return
    print(
        f"{'signal':<10}{'ours M/s':>10}{'anchor M/s':>12}{'ratio':>7}"
        f"{'ours ns/sample CPU':>20}{'anchor ns/sample CPU':>22}{'CPU ratio':>11}"
        f"{'paired CPU ratio':>18}{'paired min/q1/q3/max':>24}{'ratio of minima':>17}"
        f"{'checksum rel diff':>19}"
    )
    for r in rows:
        ow, aw, oc, ac = r["ours_wall"], r["anchor_wall"], r["ours_cpu"], r["anchor_cpu"]
        spread = "/".join(f"{v:.2f}" for v in r["cpu_ratio_spread"])
        print(
            f"{r['signal']:<10}{n / ow / 1e6:10.1f}{n / aw / 1e6:12.1f}{aw / ow:7.2f}"
            f"{oc / n * 1e9:20.2f}{ac / n * 1e9:22.2f}{ac / oc:11.2f}"
            f"{r['cpu_ratio_paired']:18.2f}{spread:>24}{r['cpu_ratio_min']:17.2f}"
            f"{r['checksum_rel_diff']:19.1e}"
        )


if __name__ == "__main__":
    main()
