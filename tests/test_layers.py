"""The layers of docs/architecture.md hold (lint-imports), and their contracts catch a forbidden import."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = Path(sys.executable).with_name("lint-imports")
CONTRACTS = {c["id"]: c["name"] for c in
             tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]}


def lint(cwd: Path, pythonpath: Path | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    return subprocess.run([str(LINT), "--no-cache"], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=120)


def test_contracts_are_kept():
    r = lint(ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"Contracts: {len(CONTRACTS)} kept, 0 broken." in r.stdout


@pytest.mark.parametrize(("module", "imported", "contract"), [
    ("integrate/base.py", "cvtfem.commands", "layers"),       # a solver reaching the CLI
    ("post/figures.py", "cvtfem.cli", "layers"),              # plots reaching the CLI
    ("io/progress.py", "cvtfem.elements.beam", "io"),         # io learning physics
    ("modal/eigen.py", "cvtfem.scene.loader", "scenes"),      # an analysis reading scenes
    ("integrate/base.py", "cvtfem.elements.torsional", "integrate"),
    ("analysis/run.py", "cvtfem.control.stabilisation", "physics"),
    ("scene/node.py", "cvtfem.machines", "no-cycles"),        # machines -> scene -> machines
])
def test_a_forbidden_import_breaks_its_contract(tmp_path, module, imported, contract):
    """A copy of the package with one forbidden import, made inside a function (lazy imports count)."""
    shutil.copytree(ROOT / "cvtfem", tmp_path / "cvtfem", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    path = tmp_path / "cvtfem" / module
    path.write_text(path.read_text() + f"\n\ndef _forbidden():\n    import {imported}  # noqa: F401\n")
    r = lint(tmp_path, pythonpath=tmp_path)
    assert r.returncode != 0, r.stdout + r.stderr
    broken = " ".join(r.stdout.split("Broken contracts")[-1].split())  # names are wrapped at 80 columns
    assert CONTRACTS[contract] in broken
    importer = "cvtfem." + module.removesuffix(".py").replace("/", ".")
    assert f"{importer} -> {imported}" in broken
