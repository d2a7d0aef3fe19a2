# The two commands of the README. Needs only python3 (with venv) and make.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= out/paper_example

.PHONY: demo test test-core bench clean notebook

# The install says what it does: pip lists each package it collects and installs; then the
# numba kernels are compiled once, so that the first run simulates at full speed.
$(BIN)/.installed: pyproject.toml constraints.txt
	@echo "== drake_dock: creating $(VENV) and installing Drake, numba and the other dependencies (about 2 min the first time)"
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade "pip==26.3"
	$(BIN)/python -m pip install -c constraints.txt -e ".[test]"
	@echo "== drake_dock: compiling the numba kernels (once, a process per core, a line per module; runs load them from the cache)"
	$(BIN)/python -m drake_dock.core.kernels
	touch $@

demo: $(BIN)/.installed
	$(BIN)/drake-dock run models/paper_example.yaml --out $(OUT)

# Jupyter (the `notebook` extra) and the tutorial opened in it.
$(BIN)/.notebook: $(BIN)/.installed
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[notebook]"
	touch $@

# Jupyter refuses to run as root unless told (containers).
notebook: $(BIN)/.notebook
	$(BIN)/jupyter notebook $(if $(filter 0,$(shell id -u)),--allow-root) notebooks/tutorial.ipynb

test: $(BIN)/.installed
	$(BIN)/python -m pytest -q

# tests/core in a virtual environment without Drake (numpy, scipy, numba, pytest, pyyaml only).
test-core:
	$(PYTHON) -m venv .venv-core
	.venv-core/bin/python -m pip install --quiet -c constraints.txt numpy scipy numba pytest hypothesis pyyaml
	PYTHONPATH=. .venv-core/bin/python -m pytest -q -p no:cacheprovider tests/core

bench: $(BIN)/.installed
	$(BIN)/python bench/lzb_chains.py
	$(BIN)/python bench/contact_eval.py
	$(BIN)/python bench/paper_example.py
	$(BIN)/python bench/time_shares.py
	$(BIN)/python bench/target_floor.py
	$(BIN)/python bench/offnominal.py
	$(BIN)/python bench/evaluation.py
	$(BIN)/python bench/campaign.py
	$(BIN)/python bench/cold_start.py

clean:
	rm -rf $(VENV) .venv-core out
