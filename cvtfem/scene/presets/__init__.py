"""Built-in scene presets (TOML files beside this module)."""
