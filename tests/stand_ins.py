"""Stand-ins the rounds of ``diagnose`` read in place of fitted models, for tests that set block ELPDs by hand."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np


@dataclass
class StandInFit:
    """The parts of a :class:`~friction_uq.discrepancy.extended.ModelFit` that the rounds read."""

    label: str
    variants: tuple
    elpd: object
    f_effective: np.ndarray
    predicted: dict = field(default_factory=dict)
    fit: object = field(default_factory=lambda: SimpleNamespace(mode={"f": 0.05}))
