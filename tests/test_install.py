"""The environment is the one `constraints.txt` pins (issue 11: results depend on library versions).

`make demo` and `make test` install with `PIP_CONSTRAINT=constraints.txt`, so every pinned distribution
must be installed at exactly its pinned version.  `make test-latest` runs the suite on the newest
versions instead and sets CVTFEM_UNPINNED=1, which skips this test.
"""
import os
import re
from importlib import metadata
from pathlib import Path

import pytest

CONSTRAINTS = Path(__file__).resolve().parents[1] / "constraints.txt"


def pins() -> dict[str, str]:
    out = {}
    for line in CONSTRAINTS.read_text().splitlines():
        m = re.fullmatch(r"([A-Za-z0-9_.\-]+)==([^\s;#]+)", line.strip())
        if m:
            out[re.sub(r"[-_.]+", "-", m[1]).lower()] = m[2]
    return out


def test_constraints_pin_the_declared_dependencies():
    from tomllib import loads

    project = loads((CONSTRAINTS.parent / "pyproject.toml").read_text())["project"]
    declared = project["dependencies"] + project["optional-dependencies"]["test"]
    names = {re.sub(r"[-_.]+", "-", re.match(r"[A-Za-z0-9_.\-]+", d)[0]).lower() for d in declared}
    assert names <= set(pins()), sorted(names - set(pins()))


@pytest.mark.skipif(os.environ.get("CVTFEM_UNPINNED") == "1", reason="make test-latest: newest versions on purpose")
def test_installed_versions_are_the_pinned_ones():
    wrong = {}
    for name, version in pins().items():
        try:
            have = metadata.version(name)
        except metadata.PackageNotFoundError:
            have = None
        if have != version:
            wrong[name] = (have, version)
    assert not wrong, f"installed vs constraints.txt: {wrong} (run `make install`, or `make lock` to re-pin)"
