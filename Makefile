# navbook: `make book` builds the HTML book, `make test` runs the library tests and nbval.
# Both create .venv from environment.lock first if it is missing (or older than the lock).
SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.navbook-installed
GENERATED := book/_generated
NOTEBOOKS := $(sort $(wildcard notebooks/*.ipynb))
export PYTHONHASHSEED := 0
export PYDEVD_DISABLE_FILE_VALIDATION := 1
# One BLAS thread per process: on 2 shared cores threaded LAPACK stalls (50-400 ms on small solves) and
# single-threaded reductions keep stored notebook numbers identical from run to run.
export OPENBLAS_NUM_THREADS := 1
# The same floating-point kernels on every x86-64 machine with AVX2, so that the stored notebook outputs are
# what CI's machine computes too (CI failed on 2026-12-03 because its CPU took other kernels: numpy's AVX-512
# exp/log1p/arctan/power, MKL's and OpenBLAS's per-CPU code paths change the last bits, and the trained
# networks of chapters A and D amplify them into different tables).  Each library is pinned to its AVX2 path:
# numpy (no X86_V4/AVX-512 loops), OpenBLAS (Haswell kernels), MKL inside torch (conditional numerical
# reproducibility, AVX2 branch, strict: whatever the arrays' alignment) and torch's own vectorised kernels
# (ATen AVX2).  numba's kernels need no pin: they give the same bits for any vector width (navlib.methods.jit).
# navlib itself pins nothing: a library user gets the native kernels, equal to these within rounding.
export NPY_DISABLE_CPU_FEATURES := X86_V4 AVX512_ICL AVX512_SPR
export OPENBLAS_CORETYPE := Haswell
export MKL_CBWR := AVX2,STRICT
export ATEN_CPU_CAPABILITY := avx2

.PHONY: help venv book screenshots check test test-lib test-notebooks test-results notebooks bench lock clean

help:
	@echo "make book      - execute every notebook (papermill) and build the HTML book in book/_build/html"
	@echo "make screenshots - render every built page with headless Chromium (1400 px) into book/_build/screenshots"
	@echo "make check     - ruff lint and format check + the library tests not marked slow (the daily tier, about a minute)"
	@echo "make test      - library tests (pytest) + nbval on the stored notebooks + their results vs notebooks/results"
	@echo "make notebooks - re-execute notebooks/*.ipynb in place (regenerate the stored outputs and notebooks/results)"
	@echo "make bench     - run the speed benchmarks in benchmarks/"
	@echo "make lock      - regenerate environment.lock from requirements/requirements.in"

venv: $(STAMP)

$(STAMP): environment.lock pyproject.toml book/pyproject.toml
	@echo "== creating $(VENV) from environment.lock"
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@$(PY) -m pip install --quiet --disable-pip-version-check -r environment.lock 2>&1 | { grep -v "is ignored: it is neither" || true; }
	@$(PY) -m pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation -e . -e book 2>&1 | { grep -v "is ignored: it is neither" || true; }
	@$(PY) -m ipykernel install --sys-prefix --name python3 > /dev/null
	@touch $(STAMP)

book: $(STAMP)
	@rm -rf $(GENERATED)
	@$(PY) -m navbook compile
	@$(PY) -m navbook execute --out $(GENERATED) $(NOTEBOOKS)
	@$(PY) -m navbook status $(GENERATED)/results --notebooks $(GENERATED) --out $(GENERATED)/status.md
	@$(PY) -m navbook api-modules --out $(GENERATED)/api_modules.md
	@echo "== building the HTML book"
	@$(VENV)/bin/jupyter-book build book -W -n --keep-going --quiet
	@$(PY) -m navbook check-html book/_build/html
	@echo "== book built: book/_build/html/index.html"

# Screenshots of every built page (run `make book` first). Needs the Debian package chromium.
screenshots: $(STAMP)
	@test -f book/_build/html/index.html || { echo "no built book: run 'make book' first" >&2; exit 1; }
	@command -v chromium > /dev/null || { echo "chromium is missing: install it with 'apt-get install -y chromium' (Debian package chromium)" >&2; exit 2; }
	@$(PY) -m navbook screenshots book/_build/html book/_build/screenshots --width 1400

# The daily tier: lint, then the library tests not marked slow (pyproject markers), in two processes.
check: $(STAMP)
	@$(VENV)/bin/ruff check navlib book/navbook tests benchmarks
	@$(VENV)/bin/ruff format --check navlib book/navbook tests benchmarks || { echo "ruff format would change the files above: run '$(VENV)/bin/ruff format navlib book/navbook tests benchmarks'" >&2; exit 1; }
	@$(PY) -m pytest -q tests -p no:cacheprovider -m "not slow" $(if $(filter 1,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder)

# The library tests and nbval run at the same time (each is CPU-bound only part of the time: together they
# keep both cores busy; each one's output is printed when it ends), then the results files are compared.
# TEST_WORKERS=1: one after the other, each in this process.
test: $(STAMP)
	@echo "== library tests and nbval, at the same time (each prints its report when it ends)"
	@if [ "$(TEST_WORKERS)" = 1 ]; then $(MAKE) --no-print-directory test-lib test-notebooks; \
	 else $(MAKE) --no-print-directory -j2 --output-sync=target test-lib test-notebooks; fi
	@$(MAKE) --no-print-directory test-results

# Two pytest processes (pytest-xdist), each test file whole in one of them (module fixtures computed once),
# the longest files first (tests/conftest.py) so the two finish together;
# TEST_WORKERS=1 runs them in this process.
TEST_WORKERS ?= 2
test-lib: $(STAMP)
	@if [ "$(TEST_WORKERS)" = 1 ]; then $(PY) -m pytest -q tests -p no:cacheprovider; \
	 else $(PY) -m pytest -q tests -p no:cacheprovider -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder; fi

# nbval re-executes every notebook; each chapter's last cell rewrites $(GENERATED)/results/<chapter>.json.
# The folder is cleared first so a stale file cannot pass test-results.  Two notebooks run at a time
# (pytest-xdist, one whole notebook per process): one chapter's serial cells overlap the other's engine
# work; the numbers do not depend on it (TEST_WORKERS=1: one at a time).
test-notebooks: $(STAMP)
	@rm -rf $(GENERATED)/results
	@$(PY) -m navbook compile
	@NAVBOOK_RESULTS_DIR=$(CURDIR)/$(GENERATED)/results $(PY) -m pytest -q -p no:cacheprovider --nbval \
	    --nbval-current-env --nbval-sanitize-with notebooks/sanitize.cfg notebooks \
	    $(if $(filter 1,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder)

# The fresh results files against the committed references notebooks/results/<chapter>.json (make notebooks).
test-results: $(STAMP)
	@$(PY) -m navbook check-results --fresh $(GENERATED)/results --reference notebooks/results $(NOTEBOOKS)

notebooks: $(STAMP)
	@$(PY) -m navbook compile
	@$(PY) -m navbook execute --in-place $(NOTEBOOKS)

bench: $(STAMP)
	@for b in benchmarks/*.py; do echo "== $$b"; $(PY) $$b; done

lock:
	@rm -rf .lockvenv && $(PYTHON) -m venv .lockvenv
	@.lockvenv/bin/pip install --quiet -r requirements/requirements.in
	@{ echo "# navbook environment lock: every package pinned. Python 3.11."; \
	   echo "# Generated by 'make lock' from requirements/requirements.in (fresh venv, pip install, pip freeze)."; \
	   echo "# torch is the CPU wheel (2.13.0+cpu) that pip finds through this machine's find-links."; \
	   .lockvenv/bin/pip freeze --exclude-editable | grep -v '^navlib'; } > environment.lock
	@rm -rf .lockvenv
	@echo "environment.lock regenerated"

clean:
	rm -rf book/_build $(GENERATED)
