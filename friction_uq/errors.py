"""One exception base class for the package; the CLI catches it and exits 2 with its message."""

from __future__ import annotations

from pathlib import Path


class FrictionUQError(Exception):
    """Base class of every error the package raises on purpose (bad input, failed checks)."""


class RecordError(FrictionUQError):
    """A test record breaks the ``test.h5`` contract.

    The message names the file, the path inside it and the problem.
    """

    def __init__(self, file: str | Path, where: str, problem: str) -> None:
        self.file = str(file)
        self.where = where
        self.problem = problem
        super().__init__(f"{self.file}: {where}: {problem}")


class BackgroundError(FrictionUQError):
    """A forked process ended without handing back its value (killed, or out of memory)."""


class SignalError(FrictionUQError):
    """The signals of a record cannot be analysed (no pulse, no stationary phase, ...)."""


class ShortPreTrigger(SignalError):
    """A channel's pulse begins too soon after the record's start to leave a baseline before it."""


class NoStationaryPhase(SignalError):
    """No window in which the forces are steady within their noise."""


class PriorError(FrictionUQError):
    """A prior file is malformed: unknown key, unknown distribution, impossible parameters."""


class ConfigError(FrictionUQError):
    """A simulation configuration file is malformed."""


class SetupError(FrictionUQError):
    """An import set-up file (SETUP.toml) is malformed: unknown table or key, missing value, wrong unit."""


class ScopeFileError(FrictionUQError):
    """An oscilloscope export cannot be imported: missing column, non-numeric cell, unequal lengths, ..."""


class SamplingError(FrictionUQError):
    """The sampler could not produce a usable posterior."""


class OutputError(FrictionUQError):
    """An output cannot be written (no space, read-only, permission, a directory in the way, a lock)."""


class LockedError(OutputError):
    """Another process holds the output folder's lock (a run or a campaign writing the same names)."""


class SeedError(FrictionUQError):
    """A random seed outside [0, 2**64)."""


def os_error_text(exc: OSError) -> str:
    """The operating system's reason for ``exc`` in a few words (``strerror``, else the message)."""
    return exc.strerror or str(exc) or type(exc).__name__


def check_seed(seed: object, *, what: str = "--seed") -> int:
    """``seed`` as an int if it is an integer in [0, 2**64) (numpy's SeedSequence range), else SeedError."""
    if isinstance(seed, bool) or not isinstance(seed, int) and not hasattr(seed, "__index__"):
        raise SeedError(f"{what}: must be an integer in [0, 2**64), got {seed!r}")
    value = int(seed.__index__())
    if not 0 <= value < 2**64:
        raise SeedError(f"{what}: must be an integer in [0, 2**64), got {value}")
    return value
