#!/usr/bin/env bash
# The wheel stays installable (issue 12): build the release abi3 wheel, install it into a
# fresh virtual environment from binaries only (no source builds, dependencies as wheels from
# the index), and run a smoke test outside the source tree. Fails CI when the wheel is broken.
# Reuses target/ from `make test`; prints the wheel's size and the install time.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
.venv/bin/maturin build --release --locked -q --out "$OUT/dist"
wheel=$(ls "$OUT"/dist/contactlab-*.whl)
case $wheel in *-abi3-*) ;; *) echo "wheel is not abi3: $wheel" >&2; exit 1 ;; esac
python3 -m venv "$OUT/venv"
start=$(date +%s%N)
"$OUT/venv/bin/python" -m pip install -q --only-binary :all: "$wheel"
ms=$((($(date +%s%N) - start) / 1000000))
size=$(du -k "$wheel" | cut -f1)
echo "wheel: $(basename "$wheel"), ${size} KiB; fresh-venv install (deps included) ${ms} ms"
cd "$OUT"  # away from the source tree: only the installed wheel can be imported
"$OUT/venv/bin/python" - <<'PY'
import numpy as np
import contactlab
from contactlab import Masing

assert "site-packages" in contactlab.__file__, contactlab.__file__
x = 20e-6 * np.sin(np.linspace(0, 4 * np.pi, 4001))
F = Masing(h0=40.0, ac=4e4).force(x)
assert np.isfinite(F).all() and abs(F.max() - Masing(40.0, 4e4).virgin(20e-6)) < 1e-9
print("wheel smoke: import and Masing.force ok")
PY
sample=$("$OUT/venv/bin/python" -c "from contactlab.data import data_dir; print(sorted(data_dir().glob('tangential/*.csv'))[0])")
"$OUT/venv/bin/contactlab" analyze "$sample" --model tangential --json "$OUT/fit.json" --no-progress
"$OUT/venv/bin/python" -c "import json, sys; d = json.load(open(sys.argv[1])); assert d['h0'] > 0, d" "$OUT/fit.json"
echo "wheel smoke: contactlab analyze on a bundled file ok"
