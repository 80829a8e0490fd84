"""friction-uq: friction coefficient with honest uncertainty from confined friction SHPB tests.

The Python interface (:mod:`friction_uq.api`), imported on first use so that ``import friction_uq``
stays light:

* :func:`import_scope_files` - oscilloscope files and a SETUP.toml to a test record;
* :func:`run` - the posterior of f and nu for one record, its JSON, netCDF and PDF;
* :func:`diagnose` - run, then the cause of a misfit named;
* :func:`campaign` - many records, pooled, the friction law across set-ups;
* :func:`read_result` - a run's outputs read back (:class:`Result`, with ``datatree()`` for ArviZ).
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("friction-uq")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

_API = ("Result", "campaign", "diagnose", "import_scope_files", "read_result", "run")

__all__ = ["__version__", *_API]


def __getattr__(name: str):  # PEP 562: the API's modules load on first use
    if name in _API:
        from . import api

        return getattr(api, name)
    raise AttributeError(f"module 'friction_uq' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
