"""The element library: vectorised families of physics (one object per family)."""
