"""Draws taken evenly through a chain: the same draws for the same input, every part of the chain kept alike."""

from __future__ import annotations

import numpy as np


def evenly_spaced(x: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` of ``x``'s draws (flattened, as float), evenly spaced through them; all of them when there
    are no more than ``n``. Arrays of one length give the same indices, so draws of several variables stay paired."""
    x = np.asarray(x, float).ravel()
    return x if x.size <= n else x[np.linspace(0, x.size - 1, n).round().astype(int)]
