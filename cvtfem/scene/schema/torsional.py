"""Torsional networks (disks, shafts, gear meshes with backlash) for harmonic balance.

Filled in by the periodic-response work (issue 6).
"""
from __future__ import annotations

ROOT_ITEMS: tuple = ()
ROOT_CHECKS: tuple = ()
