"""Randomised link pattern: exact counts, chain length, reproducible by seed."""
from __future__ import annotations

import numpy as np

from cvtfem.elements.link_pattern import link_lengths


def test_counts_length_and_seed():
    a = link_lengths(84, 0.0085, 0.0095, 0.5, np.random.default_rng(1))
    b = link_lengths(84, 0.0085, 0.0095, 0.5, np.random.default_rng(1))
    c = link_lengths(84, 0.0085, 0.0095, 0.5, np.random.default_rng(2))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.count_nonzero(a == 0.0095) == 42
    assert np.isclose(a.sum(), 0.756, rtol=1e-12)
