"""The ``test.h5`` contract (format version 1): its constants and the checked, immutable record.

The contract is ``docs/record-format.md``. A :class:`Record` holds the gauge channels converted
to strain, **positive in compression** (the sign is flipped once, by the reader), and the
apparatus with its derived quantities.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..apparatus import Apparatus

FORMAT = "friction-uq/test"
FORMAT_VERSION = 1

REQUIRED_CHANNELS = ("input_bar", "internal_output_bar", "external_output_bar")
OPTIONAL_CHANNELS = ("tube_hoop",)
CHANNELS = REQUIRED_CHANNELS + OPTIONAL_CHANNELS

UNITS = {"strain": 1.0, "microstrain": 1e-6, "V": None}

#: Minimum run of identical samples at a channel's extreme value that can mark it as clipped; the
#: run must also be longer than its pre-trigger noise leaves by chance (:mod:`.saturation`): a
#: plateau read by a digitiser whose step is coarser than its noise sits on one code too.
CLIP_RUN = 8
#: A channel's pre-trigger as first read (its noise, a provisional baseline): its first 2 %, at least 32 samples.
HEAD_FRACTION = 0.02
MIN_HEAD_SAMPLES = 32

#: Minimum number of samples in a channel.
MIN_SAMPLES = 64


@dataclass(frozen=True)
class Channel:
    """One gauge channel, converted to strain, **positive in compression**.

    ``units`` and ``strain_per_volt`` are as stored in the file (for display).
    """

    name: str
    strain: np.ndarray
    units: str
    strain_per_volt: float | None = None


@dataclass(frozen=True)
class Record:
    """One confined friction test, read and checked. Immutable."""

    path: str
    test_id: str
    campaign: str
    sample_rate: float
    t0: float
    channels: Mapping[str, Channel]
    apparatus: Apparatus
    date: str | None = None
    description: str | None = None
    striker_velocity: float | None = None
    provenance: Mapping[str, Any] = field(default_factory=dict)
    sha256: str = ""

    @property
    def n_samples(self) -> int:
        return len(next(iter(self.channels.values())).strain)

    @property
    def sample_interval(self) -> float:
        return 1.0 / self.sample_rate

    @property
    def duration(self) -> float:
        return self.n_samples / self.sample_rate

    @property
    def time(self) -> np.ndarray:
        """Time of each sample on the record's time base (s)."""
        return self.t0 + np.arange(self.n_samples) / self.sample_rate

    @property
    def has_hoop(self) -> bool:
        return "tube_hoop" in self.channels

    def strain(self, name: str) -> np.ndarray:
        """Strain of channel ``name``, compression positive."""
        return self.channels[name].strain
