# gripkit: `make demo` and `make test` work on a fresh machine with Python 3.11 and pip.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# pytest workers; CI machines have 2 cores
JOBS   ?= 2

# exact versions for the venv, CI and the demo; pyproject.toml keeps ranges for library users
LOCK   := requirements.lock
UV     := uv==0.13.9

.PHONY: install lock demo test test-all bench clean clean-cache

install: $(STAMP)

# every package at the version of the lock; gripkit itself built with the locked setuptools
$(STAMP): pyproject.toml $(LOCK)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -r $(LOCK)
	$(PY) -m pip install --quiet --no-deps --no-build-isolation -e .
	$(PY) -m pip check
	touch $(STAMP)

# refresh the lock from pyproject.toml's ranges (uv resolves in seconds and writes pip's format,
# so installing from the lock needs nothing but pip)
lock:
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet "$(UV)"
	printf 'setuptools>=77\n' | .venv-lock/bin/uv pip compile pyproject.toml - --extra dev --extra bench \
		--python-version 3.11 --universal --no-header --annotation-style line -o $(LOCK)

demo: install
	$(VENV)/bin/gripkit demo --out report

test: install
	$(PY) -m ruff check src tests benchmarks examples scripts
	$(PY) -m pytest -n $(JOBS)

test-all: install
	$(PY) -m ruff check src tests benchmarks examples scripts
	$(PY) -m pytest -n $(JOBS) -m ""

bench: install
	$(PY) benchmarks/run.py --out benchmarks/results

clean-cache:
	find src benchmarks examples tests \( -name '*.nbi' -o -name '*.nbc' \) -delete

clean: clean-cache
	rm -rf $(VENV) .venv-lock report build src/*.egg-info .pytest_cache
