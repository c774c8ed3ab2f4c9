"""Off-screen pyvista renderings (pyvista is imported inside the functions)."""
