"""Work on the machine's other core: a forked process where forking is safe, in line otherwise.

Forking a process that runs other threads can deadlock the child (a lock held by a thread that the
child does not have), and a daemon process (a Dask or multiprocessing worker) may not have
children; there the work runs in the calling process, with the same result: the functions handed
here are pure and seeded.
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Callable, Sequence
from typing import Any

from .errors import BackgroundError


#: True in a worker of :class:`ForkedPool` or :func:`forked_map` (set by :func:`end_with_parent`): a worker does its
#: share in line and forks nothing of its own (an executor's workers are not daemon processes).
_IN_WORKER = False


def can_fork() -> bool:
    """Whether this process may fork workers safely (module docstring)."""
    return ("fork" in multiprocessing.get_all_start_methods() and not multiprocessing.current_process().daemon
            and not _IN_WORKER and threading.active_count() == 1)


def end_with_parent() -> None:
    """In a forked child: be killed when the parent dies (Linux ``PR_SET_PDEATHSIG``), so a run killed
    with ``kill -9`` leaves no process working on for it (elsewhere the child ends when its value cannot
    be sent); ignore Ctrl-C, which the terminal sends to the whole process group: the parent handles it
    and stops the child, without a second traceback from the child."""
    import os
    import signal
    import sys

    global _IN_WORKER
    _IN_WORKER = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle: it stops the child
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        known = multiprocessing.parent_process()  # its pid was taken before the fork
        parent = known.pid if known is not None else os.getppid()
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
        if os.getppid() != parent:  # the parent died before the call: end now
            os._exit(1)
    except (OSError, AttributeError):
        pass


def _child(fn: Callable[..., Any], args: tuple, kwargs: dict, send: Any, recv: Any) -> None:
    """In the forked process: run the call, send (ok, value or exception) once, exit. A parent gone
    meanwhile closes the pipe's other end: the send fails and the child ends all the same (and on
    Linux it is killed with its parent)."""
    end_with_parent()
    recv.close()
    try:
        out: tuple[bool, Any] = (True, fn(*args, **kwargs))
    except BaseException as exc:  # noqa: BLE001 - carried back to the parent, raised there
        out = (False, exc)
    try:
        send.send(out)
    except Exception:  # noqa: BLE001 - the parent has gone (or the value does not pickle): nothing to tell
        pass
    finally:
        send.close()


class Background:
    """``fn(*args, **kwargs)`` started now in a forked process (where :func:`can_fork`), its value taken
    with :meth:`result`; in line, at :meth:`result`, where not. The child inherits the call from the
    fork (the arguments need not pickle); the value or the exception comes back pickled, once, and
    the child ends. A daemon child: it is stopped when this process exits, and :meth:`close` (or
    leaving the ``with`` block) stops it when its value is no longer wanted. ``fn`` None: nothing
    to do, :meth:`result` is None."""

    def __init__(self, fn: Callable[..., Any] | None, *args: Any, **kwargs: Any) -> None:
        self._call = (fn, args, kwargs)
        self._proc: Any = None
        self._recv: Any = None
        self._taken: tuple[bool, Any] | None = None
        if fn is not None and can_fork():
            ctx = multiprocessing.get_context("fork")
            recv, send = ctx.Pipe(duplex=False)
            self._proc = ctx.Process(target=_child, args=(fn, args, kwargs, send, recv), daemon=True)
            self._proc.start()
            send.close()
            self._recv = recv

    @property
    def forked(self) -> bool:
        return self._proc is not None

    def result(self) -> Any:
        """The value (computed once); the exception ``fn`` raised is raised again, and
        :class:`~friction_uq.errors.BackgroundError` where the child ended without a value."""
        fn, args, kwargs = self._call
        if self._taken is None:
            if fn is None:
                self._taken = (True, None)
            elif self._recv is None:  # in line (or the child was stopped before its value was taken)
                try:
                    self._taken = (True, fn(*args, **kwargs))
                except Exception as exc:
                    self._taken = (False, exc)
            else:
                try:
                    self._taken = self._recv.recv()
                except EOFError:
                    raise BackgroundError(f"the process working beside this one ({fn.__name__}) ended without handing "
                                          "back its result: it was killed, or ran out of memory") from None
                finally:
                    self.close()
        ok, value = self._taken
        if not ok:
            raise value
        return value

    def close(self) -> None:
        """Stop the child if it still runs (its value was not taken) and release the pipe."""
        if self._proc is not None:
            if self._proc.is_alive():
                self._proc.terminate()
            self._proc.join()
            self._proc = None
        if self._recv is not None:
            self._recv.close()
            self._recv = None

    def __enter__(self) -> Background:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_MAPPED: tuple[Callable[[Any], Any], list[Any]] | None = None


def _mapped(i: int) -> Any:
    fn, items = _MAPPED
    return fn(items[i])


def forked_map(fn: Callable[[Any], Any], items: Sequence[Any], *, workers: int) -> list[Any]:
    """``[fn(x) for x in items]`` on ``workers`` forked processes (where :func:`can_fork`; in turn where not):
    the items reach the workers by the fork (they need not pickle), the values come back pickled, in order.
    ``fn`` must give the same value in a child as in this process (a seed in each item, not a shared
    generator), so that the results do not depend on ``workers``."""
    global _MAPPED
    items = list(items)
    workers = min(workers, len(items))
    if workers <= 1 or not can_fork():
        return [fn(x) for x in items]
    _MAPPED = (fn, items)
    pool, done = _executor(workers), False
    try:
        values = _gather(pool, _mapped, range(len(items)), 1, getattr(fn, "__name__", "work"))
        done = True
        return values
    finally:
        _stop(pool, kill=not done)
        _MAPPED = None


def _executor(workers: int) -> Any:
    """``workers`` forked processes (forked at the first call, before the executor starts its own thread): a
    worker that dies (killed, out of memory) breaks the pool, and every wait on it ends with that error; a
    ``multiprocessing.Pool`` waits for ever for the dead worker's values."""
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork"), initializer=end_with_parent)


def _stop(pool: Any, *, kill: bool) -> None:
    """Shut the executor down; ``kill``: its workers stopped first (leaving on an error or Ctrl-C, nothing of
    theirs is wanted, and they ignore Ctrl-C: waiting for them would hold the caller for a fit or more).
    Python 3.14's ``terminate_workers``, else the executor's table of its processes."""
    if kill:
        stop = getattr(pool, "terminate_workers", None)
        if stop is not None:
            stop()
        else:
            for proc in list((getattr(pool, "_processes", None) or {}).values()):
                proc.terminate()
    pool.shutdown(wait=True, cancel_futures=True)


def _gather(pool: Any, fn: Callable[[Any], Any], items: Sequence[Any], chunk: int, name: str) -> list[Any]:
    """``list(pool.map(fn, items))``, a broken pool said as :class:`~friction_uq.errors.BackgroundError`."""
    from concurrent.futures.process import BrokenProcessPool

    try:
        return list(pool.map(fn, items, chunksize=chunk))
    except BrokenProcessPool:
        raise BackgroundError(f"a process working beside this one ({name}) ended without handing back its "
                              "result: it was killed, ran out of memory, or its result could not be passed "
                              "back") from None



_POOLED: Callable[[Any], Any] | None = None


def _pooled(x: Any) -> Any:
    return _POOLED(x)


class ForkedPool:
    """``fn`` on ``workers`` forked processes for many calls of :meth:`map` (a sampler's steps), forked once,
    at the first call; in turn, in this process, where :func:`can_fork` says no or one worker is asked for. A
    worker that dies ends the call with :class:`~friction_uq.errors.BackgroundError`. ``fn`` reaches the workers by the fork (it need not pickle: a closure over a likelihood);
    each call's items and values are pickled. ``fn`` must be pure, so that the values do not depend on
    ``workers``. One pool at a time per process."""

    def __init__(self, fn: Callable[[Any], Any], *, workers: int) -> None:
        self._fn = fn
        self._workers = workers
        self._pool: Any = None

    @property
    def forked(self) -> bool:
        return self._pool is not None

    def map(self, items: Sequence[Any]) -> list[Any]:
        """``[fn(x) for x in items]``, in order, split over the workers."""
        items = list(items)
        if self._pool is None or len(items) <= 1:
            return [self._fn(x) for x in items]
        chunk = max(1, len(items) // (4 * self._workers))
        return _gather(self._pool, _pooled, items, chunk, getattr(self._fn, "__name__", "work"))

    def __enter__(self) -> ForkedPool:
        global _POOLED
        if self._workers > 1 and can_fork():
            if _POOLED is not None:
                raise RuntimeError("one ForkedPool at a time per process")
            _POOLED = self._fn
            try:
                self._pool = _executor(self._workers)
            except BaseException:  # no pool (the fork failed): nothing holds the function any more
                _POOLED = None
                raise
        return self

    def __exit__(self, *exc: object) -> None:
        global _POOLED
        if self._pool is not None:
            _stop(self._pool, kill=exc[0] is not None)
            self._pool = None
            _POOLED = None
