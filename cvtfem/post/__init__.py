"""Post-processing and plots (matplotlib is imported lazily inside functions)."""
