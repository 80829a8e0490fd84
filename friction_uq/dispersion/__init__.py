"""Frequency-domain wave transport along elastic bars (docs/physics.md sections 2 and 7).

Everything that moves a strain wave along a bar goes through this package: the transport of the
gauge signals to the bar ends that touch the cell (section 2), the dispersion correction of those
signals (section 7, Tyas and Pope 2005) and the dispersive bar legs of the simulator.

Contents
--------
``pochhammer_phase_velocity_ratio``
    c/c0 of the first longitudinal mode of a solid elastic cylinder, from the Pochhammer-Chree
    frequency equation solved by root bracketing along the first-mode branch.
``phase_velocity_curve``
    Cached table (d/Lambda, c/c0) of that branch for one Poisson ratio, for interpolation.
``phase_velocity``
    Phase velocity (m/s) against frequency (Hz) for a solid bar (exact first mode) or a hollow bar
    (Love estimate, an approximation valid well below the tube's ring frequency).
``first_mode_cutoff``
    Frequency (Hz) above which the first-mode correction is not trusted (d/Lambda = 0.6; for a
    hollow bar also at most 0.6 of its ring frequency).
``delay``
    Exact fractional (sub-sample) delay by a phase ramp on the zero-padded FFT.
``propagate``
    The wave as it reads a signed distance further along its direction of travel, with or without
    dispersion.

Conventions
-----------
SI units throughout: seconds, metres, hertz, m/s. c0 = sqrt(E / rho) is the one-dimensional bar
velocity. A wave travelling in +z with phase velocity c_p(f) is transported over a distance z by
multiplying each bin of ``numpy.fft.rfft`` by exp(-i 2 pi f z / c_p(f)), so that a non-dispersive
bar gives out(t) = in(t - z / c0). Negative z brings a wave back towards where it came from (the
correction of a gauge signal to the bar end it travelled from).

Not implemented
---------------
The amplitude factor M1 of Tyas and Wilson (2001), which converts the surface strain of a gauge to
the mean stress over the section at each frequency, is **not** implemented: only the phase of each
bin is corrected (and bins beyond the first-mode cut-off are removed). M1 tends to 1 at low
frequency; the error of leaving it out grows towards the cut-off.
"""

from .hollow import RING_FREQUENCY_FRACTION
from .phase import first_mode_cutoff, phase_velocity
from .pochhammer import (
    CURVE_MAX_D_OVER_LAMBDA,
    CUTOFF_D_OVER_LAMBDA,
    phase_velocity_curve,
    pochhammer_phase_velocity_ratio,
)
from .transport import CUTOFF_TAPER_FRACTION, delay, propagate

__all__ = [
    "CURVE_MAX_D_OVER_LAMBDA",
    "CUTOFF_D_OVER_LAMBDA",
    "CUTOFF_TAPER_FRACTION",
    "RING_FREQUENCY_FRACTION",
    "delay",
    "first_mode_cutoff",
    "phase_velocity",
    "phase_velocity_curve",
    "pochhammer_phase_velocity_ratio",
    "propagate",
]
