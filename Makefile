# The two commands of the README: `make demo` and `make test`.
# Each creates .venv and installs what it needs (Python 3.11, pip, gcc; PyPI only).
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-$(shell cksum pyproject.toml | cut -d' ' -f1)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	rm -f $(VENV)/.installed-*
	touch $@

.PHONY: install demo test test-slow test-all docs
install: $(STAMP)

demo: $(STAMP)
	$(BIN)/cvtfem demo --out out/demo

test: $(STAMP)
	$(BIN)/python -m pytest -m "not slow" -q

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow -q

test-all: $(STAMP)
	$(BIN)/python -m pytest -q

docs: $(STAMP)
	$(BIN)/cvtfem docs scenes --out docs/scenes.md
