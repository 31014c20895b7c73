# Two entry points for a fresh machine (see README): `make demo` and `make test`.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[test]'
	touch $(STAMP)

.PHONY: install demo test test-all lint bench
install: $(STAMP)

demo: $(STAMP)
	$(BIN)/mechc compile examples/sorter.bool -o sorter.json
	$(BIN)/mechc simulate sorter.json

test: $(STAMP)
	@$(BIN)/python -m pytest -n auto -m "not slow"; rc=$$?; \
	if [ $$rc -eq 5 ]; then echo "pytest collected no tests: failing" >&2; exit 1; fi; \
	exit $$rc

# every test, the long ones (marked slow: multi-level circuits, held-out sweeps) included
test-all: $(STAMP)
	@$(BIN)/python -m pytest -n auto; rc=$$?; \
	if [ $$rc -eq 5 ]; then echo "pytest collected no tests: failing" >&2; exit 1; fi; \
	exit $$rc

lint: $(STAMP)
	$(BIN)/ruff check mechc stdlib tests benchmarks

bench: $(STAMP)
	$(BIN)/python benchmarks/minimise.py
