"""The stationary phase: where it is, and the data the likelihood sees inside it.

Criterion (documented in README.md). A sample time t is *steady* when, over the evaluation span
``span`` (40 us by default) centred on t, all of these hold:

1. the cell is loaded: F_io(t) >= ``load_fraction`` (0.5) of its largest value;
2. the force ratio F_eo/F_io (smoothed over ``smooth`` = 10 us) changes across the span by less
   than ``sigmas`` (3) times its noise, or by less than ``ratio_tol`` (3 %) of itself, whichever
   is larger: the friction does not evolve;
3. the sample's ends move together (eq. 6): the smoothed |V_i - V_io| is within ``sigmas`` times
   its noise, or within ``velocity_tol`` (5 %) of V_io.

Isolated unsteady instants shorter than ``max_gap`` (10 us) between steady runs are noise
excursions (thousands of instants are tested, so a 3-sigma test fails by chance a few times):
they are closed. Within the longest steady run, the window is then the longest stretch in which the
smoothed ratio stays inside a band of +- ``band_sigmas`` (4) times its noise or ``ratio_tol``,
whichever is larger (a slow drift passes the local test but not this one; 4 sigma because a
plateau of pure noise holds some 40 independent 10 us averages, whose range reaches about
+- 2.7 sigma). It must be at least ``min_duration`` (50 us) long; otherwise the record has no stationary phase and is refused. The noise of each smoothed
quantity is propagated from the channels' pre-pulse noise (standard deviation and AR(1)
coefficient).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import NoStationaryPhase, SignalError
from .forces import Forces
from .record import Apparatus, Tube
from .signals import moving_average
from .stats.ar1 import ar1_mean_sd
from .stats.robust import longest_true_run


@dataclass(frozen=True)
class WindowCriterion:
    """Parameters of the stationary-phase criterion (see the module docstring)."""

    smooth: float = 10e-6
    span: float = 40e-6
    load_fraction: float = 0.5
    sigmas: float = 3.0
    ratio_tol: float = 0.03
    velocity_tol: float = 0.05
    min_duration: float = 50e-6
    max_gap: float = 10e-6
    band_sigmas: float = 4.0


@dataclass(frozen=True)
class Window:
    """A time window [t0, t1] (s) on the record's time base, and its sample indices [i0, i1)."""

    t0: float
    t1: float
    i0: int
    i1: int
    automatic: bool

    @property
    def duration(self) -> float:
        return self.t1 - self.t0

    @property
    def slice(self) -> slice:
        return slice(self.i0, self.i1)


def steady_mask(forces: Forces, apparatus: Apparatus, criterion: WindowCriterion = WindowCriterion()) -> np.ndarray:
    """Boolean array: True where the record is steady by the criterion of this module."""
    return _steadiness(forces, apparatus, criterion)[0]


def _steadiness(
    forces: Forces, apparatus: Apparatus, criterion: WindowCriterion, *, velocity: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady mask, smoothed ratio and the half-width of its steadiness band at each time
    (``velocity=False``: without criterion 3, for a record whose internal gauge is suspect)."""
    t = forces.time
    fs = 1.0 / (t[1] - t[0])
    w = max(1, int(round(criterion.smooth * fs)))
    half = max(1, int(round(criterion.span * fs / 2)))
    ch = forces.channels
    io, eo, ib = apparatus.internal_output_bar, apparatus.external_output_bar, apparatus.input_bar

    valid = np.isfinite(forces.F_io) & np.isfinite(forces.F_eo) & np.isfinite(forces.V_i)
    F_io = np.where(valid, forces.F_io, 0.0)
    F_eo = np.where(valid, forces.F_eo, 0.0)
    fio_s = moving_average(F_io, w)
    feo_s = moving_average(F_eo, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        r_s = feo_s / fio_s
    sd_io = io.area * io.young_modulus * ch["internal_output_bar"].noise.sd
    sd_eo = eo.area * eo.young_modulus * ch["external_output_bar"].noise.sd
    k_io = ar1_mean_sd(1.0, ch["internal_output_bar"].noise.rho_eff, w)
    k_eo = ar1_mean_sd(1.0, ch["external_output_bar"].noise.rho_eff, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        sd_r = np.sqrt((sd_eo * k_eo) ** 2 + (r_s * sd_io * k_io) ** 2) / np.abs(fio_s)

    loaded = valid & (F_io >= criterion.load_fraction * np.nanmax(np.where(valid, F_io, np.nan)))

    n = len(t)
    idx = np.arange(n)
    lo = np.clip(idx - half, 0, n - 1)
    hi = np.clip(idx + half, 0, n - 1)
    dr = np.abs(r_s[hi] - r_s[lo])
    tol_r = np.maximum(criterion.sigmas * math.sqrt(2.0) * sd_r[idx], criterion.ratio_tol * np.abs(r_s))
    ratio_ok = dr <= tol_r

    V_i = np.where(valid, forces.V_i, 0.0)
    V_io = np.where(valid, forces.V_io, 0.0)
    dv_s = moving_average(V_i - V_io, w)
    vio_s = moving_average(V_io, w)
    sd_dv = math.hypot(
        ib.wave_speed * math.sqrt(2.0) * ar1_mean_sd(ch["input_bar"].noise.sd, ch["input_bar"].noise.rho_eff, w),
        io.wave_speed * ch["internal_output_bar"].noise.sd * k_io,
    )
    vel_ok = np.abs(dv_s) <= np.maximum(criterion.sigmas * sd_dv, criterion.velocity_tol * np.abs(vio_s))

    # a time is steady when the whole span around it is loaded and valid
    loaded_span = np.convolve(loaded.astype(int), np.ones(2 * half + 1, int), mode="same") == 2 * half + 1
    band = np.maximum(criterion.band_sigmas * sd_r, criterion.ratio_tol * np.abs(r_s))
    return loaded_span & ratio_ok & (vel_ok if velocity else True), r_s, band


def _longest_banded(values: np.ndarray, half_width: float) -> tuple[int, int]:
    """Longest [i, j) with max - min of ``values`` <= 2 half_width (two pointers, monotone deques)."""
    from collections import deque

    best = (0, 0)
    lo_q: deque[int] = deque()
    hi_q: deque[int] = deque()
    i = 0
    for j, v in enumerate(values):
        while hi_q and values[hi_q[-1]] <= v:
            hi_q.pop()
        hi_q.append(j)
        while lo_q and values[lo_q[-1]] >= v:
            lo_q.pop()
        lo_q.append(j)
        while values[hi_q[0]] - values[lo_q[0]] > 2.0 * half_width:
            i += 1
            if hi_q[0] < i:
                hi_q.popleft()
            if lo_q[0] < i:
                lo_q.popleft()
        if j + 1 - i > best[1] - best[0]:
            best = (i, j + 1)
    return best


def _close_gaps(mask: np.ndarray, max_gap: int) -> np.ndarray:
    """Fill runs of False no longer than ``max_gap`` that have True on both sides."""
    out = mask.copy()
    padded = np.concatenate(([1], mask.astype(np.int8), [1]))
    edges = np.flatnonzero(np.diff(padded))
    for a, b in zip(edges[0::2], edges[1::2]):  # runs of False: [a, b)
        if 0 < a and b < len(mask) and b - a <= max_gap:
            out[a:b] = True
    return out


def find_stationary_window(
    forces: Forces, apparatus: Apparatus, criterion: WindowCriterion = WindowCriterion(), *, velocity: bool = True,
) -> Window:
    """The longest steady run of the record (see module docstring); ``velocity=False`` leaves out
    criterion 3 (the ends' velocities, which a gain error of the internal gauge breaks).

    Raises
    ------
    NoStationaryPhase
        If no steady run lasts ``criterion.min_duration``.
    """
    t = forces.time
    dt = t[1] - t[0]
    steady, r_s, band = _steadiness(forces, apparatus, criterion, velocity=velocity)
    mask = _close_gaps(steady, int(round(criterion.max_gap / dt)))
    i0, i1 = longest_true_run(mask)
    if i1 > i0:
        a, b = _longest_banded(r_s[i0:i1], float(np.median(band[i0:i1])))
        i0, i1 = i0 + a, i0 + b
    if (i1 - i0) * dt < criterion.min_duration:
        raise NoStationaryPhase(
            f"no stationary phase: the longest run where F_eo/F_io and V_i - V_io stay steady within "
            f"their noise lasts {(i1 - i0) * dt * 1e6:.1f} us, less than the {criterion.min_duration * 1e6:.0f} us "
            "required; give a window by hand with --window T0:T1 if you know one"
        )
    return Window(float(t[i0]), float(t[i1 - 1]), i0, i1, automatic=True)


def window_from_times(forces: Forces, t0: float, t1: float) -> Window:
    """A window given by hand (seconds on the record's time base), checked against the valid waves; a refusal starts
    with the times (its caller names the record and the option)."""
    t = forces.time
    if not t1 > t0:
        raise SignalError(f"{t0}:{t1} s: T1 must be after T0")
    if t0 < t[0] or t1 > t[-1]:
        raise SignalError(f"{t0}:{t1} s lies outside the record ({t[0]:.6g} to {t[-1]:.6g} s)")
    i0 = int(np.searchsorted(t, t0))
    i1 = int(np.searchsorted(t, t1, side="right"))
    seg = slice(i0, i1)
    if i1 - i0 < 8:
        raise SignalError(f"{t0}:{t1} s holds {i1 - i0} samples, at least 8 are needed")
    for name, arr in (("F_io", forces.F_io), ("F_eo", forces.F_eo)):
        if not np.all(np.isfinite(arr[seg])):
            raise SignalError(
                f"{t0}:{t1} s reaches outside the time where {name} is valid (after the bar's "
                "far-end echo reaches the gauge)"
            )
    if np.mean(forces.F_io[seg]) < 0.2 * np.nanmax(forces.F_io):
        raise SignalError(
            f"{t0}:{t1} s: the cell is not loaded there (mean F_io {np.mean(forces.F_io[seg]):.0f} N, "
            f"less than 20 % of its peak {np.nanmax(forces.F_io):.0f} N)"
        )
    return Window(float(t[i0]), float(t[i1 - 1]), i0, i1, automatic=False)


@dataclass(frozen=True)
class StationaryData:
    """What a likelihood sees: the stationary-phase force signals and their noise. SI units.

    Noise of the forces comes from each output bar's pre-pulse segment (the gauge at rest, before
    any wave): sd = A E sd(strain); rho = the effective AR(1) coefficient of that segment (same
    long-run variance, :class:`~friction_uq.signals.NoiseEstimate`). ``sd_offset_*`` are the
    standard errors of the offsets removed (the segment means): one constant error per channel
    over the whole window, which the likelihood integrates out.

    ``hoop`` is the tube gauge's strain in the package's convention (compression positive, so it
    is negative while the tube swells), baseline removed. ``slip`` is the sample's sliding
    displacement relative to the tube since the start of loading (m), from eq. 7.
    """

    test_id: str
    campaign: str
    time: np.ndarray
    F_io: np.ndarray
    F_eo: np.ndarray
    V: np.ndarray
    slip: np.ndarray
    sd_io: float
    sd_eo: float
    rho_io: float
    rho_eo: float
    radius: float
    length: float
    tube: Tube
    window: tuple[float, float]
    sample_rate: float
    hoop: np.ndarray | None = None
    sd_hoop: float | None = None
    rho_hoop: float | None = None
    striker_velocity: float | None = None
    sd_offset_io: float = 0.0
    sd_offset_eo: float = 0.0
    sd_offset_hoop: float = 0.0

    @property
    def n(self) -> int:
        return len(self.time)


def stationary_data(
    forces: Forces, apparatus: Apparatus, window: Window, *, test_id: str = "", campaign: str = "",
    striker_velocity: float | None = None,
) -> StationaryData:
    """Cut the stationary phase out of ``forces`` for a likelihood."""
    seg = window.slice
    t = forces.time
    dt = t[1] - t[0]
    V = np.nan_to_num(forces.V, nan=0.0)
    start = forces.loading_start
    V = np.where(t >= start, V, 0.0)
    slip = np.cumsum(V) * dt
    io, eo = apparatus.internal_output_bar, apparatus.external_output_bar
    ch = forces.channels
    hoop = sd_h = rho_h = None
    if forces.hoop is not None:
        hoop = np.array(forces.hoop[seg])
        sd_h = ch["tube_hoop"].noise.sd
        rho_h = ch["tube_hoop"].noise.rho_eff
    return StationaryData(
        test_id=test_id,
        campaign=campaign,
        time=np.array(t[seg]),
        F_io=np.array(forces.F_io[seg]),
        F_eo=np.array(forces.F_eo[seg]),
        V=np.array(forces.V[seg]),
        slip=np.array(slip[seg]),
        sd_io=io.area * io.young_modulus * ch["internal_output_bar"].noise.sd,
        sd_eo=eo.area * eo.young_modulus * ch["external_output_bar"].noise.sd,
        rho_io=ch["internal_output_bar"].noise.rho_eff,
        rho_eo=ch["external_output_bar"].noise.rho_eff,
        radius=apparatus.sample.radius,
        length=apparatus.sample.length,
        tube=apparatus.tube,
        window=(window.t0, window.t1),
        sample_rate=1.0 / dt,
        hoop=hoop,
        sd_hoop=sd_h,
        rho_hoop=rho_h,
        striker_velocity=striker_velocity,
        sd_offset_io=io.area * io.young_modulus * ch["internal_output_bar"].noise.offset_sd,
        sd_offset_eo=eo.area * eo.young_modulus * ch["external_output_bar"].noise.offset_sd,
        sd_offset_hoop=ch["tube_hoop"].noise.offset_sd if forces.hoop is not None else 0.0,
    )
