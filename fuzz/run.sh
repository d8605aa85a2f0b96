#!/usr/bin/env bash
# Coverage-guided fuzzing of every way data gets into contactlab.
#
#   fuzz/run.sh TARGET SECONDS     one target for SECONDS (nice 19)
#   fuzz/run.sh all SECONDS        every target, one after the other, SECONDS each
#   fuzz/run.sh list               the targets
#
# Python targets (fuzz/<target>.py) run under atheris (libFuzzer); the Rust core target
# (`core`) runs under AFL++ through cargo-afl (fuzz/afl/). Corpora grow in fuzz/corpus/<target>/,
# crashing inputs land in fuzz/crashes/<target>/ (both ignored by git). Once a defect is fixed,
# copy its input to fuzz/regressions/<target>/: tests/test_fuzz_regressions.py replays those.
# The summary line "TARGET: N execs, M crashes" goes to fuzz/logs/<target>.log.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
PY=${PY:-$ROOT/.venv/bin/python}
PY_TARGETS="read_csv read_tdms read_hdf5 read_mat manifest kernels analyze diagnose track export identify simulate"
ALL="$PY_TARGETS core"

usage() { echo "usage: fuzz/run.sh TARGET|all|list SECONDS  (targets: $ALL)" >&2; exit 2; }
[[ $# -ge 1 ]] || usage
if [[ $1 == list ]]; then echo "$ALL"; exit 0; fi
[[ $# -eq 2 && $2 =~ ^[0-9]+$ ]] || usage
SECS=$2

ensure_atheris() {
  "$PY" -c "import atheris" 2>/dev/null || "$PY" -m pip install -q --only-binary :all: "atheris>=2.3"
}

run_py() {
  local t=$1
  ensure_atheris
  [[ -d fuzz/seeds/$t ]] || "$PY" fuzz/seeds.py
  mkdir -p "fuzz/corpus/$t" "fuzz/crashes/$t" fuzz/logs
  local log=fuzz/logs/$t.log
  : >"$log"
  # The harness saves each distinct defect and goes on (see _harness.main); should the process
  # die all the same (an abort, an out-of-memory kill), it is restarted until the time is up.
  local end=$((SECONDS + SECS)) left
  while (( (left = end - SECONDS) > 5 )); do
    (cd fuzz && CONTACTLAB_FUZZING=1 CONTACTLAB_FUZZ_CRASHES="crashes/$t" MPLBACKEND=Agg \
        nice -n 19 "$PY" "$t.py" -max_total_time="$left" -print_final_stats=1 -timeout=120 \
        -rss_limit_mb=4096 -artifact_prefix="crashes/$t/" "corpus/$t" "seeds/$t") >>"$log" 2>&1 \
        || true
  done
  local execs defects
  execs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' \
          | awk '{s+=$1} END {print s+0}')
  defects=$(grep -c '^## ' "fuzz/crashes/$t/SIGNATURES.txt" 2>/dev/null || true)
  echo "$t: $execs execs, ${defects:-0} distinct defects (fuzz/crashes/$t/SIGNATURES.txt), $SECS s" \
    | tee -a "$log"
}

run_core() {
  bash fuzz/afl/run.sh "$SECS"
}

one() {
  case " $ALL " in *" $1 "*) ;; *) usage ;; esac
  if [[ $1 == core ]]; then run_core; else run_py "$1"; fi
}

if [[ $1 == all ]]; then
  for t in $ALL; do one "$t"; done
else
  one "$1"
fi
