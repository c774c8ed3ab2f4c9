"""The main demo (``cvtfem demo``): one module per part, each with ``run(outdir) -> list[str]``."""
