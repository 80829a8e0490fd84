"""Read and write a confined friction test record (``test.h5``, format version 1).

The contract is ``docs/record-format.md``. The package is the reading boundary of friction-uq:

* :mod:`.contract`: the format's constants and the immutable :class:`Record` / :class:`Channel`;
* :mod:`.reader`: :func:`read_record` checks every rule of the contract (a file that breaks one is
  refused with a :class:`~friction_uq.errors.RecordError` naming the file, the path inside it and
  the problem) and flips the gauge sign **once**: inside the package strains are positive in
  compression; :func:`read_truth` reads the generating parameters of a synthetic record;
* :mod:`.writer`: :func:`write_record`, the single way the package writes records, atomically.

The apparatus types and the paper's set-up live in :mod:`friction_uq.apparatus` and are
re-exported here, being the record's apparatus.
"""

from ..apparatus import (
    DEFAULT_BAR_POISSON_RATIO,
    Apparatus,
    Bar,
    Plug,
    Sample,
    Tube,
    paper_apparatus,
)
from .contract import (
    CHANNELS,
    CLIP_RUN,
    FORMAT,
    FORMAT_VERSION,
    MIN_SAMPLES,
    OPTIONAL_CHANNELS,
    REQUIRED_CHANNELS,
    UNITS,
    Channel,
    Record,
)
from .reader import read_record, read_truth
from .writer import write_record

__all__ = [
    "CHANNELS",
    "CLIP_RUN",
    "DEFAULT_BAR_POISSON_RATIO",
    "FORMAT",
    "FORMAT_VERSION",
    "MIN_SAMPLES",
    "OPTIONAL_CHANNELS",
    "REQUIRED_CHANNELS",
    "UNITS",
    "Apparatus",
    "Bar",
    "Channel",
    "Plug",
    "Record",
    "Sample",
    "Tube",
    "paper_apparatus",
    "read_record",
    "read_truth",
    "write_record",
]
