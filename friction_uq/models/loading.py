"""The measured incident wave of a record as the loading of a forward model."""

from __future__ import annotations

import numpy as np

from ..forces import Forces
from ..record import Record
from ..signals import baseline_free, transport, window_mask
from ..simulate.loading import Loading


def measured_loading(record: Record, forces: Forces, *, dispersion: bool = False) -> Loading:
    """The incident wave read on the input-bar gauge, offset removed, and transported to the plug.

    The gauge reads the incident pulse until the reflected wave comes back to it (2 d / c after
    the incident front, less 2 % of the pulse length); after that the series is zero. The wave is
    carried forward by the gauge distance with an exact sub-sample delay (an all-pass filter: the
    gauge noise keeps its spectrum), or with Pochhammer-Chree dispersion when ``dispersion``.
    """
    ib = record.apparatus.input_bar
    fs = record.sample_rate
    n = record.n_samples
    info = forces.channels["input_bar"]
    sep = info.arrival + 2.0 * ib.gauge_delay * fs - 0.02 * record.apparatus.pulse_duration * fs
    x = baseline_free(record.strain("input_bar"), info.noise)  # as the forces read it: no spike, no padding
    at_gauge = np.where(window_mask(n, info.noise.start, sep), x, 0.0)
    at_cell = transport(at_gauge, sample_interval=1.0 / fs, distance=ib.gauge_distance, wave_speed=ib.wave_speed,
                        diameter=ib.outer_diameter, inner_diameter=ib.inner_diameter,
                        poisson_ratio=ib.poisson_ratio, dispersion=dispersion)
    return Loading(time=record.time, at_gauge=at_gauge, at_cell=at_cell, source="measured")
