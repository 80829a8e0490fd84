"""Atomic file output: write to a temporary name in the same folder, then rename.

A file written this way appears whole or not at all, with the permissions an ordinary file gets
(``mkstemp`` alone would leave it 0600). Temporary names are ``.<name>.<random>.tmp<suffix>``
(:func:`temporary_glob` finds those an interrupted process left behind). An operating-system error
(no space, read-only file system, permission, a directory in the way) becomes one
:class:`~friction_uq.errors.OutputError` sentence naming the file; the temporary file is removed.
"""

from __future__ import annotations

import errno
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import LockedError, OutputError, os_error_text


def temporary_glob(name: str) -> str:
    """Glob pattern of the temporary files :func:`atomic_path` makes for a file called ``name``."""
    return f".{name}.*.tmp{Path(name).suffix}"


def output_error(path: str | os.PathLike[str], exc: OSError) -> OutputError:
    """One sentence for an operating-system error while writing ``path``."""
    hint = {
        errno.ENOSPC: "; free some space or choose another --out",
        errno.EDQUOT: "; free some space or choose another --out",
        errno.EROFS: "; choose a writable --out",
        errno.EACCES: "; choose a folder you may write to",
        errno.EPERM: "; choose a folder you may write to",
        errno.EISDIR: "; a directory has that name",
    }.get(exc.errno or 0, "")
    return OutputError(f"{path}: cannot write ({os_error_text(exc)}){hint}")


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[str]:
    """Yield a temporary path beside ``path``; on success it replaces ``path``, on error it is removed.

    Raises
    ------
    OutputError
        On any ``OSError`` while creating, writing or renaming (the message names ``path``).
    """
    out = Path(path)
    tmp = None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        if out.is_dir():
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(out))
        fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp" + out.suffix, dir=out.parent)
        os.close(fd)
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, out)
    except OSError as exc:
        raise output_error(out, exc) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return Path(path)


def write_together(files: dict[Path, bytes | None], *, last: Path) -> None:
    """Write several files as one set: all to temporary names first, then renamed, ``last`` last.

    ``files`` maps each path to its content, or to None for a file of an earlier set that this set
    does not have (it is removed, so no file of another run stays beside the new ones). ``last``
    (the file naming the others' checksums) is removed first and renamed into place last: while
    it is missing the set is incomplete, and once it is there every other file is the new one.

    Raises
    ------
    OutputError
        On any operating-system error; temporary files are removed and no old file is replaced.
    """
    tmps: dict[Path, str] = {}
    try:
        for path, data in files.items():
            if data is None:
                continue
            path.parent.mkdir(parents=True, exist_ok=True)
            if path.is_dir():
                raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=path.parent)
            tmps[path] = tmp
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
    except OSError as exc:
        for tmp in tmps.values():
            if os.path.exists(tmp):
                os.unlink(tmp)
        raise output_error(getattr(exc, "filename", None) or next(iter(files)), exc) from None
    current = None
    try:
        current = last
        if last.exists():
            last.unlink()
        for path, data in files.items():
            current = path
            if data is None:
                if path.exists():
                    path.unlink()
            elif path != last:
                os.replace(tmps.pop(path), path)
        current = last
        if last in tmps:
            os.replace(tmps.pop(last), last)
    except OSError as exc:
        raise output_error(current, exc) from None
    finally:
        for tmp in tmps.values():
            if os.path.exists(tmp):
                os.unlink(tmp)


#: File descriptors of the locks this process holds: a forked child closes them at once
#: (:func:`_close_locks_in_child`), so a lock ends with the process that took it, never later with a child.
_HELD_LOCKS: set[int] = set()


def _close_locks_in_child() -> None:
    """After a fork, in the child: drop its copies of the parent's lock descriptors. An ``flock`` is held
    while any descriptor of it is open; a child still working (or stopped) after its parent was killed
    would otherwise keep the folder locked."""
    for fd in list(_HELD_LOCKS):
        try:
            os.close(fd)
        except OSError:
            pass
    _HELD_LOCKS.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_close_locks_in_child)


@contextmanager
def output_lock(folder: Path, stem: str, *, busy: str | None = None) -> Iterator[Path]:
    """Hold ``folder/.<stem>.lock`` (``fcntl.flock``) while a run writes ``<stem>.*`` into ``folder``.

    A second run of the same record into the same folder is refused at once with one sentence (it
    would overwrite the first one's outputs and checkpoint); ``busy`` replaces that sentence. The lock
    file is removed on release; a lock whose file was removed meanwhile is taken again on the new file.
    Forked children do not keep it (their copy of the descriptor is closed at the fork).

    Raises
    ------
    OutputError
        If another process holds the lock, or the lock file cannot be created.
    """
    import fcntl

    path = folder / f".{stem}.lock"
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise output_error(path, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise LockedError(busy or (
                f"{folder}: another friction-uq run is writing {stem} into this folder (lock {path.name}); "
                "wait for it to end or choose another --out")) from None
        except OSError as exc:
            os.close(fd)
            raise output_error(path, exc) from None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # the holder removed the file between our open and flock: lock the new one
    _HELD_LOCKS.add(fd)
    try:
        yield path
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
        _HELD_LOCKS.discard(fd)
        os.close(fd)


@contextmanager
def output_folder(folder: Path) -> Iterator[Path]:
    """Create ``folder`` (and its parents) for a run's outputs; if the run then fails, remove the folders this
    call created that are still empty, so that a refused run leaves nothing behind.

    Raises
    ------
    OutputError
        If ``folder`` is a file or cannot be created.
    """
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{folder}: --out must be a directory, and this is a file")
    full = Path(os.path.abspath(folder))  # 'a/../b' made 'b' only
    made = [p for p in reversed([full, *full.parents]) if not p.exists()]

    def remove_made() -> None:
        for p in reversed(made):  # the deepest first; a folder something was written into stays
            try:
                p.rmdir()
            except OSError:
                break

    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        remove_made()  # the parents made before the failure
        raise OutputError(f"{folder}: cannot create the output directory ({os_error_text(exc)})") from None
    try:
        yield folder
    except BaseException:
        remove_made()
        raise


def check_unlocked(folder: Path, stem: str, *, busy: str | None = None) -> None:
    """Refuse at once, as :func:`output_lock` would, when another process holds ``folder/.<stem>.lock``: a
    busy folder is said before any work. Takes nothing and creates nothing (the lock itself is taken later)."""
    import fcntl

    path = folder / f".{stem}.lock"
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return  # no lock file (or none readable): nobody holds it, or output_lock will say why
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        raise LockedError(busy or f"{folder}: another friction-uq run is writing {stem} into this folder (lock "
                          f"{path.name}); wait for it to end or choose another --out") from None
    except OSError:
        pass
    finally:
        os.close(fd)


def remove_orphans(folder: Path, names: list[str]) -> list[Path]:
    """Remove the temporary files an interrupted process left for ``names`` in ``folder``.

    Call it only while holding :func:`output_lock` for these names (then nobody else writes them).
    Returns the files removed.
    """
    gone = []
    for name in names:
        for p in folder.glob(temporary_glob(name)):
            try:
                p.unlink()
                gone.append(p)
            except OSError:
                pass
    return gone
