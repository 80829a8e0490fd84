"""The libraries' own messages go to a log file in the output folder, not to the terminal.

Dask's nanny ("Worker process still alive after 4.0 seconds, killing"), numba's, ArviZ's and
matplotlib's warnings mean something to a developer, not to the person reading the run's result:
while a command works, Python warnings and the log records of the libraries named in
:data:`LIBRARIES` are kept and, when the command ends, appended to ``<out>/friction-uq.log`` (only
when there is one to write, only into an output folder that exists, and only when the command ended without an
error: a refused or failed command leaves nothing behind, not even in a folder that was there before). The terminal
keeps the tool's own lines.
"""

from __future__ import annotations

import contextlib
import logging
import os
import warnings
from collections.abc import Iterator

#: Loggers of the libraries a command uses (their children follow them).
LIBRARIES = ("distributed", "dask", "tornado", "asyncio", "numba", "arviz", "arviz_stats", "matplotlib", "h5py",
             "xarray", "emcee", "fontTools", "py.warnings")


#: The log's name in the output folder.
LOG_NAME = "friction-uq.log"


class _Kept(logging.Handler):
    """Keeps the formatted records until the command ends."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.lines.append(self.format(record))
        except Exception:  # noqa: BLE001 - a message that cannot be formatted is not worth a traceback
            self.lines.append(f"{record.name} {record.levelname}: (unformattable message)")


#: The handler of the :func:`libraries_to_log` in force (None outside one).
_ACTIVE: list[logging.Handler] = []


def reroute() -> None:
    """Send the libraries' loggers to the log again: a library that sets up its own handlers when it is
    imported (dask.distributed does) is imported after :func:`libraries_to_log` began; call this after."""
    if _ACTIVE:
        for name in LIBRARIES:
            lg = logging.getLogger(name)
            lg.handlers, lg.propagate = [_ACTIVE[-1]], False


@contextlib.contextmanager
def libraries_to_log(out_dir: str | os.PathLike[str]) -> Iterator[None]:
    """While inside: Python warnings and the libraries' log records are kept for ``out_dir/friction-uq.log``."""
    handler = _Kept()
    handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(levelname)s: %(message)s"))
    saved = []
    for name in LIBRARIES:
        lg = logging.getLogger(name)
        saved.append((lg, lg.handlers[:], lg.propagate))
        lg.handlers, lg.propagate = [handler], False
    _ACTIVE.append(handler)
    capture = logging.getLogger("py.warnings")
    capture.setLevel(logging.WARNING)
    logging.captureWarnings(True)
    ended = False
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            yield
        ended = True
    finally:
        _ACTIVE.remove(handler)
        logging.captureWarnings(False)
        for lg, handlers, propagate in saved:
            lg.handlers, lg.propagate = handlers, propagate
        if ended:  # a command that failed leaves nothing behind (its one sentence is the message)
            _append(out_dir, handler.lines)


def _append(out_dir: str | os.PathLike[str], lines: list[str]) -> None:
    if not lines or not os.path.isdir(out_dir):
        return
    with contextlib.suppress(OSError):  # a full disk or a read-only folder: the result matters, not the log
        with open(os.path.join(out_dir, LOG_NAME), "a", encoding="utf-8") as fh:
            fh.write("\n".join(lines) + "\n")
