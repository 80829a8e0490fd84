"""Work on the machine's other core: a forked process where forking is safe, in line otherwise.

Forking a process that runs other threads can deadlock the child (a lock held by a thread that the
child does not have), and a daemon process (a Dask or multiprocessing worker) may not have
children; there the work runs in the calling process, with the same result: the functions handed
here are pure and seeded.
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any


def can_fork() -> bool:
    """Whether this process may fork workers safely (module docstring)."""
    return ("fork" in multiprocessing.get_all_start_methods() and not multiprocessing.current_process().daemon
            and threading.active_count() == 1)


_CALLS: dict[int, tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]] = {}


def _run_inherited(key: int) -> Any:
    """In the forked worker: the call :class:`Background` left in this module (inherited, not pickled)."""
    fn, args, kwargs = _CALLS[key]
    return fn(*args, **kwargs)


class Background:
    """``fn(*args, **kwargs)`` started now in a forked process (where :func:`can_fork`), its value taken
    with :meth:`result`; in line, at :meth:`result`, where not. The worker inherits the call from the
    fork (the arguments need not pickle); the value comes back pickled; an exception raised by ``fn``
    is raised again by :meth:`result`."""

    def __init__(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        self._call = (fn, args, kwargs)
        self._pool: ProcessPoolExecutor | None = None
        self._future: Future | None = None
        if can_fork():
            key = id(self)
            _CALLS[key] = self._call
            try:
                self._pool = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("fork"))
                self._future = self._pool.submit(_run_inherited, key)  # the worker is forked here
            finally:
                del _CALLS[key]

    @property
    def forked(self) -> bool:
        return self._future is not None

    def result(self) -> Any:
        fn, args, kwargs = self._call
        if self._future is None:
            return fn(*args, **kwargs)
        try:
            return self._future.result()
        finally:
            self.close()

    def close(self) -> None:
        """Stop the worker (a run interrupted before it asked for the value)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
