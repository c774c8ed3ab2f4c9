"""Results files, checkpoints and exports."""
