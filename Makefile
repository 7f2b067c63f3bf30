# Quick start: `make demo` builds the report of all five systems; `make test` runs the suite.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
OUT ?= results

.PHONY: demo test bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e .
	touch $@

$(VENV)/.installed-test: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(VENV)/.installed $@

demo: $(VENV)/.installed
	$(BIN)/schuler report --out $(OUT)
	@echo "Open $(OUT)/index.html in a browser."

# the PSINS laser-gyro recording beside the checkout (not part of the project): its tests skip without it
PSINS_IMU ?= $(abspath $(wildcard ../shared/data/psins/lasergyro.imu))

# one BLAS thread per test process: the models' matrices are small, and two
# processes already use both cores
test: $(VENV)/.installed-test
	SCHULER_PSINS_IMU="$(PSINS_IMU)" OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -n 2 -q

bench: $(VENV)/.installed-test
	for b in benchmarks/bench_*.py; do OPENBLAS_NUM_THREADS=1 $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache
