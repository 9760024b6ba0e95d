# rawehelix: two commands on a fresh Debian 12 machine (root or sudo):
#   make demo   installs what is missing, then runs Secs. 5.1-5.3 and writes results/report.html
#   make test   installs what is missing, then runs the tests serially and under mpirun -n 2
#   make docs   builds the documentation (Sphinx, MyST) into docs/_build/html

VENV    := .venv
PY      := $(VENV)/bin/python
RAWE    := $(VENV)/bin/rawehelix
NP      ?= 2
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
MPIRUN  := mpirun -n $(NP) --oversubscribe
PYTEST_ARGS ?=
MARKS   ?= not long

.PHONY: install demo test test-long test-debian13 bench clean docs

install:
	@bash scripts/install.sh

demo: install
	$(PY) -m rawehelix.cli.demo results

test: install
	$(PY) -m pytest -q -m "$(MARKS)" --durations=15 $(PYTEST_ARGS)
	$(MPIRUN) $(PY) -m pytest -q -m "mpi and ($(MARKS))" -p no:cacheprovider $(PYTEST_ARGS)

test-long: install
	$(PY) -m pytest -q -m long $(PYTEST_ARGS)
	$(MPIRUN) $(PY) -m pytest -q -m "mpi and long" -p no:cacheprovider $(PYTEST_ARGS)

test-debian13:
	@MARKS="$(MARKS)" bash scripts/test-debian13.sh

clean:
	rm -rf results .pytest_cache

docs: install
	$(PY) -m sphinx -W --keep-going -b html docs docs/_build/html

bench: install
	$(PY) benchmarks/run.py
