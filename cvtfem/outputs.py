"""What a named output is: name, SI unit, meaning and size per sample.

Element families declare their outputs with it, results files store it; it
sits at the bottom of the layers so that both can.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class OutputSpec:
    """A named output of an element family.

    Attributes
    ----------
    name : str
        Output name, unique within the model (``chain.link_tension``).
    unit : str
        SI unit.
    doc : str
        One-line meaning.
    size : int
        Number of values per output sample (e.g. one per link).
    """

    name: str
    unit: str
    doc: str
    size: int = 1
