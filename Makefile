# The two commands of the README. Needs only python3 (with venv) and make.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= out/paper_example

.PHONY: demo test test-core bench clean notebook docs

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

# Two pytest workers (pytest-xdist), a test file to each in turn: the suite is single-threaded
# and the machines have two cores.
test: $(BIN)/.installed
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

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
	$(BIN)/python bench/campaign_step.py
	$(BIN)/python bench/cold_start.py

# Every figure, table and data file under docs/, each from the command that docs/results.md
# gives for it, into $(DOCS_OUT) and then copied (hours on two cores: the two 1,000-sample
# campaigns take most of it). Files that hold wall times say so; nothing else should change.
DOCS_OUT ?= out/docs
DD := $(BIN)/drake-dock
docs: $(BIN)/.installed
	$(DD) run models/paper_example.yaml --out $(DOCS_OUT)/paper_example --no-progress
	cp $(DOCS_OUT)/paper_example/*.png docs/
	$(DD) study stability --out $(DOCS_OUT)/stability
	cp $(DOCS_OUT)/stability/stability_*.png docs/
	cp $(DOCS_OUT)/stability/summary.txt docs/stability_summary.txt
	$(DD) study speed-accuracy --out $(DOCS_OUT)/study
	cp $(DOCS_OUT)/study/work_precision_*.png docs/
	cp $(DOCS_OUT)/study/points.csv docs/speed_accuracy_points.csv
	cp $(DOCS_OUT)/study/speedups.txt docs/speed_accuracy_speedups.txt
	$(BIN)/python -m drake_dock.studies.funnel --shipped $(DOCS_OUT)/funnel_shipped
	cp $(DOCS_OUT)/funnel_shipped/funnel.png $(DOCS_OUT)/funnel_shipped/funnel.csv docs/
	$(DD) study conditions models/apds_funnel.yaml --out $(DOCS_OUT)/conditions_funnel
	cp $(DOCS_OUT)/conditions_funnel/conditions.png $(DOCS_OUT)/conditions_funnel/conditions.csv docs/
	$(DD) study examples --out $(DOCS_OUT)/examples
	cp $(DOCS_OUT)/examples/examples.csv docs/
	$(BIN)/python bench/edge_reach.py > $(DOCS_OUT)/edge_reach.txt
	cp $(DOCS_OUT)/edge_reach.txt docs/
	$(DD) study roll --out $(DOCS_OUT)/roll
	cp $(DOCS_OUT)/roll/roll.png $(DOCS_OUT)/roll/roll.csv docs/
	$(DD) study crosscheck --out $(DOCS_OUT)/crosscheck
	cp $(DOCS_OUT)/crosscheck/crosscheck.csv $(DOCS_OUT)/crosscheck/crosscheck.png docs/
	$(DD) campaign models/idss_envelope.yaml --out $(DOCS_OUT)/idss_paper --no-progress
	$(DD) campaign models/idss_envelope_funnel.yaml --out $(DOCS_OUT)/idss_funnel --no-progress
	$(BIN)/python -m drake_dock.campaign.table export $(DOCS_OUT)/idss_paper docs/campaign_paper.csv
	$(BIN)/python -m drake_dock.campaign.table export $(DOCS_OUT)/idss_funnel docs/campaign_funnel.csv
	for c in paper funnel; do for f in capture_probability histograms; do \
	  cp $(DOCS_OUT)/idss_$$c/$$f.png docs/campaign_$${c}_$$f.png; done; done

clean:
	rm -rf $(VENV) .venv-core out
