"""numba's ``njit`` for the compiled kernels of the element families, or an identity decorator without numba
(``HAVE_NUMBA`` false: the families then use their numpy twins, or the kernels run as plain Python).

**On-disk caches that follow the whole kernel source.** numba validates a cached kernel (``cache=True``)
against the source of the function's own file only, so a kernel that calls or inlines a kernel of another
module, or reads its constants, would keep stale machine code after that other file changed (an upgrade of
cvtfem, or an edit in a checkout). :func:`install_locators` puts cache locators first in numba's list that,
for the files under a package directory, add to numba's stamp of every cached kernel (its own file) one
digest of all the ``.py`` sources of the directories that hold kernels and what they use: any change there
recompiles every kernel of the package once. Kernels of other packages keep numba's own locators.
"""
from __future__ import annotations

from pathlib import Path

from cvtfem.io.sources import sources_digest

try:
    from numba import njit
    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - exercised only without numba
    HAVE_NUMBA = False

    def njit(*args, **kwargs):  # noqa: D103 - identity decorator
        return (lambda f: f) if not args or not callable(args[0]) else args[0]

__all__ = ["njit", "HAVE_NUMBA", "install_locators", "sources_digest"]

#: cvtfem's directories whose sources the compiled kernels are built from (kernels, the functions and
#: constants they import).
KERNEL_DIRS = ("elements", "assembly", "machines")



def install_locators(root: str | Path, dirs: tuple[str, ...]) -> None:
    """Stamp the numba caches of the kernels defined under ``root`` with :func:`sources_digest` of ``root``'s
    ``dirs`` (numba's user-provided, in-tree and user-wide locations, in numba's order); call before the
    kernels are decorated. Without numba, or with a numba that lacks the locator list, nothing changes."""
    if not HAVE_NUMBA:  # pragma: no cover
        return
    from numba.core import caching

    impl = getattr(caching, "CacheImpl", getattr(caching, "_CacheImpl", None))   # the name since numba 0.59
    bases = [getattr(caching, n, None) for n in ("UserProvidedCacheLocator", "InTreeCacheLocator",
                                                   "UserWideCacheLocator")]
    if impl is None or not isinstance(getattr(impl, "_locator_classes", None), list) or None in bases:
        return  # pragma: no cover - a numba without this structure keeps its own invalidation
    top = str(Path(root).resolve())

    class _Digest:
        """A numba locator for the files under ``top`` whose stamp is the digest of the kernel sources."""

        @classmethod
        def from_function(cls, py_func, py_file):
            inside = Path(py_file).resolve().is_relative_to(top) if py_file else False
            return super().from_function(py_func, py_file) if inside else None

        def get_source_stamp(self):
            return super().get_source_stamp() + sources_digest(top, dirs)   # never less than numba's own stamp

    new = [type(f"Digest{b.__name__}", (_Digest, b), {}) for b in bases]
    impl._locator_classes[:0] = new


install_locators(Path(__file__).resolve().parents[1], KERNEL_DIRS)
