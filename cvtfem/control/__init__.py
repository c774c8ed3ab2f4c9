"""Speed and ratio stabilisation systems (spec: low-order digest section 5).

Usable by any model that exposes its two shaft speeds and takes clamping forces and
shaft torques as inputs.
"""
from cvtfem.control.stabilisation import Stabilisation, StabilisationParams, clamp, ratio_estimate

__all__ = ["Stabilisation", "StabilisationParams", "clamp", "ratio_estimate"]
