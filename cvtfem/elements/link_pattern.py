"""Randomised long/short link pattern of a chain (reduces the tonal noise of the link frequency)."""
from __future__ import annotations

import numpy as np


def link_lengths(n_links: int, pitch_short: float, pitch_long: float, long_fraction: float,
                 rng: np.random.Generator) -> np.ndarray:
    """Lengths of the links of a randomised chain, m.

    Exactly ``round(long_fraction * n_links)`` links are long; their positions
    are a random permutation drawn from ``rng``, so a seed fixes the chain.

    Parameters
    ----------
    n_links : int
        Number of links (= pins in a closed chain).
    pitch_short, pitch_long : float
        Short and long link length, m.
    long_fraction : float
        Share of long links, 0..1.
    rng : numpy.random.Generator
        Source of randomness (pass ``numpy.random.default_rng(scene.seed)``).

    Returns
    -------
    ndarray, shape (n_links,)
        Link lengths in chain order, m.

    Examples
    --------
    >>> lengths = link_lengths(6, 0.008, 0.010, 0.5, np.random.default_rng(0))
    >>> float(lengths.sum())
    0.054
    """
    n_long = int(round(long_fraction * n_links))
    lengths = np.full(n_links, pitch_short)
    lengths[:n_long] = pitch_long
    return rng.permutation(lengths)
