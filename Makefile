# gripkit: `make demo` and `make test` work on a fresh machine with Python 3.11 and pip.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# pytest workers; CI machines have 2 cores
JOBS   ?= 2

.PHONY: install demo test test-all bench clean clean-cache

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[dev,bench]"
	touch $(STAMP)

demo: install
	$(VENV)/bin/gripkit demo --out report

test: install
	$(PY) -m pytest -n $(JOBS)

test-all: install
	$(PY) -m pytest -n $(JOBS) -m ""

bench: install
	$(PY) benchmarks/run.py --out benchmarks/results

clean-cache:
	find src benchmarks examples tests \( -name '*.nbi' -o -name '*.nbc' \) -delete

clean: clean-cache
	rm -rf $(VENV) report build src/*.egg-info .pytest_cache
