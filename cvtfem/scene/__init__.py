"""Scene files (TOML) -> validated, read-only ``Scene`` objects; schema, presets, docs."""
