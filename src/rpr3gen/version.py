"""The installed distribution's version, for ``rpr3gen.__version__`` and the records that name
it (a sweep's hash, ``rpr3gen --version``)."""

import importlib.metadata

__all__ = ["__version__"]

try:
    __version__: str = importlib.metadata.version("rpr3gen")
except importlib.metadata.PackageNotFoundError:  # the source tree on sys.path, not installed
    __version__ = "0+unknown"
