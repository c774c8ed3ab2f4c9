"""The command line: presets, describe, bad input with exit status 2 and no traceback."""
from __future__ import annotations

import pytest

from cvtfem.scene.loader import preset_names


def test_scenes_lists_presets(cli):
    res = cli("scenes")
    assert res.returncode == 0
    for name in preset_names():
        assert name in res.stdout


@pytest.mark.parametrize("name", preset_names())
def test_describe_each_preset(cli, name):
    res = cli("describe", name)
    assert res.returncode == 0, res.stderr
    assert "components:" in res.stdout and "total" in res.stdout and "outputs:" in res.stdout


def test_describe_counts_reference_chain(cli):
    out = cli("describe", "reference_cvt").stdout
    # model (e): 84 pins x 21 = 1764 chain coordinates (chain-models-2.md section 0.1)
    assert "1764" in out and "84 pins x 21" in out


def test_describe_typo_in_key(cli, tmp_path):
    scene = tmp_path / "typo.toml"
    scene.write_text('preset = "reference_cvt"\n[cvt.chain]\nn_pin = 84\n')
    res = cli("describe", str(scene))
    assert res.returncode == 2
    assert "`cvt.chain.n_pin`" in res.stderr and "did you mean `n_pins`" in res.stderr
    assert "Traceback" not in res.stderr


def test_bad_toml_and_missing_file(cli, tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text("[cvt\n")
    res = cli("describe", str(broken))
    assert res.returncode == 2 and "valid TOML" in res.stderr and "Traceback" not in res.stderr
    res = cli("describe", str(tmp_path / "absent.toml"))
    assert res.returncode == 2 and "existing TOML file" in res.stderr


def test_unknown_command_exits_2(cli):
    res = cli("frobnicate")
    assert res.returncode == 2 and "Traceback" not in res.stderr


def test_docs_scenes_writes_file(cli, tmp_path):
    out = tmp_path / "scenes.md"
    assert cli("docs", "scenes", "--out", str(out)).returncode == 0
    assert out.read_text().startswith("# Scene reference")
