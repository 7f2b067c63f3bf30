# Quick start: `make demo` builds the report of every system; `make test` runs the guards and the suite;
# `make docs` builds the documentation into docs/_build/html.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
OUT ?= results

.PHONY: demo test test-slow lint bench docs clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e .
	touch $@

$(VENV)/.installed-test: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(VENV)/.installed $@

$(VENV)/.installed-docs: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	touch $(VENV)/.installed $@

demo: $(VENV)/.installed
	$(BIN)/schuler report --out $(OUT)
	@echo "Open $(OUT)/index.html in a browser."

# the PSINS laser-gyro recording beside the checkout (not part of the project): its tests skip without it
PSINS_IMU ?= $(abspath $(wildcard ../shared/data/psins/lasergyro.imu))

# the guards: lint, types, and the layers of the import contract (pyproject.toml)
lint: $(VENV)/.installed-test
	@echo "== ruff: lint"
	$(BIN)/ruff check src tests benchmarks docs/_ext docs/conf.py examples
	@echo "== mypy: types"
	$(BIN)/mypy
	@echo "== import-linter: layers cli > study > systems > boundary > core"
	$(BIN)/lint-imports --no-cache

# one BLAS thread per test process: the models' matrices are small, and two
# processes already use both cores
PYTEST_ONE := SCHULER_PSINS_IMU="$(PSINS_IMU)" OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -q
PYTEST := $(PYTEST_ONE) -n 2

# the suite without the tests marked slow (long horizons, 1,000-member checks, fuzz per option)
test: lint
	@echo "== pytest: the suite (doctests included; slow tests: make test-slow)"
	$(PYTEST) -m "not slow"

test-slow: $(VENV)/.installed-test
	@echo "== pytest: the tests marked slow"
	$(PYTEST) -m "slow and not alone"
	@echo "== pytest: the slow tests timed with the machine to themselves (commands that spread over its cores)"
	$(PYTEST_ONE) -p no:xdist -m alone

# the site: user guide, gallery (its examples run), API reference; every warning is an error
docs: $(VENV)/.installed-docs
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m sphinx -W --keep-going -j auto -b html docs docs/_build/html
	@echo "Open docs/_build/html/index.html in a browser."

bench: $(VENV)/.installed-test
	for b in benchmarks/bench_*.py; do OPENBLAS_NUM_THREADS=1 $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache docs/_build docs/api docs/gallery docs/sg_execution_times.rst
