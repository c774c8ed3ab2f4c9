"""cvtfem: structural dynamics of chain-type CVTs and related drivetrains.

``import cvtfem`` loads neither matplotlib nor pyvista; plotting and rendering
modules import them lazily.
"""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("cvtfem")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+source"

__all__ = ["__version__"]
