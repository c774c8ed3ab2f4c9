"""Speed and ratio stabilisation systems, clamping schedule and regimes (spec: low-order digest sections 3.1, 5, 6).

Usable by any model that exposes its two shaft speeds and takes clamping forces and
shaft torques as inputs.
"""
from cvtfem.control.stabilisation import OpenLoop, Stabilisation, StabilisationParams, clamp, ratio_estimate

__all__ = ["OpenLoop", "Stabilisation", "StabilisationParams", "clamp", "ratio_estimate"]
