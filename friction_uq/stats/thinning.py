"""Draws taken evenly through a chain: the same draws for the same input, every part of the chain kept alike; and
the equal mixture of two posteriors made so."""

from __future__ import annotations

import numpy as np


def evenly_spaced(x: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` of ``x``'s draws (flattened, as float), evenly spaced through them; all of them when there
    are no more than ``n``. Arrays of one length give the same indices, so draws of several variables stay paired."""
    x = np.asarray(x, float).ravel()
    return x if x.size <= n else x[np.linspace(0, x.size - 1, n).round().astype(int)]


def equal_parts(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Draws of the equal mixture of two posteriors: as many of each, the smaller count, evenly spaced through each
    (two variables of one posterior, cut alike, stay paired); ``a``'s first."""
    n = min(np.size(a), np.size(b))
    return np.concatenate([evenly_spaced(a, n), evenly_spaced(b, n)])
