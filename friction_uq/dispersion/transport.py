"""Frequency-domain transport of a strain wave along a bar, with or without dispersion.

``delay`` is an exact fractional (sub-sample) delay by a phase ramp on the zero-padded FFT;
``propagate`` gives the wave as it reads a signed distance further along its direction of travel
(docs/physics.md sections 2 and 7).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from ._checks import check_finite, check_positive
from .phase import first_mode_cutoff, phase_velocity

#: Width of the raised-cosine taper that removes the bins near the cut-off, as a fraction of the
#: cut-off frequency: the weight is 1 up to (1 - fraction) f_c and falls smoothly to 0 at f_c.
CUTOFF_TAPER_FRACTION = 0.1


def _padded_length(n: int, pad_factor: float) -> int:
    """Odd fast FFT length >= pad_factor * n.

    Odd so that there is no Nyquist bin: every phase factor then acts on a conjugate pair of bins,
    and delays compose exactly (d1 then d2 equals d1 + d2 on the padded circle).
    """
    target = max(int(math.ceil(pad_factor * n)), n, 1)
    m = scipy.fft.next_fast_len(target, real=False)
    while m % 2 == 0:
        m = scipy.fft.next_fast_len(m + 1, real=False)
    return int(m)


def _prepare_signal(signal: ArrayLike, sample_interval: float, pad_factor: float) -> tuple[np.ndarray, float, int]:
    x = np.asarray(signal, dtype=np.float64)
    if x.ndim == 0 or x.shape[-1] == 0:
        raise ValueError(f"signal must be an array with at least one sample along its last axis, received shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"signal must be finite, received {int(np.sum(~np.isfinite(x)))} non-finite sample(s)")
    dt = check_positive("sample_interval", sample_interval)
    try:
        pf = float(pad_factor)
    except (TypeError, ValueError):
        raise ValueError(f"pad_factor must be a finite number >= 1, received {pad_factor!r}") from None
    if not math.isfinite(pf) or pf < 1.0:
        raise ValueError(f"pad_factor must be a finite number >= 1, received {pad_factor!r}")
    return x, dt, _padded_length(x.shape[-1], pf)


def _apply_transfer(x: np.ndarray, length: int, transfer: np.ndarray) -> np.ndarray:
    spectrum = np.fft.rfft(x, n=length, axis=-1)
    out = np.fft.irfft(spectrum * transfer, n=length, axis=-1)
    return np.ascontiguousarray(out[..., : x.shape[-1]], dtype=np.float64)


def _delay_padded(x: np.ndarray, dt: float, length: int, delay_s: float) -> np.ndarray:
    k = np.arange(length // 2 + 1, dtype=float)
    # phase in cycles, reduced modulo 1 before exp for precision at large k
    cycles = np.mod(k * (delay_s / (dt * length)), 1.0)
    return _apply_transfer(x, length, np.exp(-2j * np.pi * cycles))


def delay(signal: ArrayLike, *, sample_interval: float, delay: float) -> np.ndarray:
    """Exact fractional delay: out(t) = in(t - delay).

    The signal is zero-padded to an odd fast FFT length of at least twice its length
    (``scipy.fft.next_fast_len``), each bin of its ``numpy.fft.rfft`` is multiplied by
    exp(-i 2 pi f delay) and the inverse transform is cut back to the original length. No bin is
    dropped and the odd length leaves no Nyquist bin, so delays compose exactly and a delay followed
    by its opposite is the identity, for every signal that stays inside the record.

    The signal is assumed to be zero (baseline removed) at both ends; the mean is not removed.
    The zero padding avoids wrap-around as long as the signal does not move by more than the
    padding (at least the record length); what moves past either end of the record is lost.
    ``propagate`` with ``dispersive=False`` is this delay with delay = distance / c0 and a
    selectable padding. Non-integer delays act as band-limited (sinc) interpolation, so a signal with
    a step at an end of the record rings there.

    Parameters
    ----------
    signal : array_like
        Samples, time along the last axis.
    sample_interval : float
        Time between samples (s), > 0.
    delay : float
        Delay (s), any sign; negative values advance the signal.

    Returns
    -------
    numpy.ndarray
        Delayed signal, float64, same shape as ``signal``.

    Raises
    ------
    ValueError
        If the signal is empty or not finite, or a parameter is out of range.

    Examples
    --------
    >>> (delay([0.0, 1.0, 0.0, 0.0], sample_interval=1e-6, delay=1e-6).round(12) + 0.0).tolist()
    [0.0, 0.0, 1.0, 0.0]
    """
    x, dt, length = _prepare_signal(signal, sample_interval, 2)
    delay_s = check_finite("delay", delay)
    return _delay_padded(x, dt, length, delay_s)


def _cutoff_weight(frequency: np.ndarray, cutoff: float) -> np.ndarray:
    """Raised-cosine weight: 1 below (1 - CUTOFF_TAPER_FRACTION) f_c, 0 at and above f_c."""
    start = (1.0 - CUTOFF_TAPER_FRACTION) * cutoff
    u = np.clip((frequency - start) / (cutoff - start), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(np.pi * u))


def propagate(
    signal: ArrayLike,
    *,
    sample_interval: float,
    distance: float,
    c0: float,
    diameter: float | None = None,
    nu: float | None = None,
    inner_diameter: float = 0.0,
    dispersive: bool = False,
    pad_factor: float = 2,
) -> np.ndarray:
    """The wave as it reads ``distance`` metres further along its direction of travel.

    Non-dispersive bar (``dispersive=False``): out(t) = in(t - distance / c0), the exact
    sub-sample delay of ``delay`` (no bin dropped); ``diameter``, ``nu`` and ``inner_diameter``
    are ignored.

    Dispersive bar (``dispersive=True``, Tyas and Pope 2005): each bin of the zero-padded
    ``numpy.fft.rfft`` is multiplied by exp(-i 2 pi f distance / c_p(f)) with c_p from
    ``phase_velocity`` (first longitudinal mode; Love estimate for a hollow bar), and the bins near
    and beyond ``first_mode_cutoff`` are removed: their weight falls from 1 at
    0.9 f_c to 0 at f_c along a raised cosine (``CUTOFF_TAPER_FRACTION``), which avoids the ringing
    of a brick-wall cut. The output is therefore low-pass filtered at f_c; a forward transport
    followed by the backward one returns the original's content below the cut-off. The amplitude
    factor M1 (Tyas and Wilson 2001) is not applied.

    The signal is assumed to be zero (baseline removed) at both ends; its mean is not removed.
    Zero padding to an odd fast FFT length of at least ``pad_factor`` times the record length
    avoids wrap-around as long as the wave (including its dispersive tail) moves by less than the
    padding; what leaves the record is lost. With ``pad_factor=1`` there is (almost) no padding and
    the transport is circular.

    Parameters
    ----------
    signal : array_like
        Samples (any unit, typically strain), time along the last axis.
    sample_interval : float
        Time between samples (s), > 0.
    distance : float
        Signed distance along the direction of travel (m); negative brings a wave back to where
        it came from.
    c0 : float
        Bar velocity sqrt(E / rho) (m/s), > 0.
    diameter : float, optional
        Outer diameter of the bar (m); required when ``dispersive`` is True.
    nu : float, optional
        Poisson ratio of the bar; required when ``dispersive`` is True.
    inner_diameter : float, optional
        Bore diameter (m) of a hollow bar, 0 (default) for a solid bar.
    dispersive : bool, optional
        Apply first-mode dispersion (True) or a pure delay (False, default).
    pad_factor : float, optional
        Minimum padded length as a multiple of the record length, >= 1 (default 2).

    Returns
    -------
    numpy.ndarray
        Transported signal, float64, same shape as ``signal``.

    Raises
    ------
    ValueError
        If the signal is empty or not finite, a parameter is out of range, or ``dispersive`` is
        True without ``diameter`` and ``nu``.
    """
    x, dt, length = _prepare_signal(signal, sample_interval, pad_factor)
    z = check_finite("distance", distance)
    c0_v = check_positive("c0", c0)
    if not dispersive:
        return _delay_padded(x, dt, length, z / c0_v)
    if diameter is None or nu is None:
        raise ValueError(
            f"dispersive=True needs the bar's diameter (m) and nu, received diameter={diameter!r}, nu={nu!r}"
        )
    transfer = _dispersive_transfer(length, dt, z, c0_v, float(diameter), float(nu), float(inner_diameter))
    return _apply_transfer(x, length, transfer)


@functools.lru_cache(maxsize=64)
def _dispersive_transfer(length: int, dt: float, z: float, c0: float, diameter: float, nu: float,
                         inner_diameter: float) -> np.ndarray:
    """The bins' transfer factor of :func:`propagate` (dispersive): a forward model transports the same
    bars over the same distances at every call, so it is computed once per bar and distance (read-only)."""
    f = np.fft.rfftfreq(length, d=dt)
    cp = phase_velocity(f, c0=c0, diameter=diameter, nu=nu, inner_diameter=inner_diameter)
    cutoff = first_mode_cutoff(c0=c0, diameter=diameter, nu=nu, inner_diameter=inner_diameter)
    weight = _cutoff_weight(f, cutoff)
    cycles = np.mod(f * (z / cp), 1.0)
    out = weight * np.exp(-2j * np.pi * cycles)
    out.flags.writeable = False
    return out
