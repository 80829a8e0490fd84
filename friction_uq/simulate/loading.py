"""What drives the simulated test: the incident wave, at the input gauge and at the plug interface.

Two kinds of loading:

* the closed-form trapezoid of the striker (design and synthetic work), built inside
  :func:`friction_uq.simulate.model_1d.run_model` when no loading is given;
* a **measured** incident wave (:class:`Loading`), as the paper drove its ABAQUS model: the
  input-bar gauge's incident pulse, offset removed, read before the reflected wave reaches the
  gauge, and the same wave transported forward to the plug interface. The simulated test then
  answers the question "what would the other gauges read if the cell behaved as the model says,
  under the load that was actually applied?".

Both series are on the record's time grid and compression positive (strain).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Loading:
    """An incident wave on the record's time grid (strain, compression positive).

    Attributes
    ----------
    time : array, shape (n,)
        Record time base (s), uniform.
    at_gauge : array, shape (n,)
        The incident wave as the input-bar gauge reads it (zero once the reflected wave arrives).
    at_cell : array, shape (n,)
        The same wave at the plug interface (transported forward by the gauge distance).
    source : str
        ``"measured"`` or a description of a closed-form pulse.
    """

    time: np.ndarray
    at_gauge: np.ndarray
    at_cell: np.ndarray
    source: str = "measured"

    def __post_init__(self) -> None:
        n = len(self.time)
        if n < 2 or len(self.at_gauge) != n or len(self.at_cell) != n:
            raise ValueError(f"loading series must share the time grid of {n} samples")

    @property
    def sample_interval(self) -> float:
        return float(self.time[1] - self.time[0])

    def on_grid(self, t_fine: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(at_cell, at_gauge) linearly interpolated on a finer grid ``t_fine`` (zero outside the record)."""
        return (np.interp(t_fine, self.time, self.at_cell, left=0.0, right=0.0),
                np.interp(t_fine, self.time, self.at_gauge, left=0.0, right=0.0))
