"""Analyses of a scene over time: the run driver (`run.py`, `cvtfem run`)."""
