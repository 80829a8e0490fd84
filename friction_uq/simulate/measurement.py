"""Measurement chain: gauge gain, baseline offset, white and AR(1) noise, quantisation.

For each channel, in the fixed order of :data:`friction_uq.record.CHANNELS` (so a seed gives the
same noise on a channel whatever the other channels' settings):

    recorded = Q( gain * strain + offset + white * xi + e ),   e_k = phi e_{k-1} + s sqrt(1 - phi^2) eta_k

with xi, eta independent standard normal draws from the caller's ``numpy.random.Generator``,
e_0 = s eta_0 (the AR(1) process starts stationary, standard deviation s = ``ar1``, coefficient
phi = ``ar1_coef``) and Q rounding to a multiple of ``quantum`` (strain per digitiser count;
none when 0). All quantities are strains, compression positive; the units a channel is stored
in (strain, microstrain, V) are applied by :func:`friction_uq.record.write_record`. Both normal
sequences are drawn for every present channel even when their level is 0.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..noise import ar1_noise
from ..record import CHANNELS
from .config import ChannelSpec


def measure(clean: Mapping[str, np.ndarray], channels: Mapping[str, ChannelSpec],
            rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Recorded strains (compression positive) of the channels present in ``clean``."""
    out: dict[str, np.ndarray] = {}
    for name in CHANNELS:
        if name not in clean:
            continue
        spec = channels[name]
        x = np.asarray(clean[name], dtype=np.float64)
        white = rng.standard_normal(x.size) * spec.white
        coloured = ar1_noise(x.size, sd=spec.ar1, rho=spec.ar1_coef, rng=rng, start="first_draw")
        y = spec.gain * x + spec.offset + white + coloured
        if spec.quantum > 0.0:
            y = np.round(y / spec.quantum) * spec.quantum
        out[name] = y
    return out
