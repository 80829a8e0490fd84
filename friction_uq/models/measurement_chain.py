"""What a gauge's measurement chain does to the strain the gauge sees: the bridge's calibration (a gain),
the amplifier's bandwidth (a first-order low-pass), the channel's timing (the gauge's position or the
digitiser's trigger: the channel reads late or early) and the zero drifting through the record
(docs/physics.md, section 5: the catalogue's measurement-chain faults).

Each is a small pure function on the record's uniform time grid; :class:`Reading` chains them in the
order of the hardware (gauge -> bridge -> amplifier -> digitiser). Strain in, strain out, compression
positive; times in s. With every parameter at its neutral value (gain 1, drift 0, delay 0, time
constant 0) the reading is the strain itself, and each function is continuous in its parameter
through that value (the delay piecewise linear between whole samples), so that a fit can start from
the exact chain and move away from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal


def delayed(time: np.ndarray, strain: np.ndarray, delay: float) -> np.ndarray:
    """The strain read ``delay`` seconds late: the value at ``t`` is the strain of ``t - delay`` (linear
    interpolation between samples, the first and last values held beyond the record). A negative delay reads
    early. A gauge cemented ``dx`` further from the interface than the header says reads ``dx / c`` late."""
    if delay == 0.0:
        return np.asarray(strain, float)
    return np.interp(time - delay, time, strain)


def low_passed(time: np.ndarray, strain: np.ndarray, time_constant: float) -> np.ndarray:
    """The strain through a first-order low-pass of time constant ``time_constant`` (s; the -3 dB frequency
    is 1 / (2 pi time_constant)): y' = (x - y) / time_constant, solved exactly for the strain interpolated
    linearly between samples (as :func:`delayed` reads it, so that neither leads the other by half a sample),
    started at rest on the first sample (a record starts before the waves). A time constant of 0 passes the
    strain unchanged, and the output tends to it as the time constant does. An amplifier of higher order with
    the same -3 dB frequency delays a front by about as much; the fitted time constant is that of the
    equivalent first-order chain.

    With a = exp(-dt / tau) and r = tau / dt: y[n] = a y[n-1] + (1 - r (1 - a)) x[n] + (r (1 - a) - a) x[n-1]
    (the particular solution x - tau x' of a linear input, plus the decay of the rest)."""
    x = np.asarray(strain, float)
    if time_constant <= 0.0:
        return x
    dt = float(time[1] - time[0])
    a = float(np.exp(-dt / time_constant))
    c = (time_constant / dt) * (1.0 - a)
    b, den = [1.0 - c, c - a], [1.0, -a]
    zi = signal.lfilter_zi(b, den) * x[0]
    return signal.lfilter(b, den, x, zi=zi)[0]


def zero_drift(time: np.ndarray, rate: float) -> np.ndarray:
    """A zero drifting at ``rate`` (strain per second) from the record's first sample: bridge warming,
    amplifier drift, an AC-coupled channel's slow decay seen over a record of a millisecond or two."""
    return rate * (np.asarray(time, float) - float(time[0]))


@dataclass
class Reading:
    """One gauge's measurement chain (module docstring); edited in place by a mechanism's ``apply``."""

    gain: float = 1.0
    drift: float = 0.0  # strain / s
    delay: float = 0.0  # s
    time_constant: float = 0.0  # s

    def applied(self, time: np.ndarray, strain: np.ndarray) -> np.ndarray:
        """What the channel records when the gauge sees ``strain``."""
        seen = low_passed(time, strain, self.time_constant)
        return self.gain * delayed(time, seen, self.delay) + zero_drift(time, self.drift)

    @property
    def exact(self) -> bool:
        return self.gain == 1.0 and self.drift == 0.0 and self.delay == 0.0 and self.time_constant == 0.0
