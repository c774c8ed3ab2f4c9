"""numba's on-disk kernel caches follow every kernel source (cvtfem.elements.jit.install_locators).

numba checks a cached kernel against its own file only: a kernel calling a kernel of another module keeps
stale machine code when only that other module changes. The test builds such a pair in a temporary package,
caches it, edits the callee and runs it again in a new process: with cvtfem's locators the result follows
the edit; with numba's own (the control) it is stale, so the test can fail.
"""
from __future__ import annotations

import hashlib
import subprocess
import sys
import textwrap

import pytest

from cvtfem.elements.jit import HAVE_NUMBA, KERNEL_DIRS, sources_digest

pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")

CALLER = """
from numba import njit
from kpkg.callee import g

@njit(cache=True)
def f(x):
    return g(x) + 1.0
"""
CALLEE = """
from numba import njit

@njit(cache=True)
def g(x):
    return {value} * x
"""


def _run(tmp_path, install: bool) -> float:
    """``f(1.0)`` of the temporary package in a new process (with or without the digest locators)."""
    setup = (f"from cvtfem.elements.jit import install_locators; install_locators({str(tmp_path)!r}, ('kpkg',))"
             if install else "import numba")
    code = f"import sys; sys.path.insert(0, {str(tmp_path)!r}); {setup}; from kpkg.caller import f; print(f(1.0))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return float(out.stdout.split()[-1])


@pytest.mark.parametrize("install", [True, False])
def test_cached_caller_follows_an_edited_callee(tmp_path, install):
    pkg = tmp_path / "kpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "caller.py").write_text(textwrap.dedent(CALLER))
    (pkg / "callee.py").write_text(CALLEE.format(value="2.0"))
    assert _run(tmp_path, install) == 3.0
    assert list((pkg / "__pycache__").glob("caller.f-*.nbi"))        # the caller's kernel is cached in-tree
    (pkg / "callee.py").write_text(CALLEE.format(value="5.0"))       # only the callee changes
    result = _run(tmp_path, install)
    assert result == (6.0 if install else 3.0)                       # numba alone keeps the stale 2 x + 1


def test_cvtfem_kernels_carry_the_digest_of_their_sources():
    from pathlib import Path

    from cvtfem.elements.chain import halves_kernel

    root = str(Path(halves_kernel.__file__).resolve().parents[2])   # the cvtfem package directory
    locator = halves_kernel.forces_power._cache._impl.locator
    assert type(locator).__name__.startswith("Digest")
    digest = sources_digest(root, KERNEL_DIRS)
    assert digest != hashlib.sha256().digest()                       # it covers files
    own = hashlib.sha256(Path(halves_kernel.__file__).read_bytes()).digest()
    assert locator.get_source_stamp() == own + digest                # numba's stamp, then the sources' digest
