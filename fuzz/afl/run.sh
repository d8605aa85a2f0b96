#!/usr/bin/env bash
# AFL++ on the Rust core for SECONDS (called by fuzz/run.sh core SECONDS).
# Needs cargo-afl (`cargo install cargo-afl`, which builds AFL++); corpus in fuzz/afl/out/.
set -euo pipefail
cd "$(dirname "$0")"
SECS=${1:?seconds}
command -v cargo-afl >/dev/null || cargo install --locked cargo-afl
nice -n 19 cargo afl build --release --locked -q
mkdir -p in ../logs
[[ -n $(ls -A in) ]] || head -c 256 /dev/urandom >in/random   # any start will do: AFL++ mutates
export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 AFL_NO_AFFINITY=1
resume=-i; [[ -d out/default/queue ]] && resume="-i -"  # go on from an earlier run's queue
# shellcheck disable=SC2086
nice -n 19 cargo afl fuzz -V "$SECS" $resume $([[ $resume == -i ]] && echo in) -o out \
  target/release/contactlab-core-afl >../logs/core.log 2>&1 || true
execs=$(awk -F: '/^execs_done/ {gsub(/ /, "", $2); print $2}' out/default/fuzzer_stats)
crashes=$(awk -F: '/^saved_crashes/ {gsub(/ /, "", $2); print $2}' out/default/fuzzer_stats)
echo "core: $execs execs, $crashes crashing inputs (fuzz/afl/out/default/crashes), $SECS s" \
  | tee -a ../logs/core.log
