"""friction-uq: friction coefficient with honest uncertainty from confined friction SHPB tests."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("friction-uq")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
