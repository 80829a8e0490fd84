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


class SignalError(FrictionUQError):
    """The signals of a record cannot be analysed (no pulse, no stationary phase, ...)."""


class NoStationaryPhase(SignalError):
    """No window in which the forces are steady within their noise."""


class PriorError(FrictionUQError):
    """A prior file is malformed: unknown key, unknown distribution, impossible parameters."""


class ConfigError(FrictionUQError):
    """A simulation configuration file is malformed."""


class SamplingError(FrictionUQError):
    """The sampler could not produce a usable posterior."""
