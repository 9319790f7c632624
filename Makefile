# Every entry point of the project. `make demo` and `make test` set everything up on a fresh
# machine: they create .venv and install the package with its test dependencies.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
BUILD  := build

.PHONY: setup demo test bench clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# Simulate a built-in scene, print a summary, draw its events to build/.
demo: $(STAMP)
	mkdir -p $(BUILD)
	$(VENV)/bin/evclust simulate traffic -o $(BUILD)/traffic.npz --truth $(BUILD)/traffic_truth.csv
	$(VENV)/bin/evclust show $(BUILD)/traffic.npz -o $(BUILD)/traffic_events.png
	@echo "picture: $(BUILD)/traffic_events.png"

test: $(STAMP)
	$(PY) -m pytest -q

bench: $(STAMP)
	$(PY) bench/simulator.py --write docs/BENCHMARKS.md

clean:
	rm -rf $(BUILD) .pytest_cache
