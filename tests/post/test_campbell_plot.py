"""The Campbell figure: labels stacked without overlap, a frequency limit, and the CLI path."""
import numpy as np
import pytest

from cvtfem.post.campbell import spread


@pytest.mark.parametrize("seed", range(20))
def test_spread_keeps_order_gap_and_bounds(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 15))
    y = rng.uniform(-0.2, 1.2, n) if seed % 2 else np.full(n, 0.5)   # out of range, or all on one point
    gap = 1.0 / (n + 2)
    out = spread(y, gap, 0.0, 1.0)
    order = np.argsort(y, kind="stable")
    assert np.all(np.diff(out[order]) >= gap - 1e-12)                 # stacked in the order of y, gap apart
    assert out.min() >= -1e-12 and out.max() <= 1.0 + 1e-12
    inside = (y >= 0) & (y <= 1)
    if n == 1 or np.all(np.diff(np.sort(y)) >= gap):
        np.testing.assert_allclose(out[inside], y[inside])             # nothing moves that need not


def test_cli_campbell_png_with_frequency_limit(cli, tmp_path):
    png = tmp_path / "c.png"
    r = cli("campbell", "friswell_5_9_1", "--speeds", "0:4000rpm:11", "--n-modes", "4", "--orders", "1,2",
            "--png", str(png), "--fmax", "200")
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    r = cli("campbell", "friswell_5_9_1", "--speeds", "0:4000rpm:11", "--fmax", "-3")
    assert r.returncode == 2 and "--fmax" in r.stderr and len(r.stderr.strip().splitlines()) == 1
