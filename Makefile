# Two commands for a fresh machine:
#   make repro   create .venv, install, run the whole DVC pipeline with params.yaml
#   make test    create .venv, install with dev extras, run ruff and the test suite
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
export DVC_NO_ANALYTICS := 1
export PATH := $(abspath $(BIN)):$(PATH)

.PHONY: repro test lint format install bench clean-venv

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $@

install: $(VENV)/.installed

repro: install
	dvc repro

test: install lint
	$(BIN)/python -m pytest -n 2 --dist loadfile -q --durations=15   # the 15 slowest tests, to keep the suite in its budget

lint: install   # ruff: lint (pyflakes, pycodestyle at 120 columns, import order) and the format check
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: install   # rewrite the sources in the house format
	$(BIN)/ruff check --fix .
	$(BIN)/ruff format .

bench: install
	cd bench && ../$(BIN)/python voxelize_speed.py && ../$(BIN)/python voxelize_accuracy.py && ../$(BIN)/python grasp_quality_speed.py && ../$(BIN)/python render_speed.py

clean-venv:
	rm -rf $(VENV)
