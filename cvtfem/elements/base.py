"""What every element family declares about itself.

An element family (a whole 84-pin chain, all beam elements of a shaft) is one
object.  Besides its physics it declares how many generalized coordinates
(``n2``, each with a velocity) and first-order states (``n1``) it owns, its
discrete states (switched at events) and its named outputs with units; a model's
state is a sequence of named :class:`Block` s.
"""
from __future__ import annotations

from dataclasses import dataclass

from cvtfem.outputs import OutputSpec


@dataclass(frozen=True)
class Block:
    """A named block of state coordinates of a model.

    Attributes
    ----------
    name : str
        Block name (``band.phi``, ``control.speed``).
    size : int
        Number of coordinates.
    unit : str
        SI unit of the coordinates (their velocities carry ``unit/s``).
    order : int
        2: coordinates ``u`` with velocities ``v`` (second-order part); 1: first-order states ``z``.
    """

    name: str
    size: int
    unit: str
    order: int = 2


@dataclass(frozen=True)
class Layout:
    """Size and interface of one element family inside a model.

    Attributes
    ----------
    name : str
        Component name (``chain``, ``driving shaft``).
    kind : str
        Element family (``band-4dof``, ``chain-A5``, ``timoshenko-beam``).
    n2 : int
        Generalized coordinates with velocities.
    n1 : int
        First-order states (controllers, filters, friction memory).
    discrete : int
        Discrete states switched at events (contact on/off, plate states).
    outputs : tuple of OutputSpec
        Named outputs the family offers.
    note : str
        How the counts arise (``84 pins x 21``).
    """

    name: str
    kind: str
    n2: int
    n1: int = 0
    discrete: int = 0
    outputs: tuple[OutputSpec, ...] = ()
    note: str = ""
