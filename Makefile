# The two entry points of the README: `make demo` and `make test`. Both set everything up.
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
STAMP  := $(VENV)/.deps-stamp
PYSRC  := python tests benches fuzz

.PHONY: demo test docs develop rust-test rust-lint py-lint pytest bench clean

$(STAMP): pyproject.toml
	python3 -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q "maturin>=1.9,<2" "numpy>=1.24" "scipy>=1.10" "matplotlib>=3.7" \
		"pytest>=8" "pytest-timeout>=2.2" "hypothesis>=6.100" "ruff>=0.6" "mypy>=1.10" "npTDMS>=1.9" "h5py>=3.9" "pyarrow>=14" "tqdm>=4.60" \
		"dask[distributed]>=2024.1" "threadpoolctl>=3.1" "import-linter>=2.1"
	touch $(STAMP)

# The documentation's tools, in a stamp of their own: `make test` does not need them.
DOCS_STAMP := $(VENV)/.docs-stamp
$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(PIP) install -q "sphinx>=7" "numpydoc>=1.6" "sphinx-gallery>=0.15" "myst-parser>=2"
	touch $(DOCS_STAMP)

# Build the Rust extension (release) and install the package into the venv.
# The package is byte-compiled as an installation is (the editable build leaves that to the
# first run, which PYTHONDONTWRITEBYTECODE forbids: every CLI run would compile it, 0.13 s).
develop: $(STAMP)
	VIRTUAL_ENV=$(abspath $(VENV)) $(VENV)/bin/maturin develop --release --locked -q
	$(VENV)/bin/python -m compileall -q python/contactlab > /dev/null

demo: develop
	$(VENV)/bin/contactlab demo --out demo-output

# The property tests run on a fixed proptest seed, so a rare draw cannot make the README's
# `make test` fail at random (set PROPTEST_SEED=random to explore new cases).
PROPTEST_SEED ?= 20261123
rust-test:
	PROPTEST_RNG_SEED=$(PROPTEST_SEED) cargo test --workspace --locked -q

rust-lint:
	cargo fmt --all --check
	cargo clippy --workspace --all-targets --locked -q -- -D warnings

# lint-imports: the layer, independence and no-cycle contracts of pyproject.toml (ARCHITECTURE.md)
py-lint: develop
	$(VENV)/bin/ruff check $(PYSRC)
	$(VENV)/bin/ruff format --check $(PYSRC)
	$(VENV)/bin/lint-imports

# Every test has a deadline (pytest-timeout, pyproject.toml): a test that hangs fails alone
# with the stacks of its threads, instead of holding the suite until CI's own limit.
pytest: develop
	$(PY) -m pytest -q -p no:cacheprovider

test: rust-lint rust-test py-lint pytest

# The documentation site -> docs/_build/html/index.html. Warnings are errors (-W, all of them
# reported: --keep-going) and every cross-reference between the pages must resolve (-n); the
# gallery's examples run. The generated pages are made anew each time.
docs: develop $(DOCS_STAMP)
	rm -rf docs/_build docs/generated docs/auto_examples
	$(VENV)/bin/sphinx-build -W --keep-going -n -q -b html docs docs/_build/html
	@echo "docs: docs/_build/html/index.html"

# Benchmarks (not part of `make test`): criterion for the Rust core, then the Python-level
# scripts. LSODA over 1e7 samples takes ~20 min; bench_normal's --scipy-n shortens it.
bench: develop
	cargo bench -p contactlab-core --locked --bench masing --bench normal --bench window
	$(PY) benches/bench_masing.py
	$(PY) benches/bench_normal.py --scipy-n 1e6
	$(PY) benches/bench_study.py

clean:
	rm -rf $(VENV) target demo-output docs/_build docs/generated docs/auto_examples
