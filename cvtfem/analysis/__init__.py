"""Analyses driven for a scene: the run driver (`run.py`, `cvtfem run`), the integrator study on a
scene (`study_problem.py`), the Campbell benchmark (`bench_campbell.py`, `cvtfem bench campbell`)."""
