"""The field's deterministic identification: f from eq. 17 over the stationary window, for a given nu.

This is the lab's analysis (a point estimate for an assumed nu), kept as a reference and as the
starting point of the Bayesian one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .force_noise import MeanForces, mean_forces
from .forces import Forces, compute_forces
from .physics import cell
from .errors import NoStationaryPhase, SignalError
from .gauge_balance import NOISE_SIGMAS, GaugeFinding, attributed_over_window, gauge_findings
from .gauge_check import flat_run_findings
from .gauge_scale import gauge_and_speed, scale_findings
from .record import Record
from .signals import moving_average
from .window import (
    StationaryData,
    Window,
    WindowCriterion,
    find_stationary_window,
    stationary_data,
    window_from_times,
)


@dataclass(frozen=True)
class Prepared:
    """A record processed up to the stationary phase."""

    record: Record
    forces: Forces
    window: Window
    data: StationaryData
    #: What the gauge checks found, each with its kind (:class:`~friction_uq.gauge_balance.GaugeFinding`): a gauge's
    #: balance or scale, a balance the noise leaves unchecked, the window found from the ratio alone ("window"), a
    #: peak on one value that may be a saturated digitiser ("flat"), the striker's recorded speed ("striker").
    findings: tuple[GaugeFinding, ...] = ()

    def _said(self, keep) -> tuple[str, ...]:
        return tuple(g.sentence for g in self.findings if keep(g.kind))

    @property
    def gauge_notes(self) -> tuple[str, ...]:
        """The sentences of the gauges' balance and scale, and of the window they left (not "flat" nor "striker")."""
        return self._said(lambda kind: kind not in ("flat", "striker"))

    @property
    def flat_runs(self) -> tuple[str, ...]:
        """The sentences of peaks on one value that may be a saturated digitiser."""
        return self._said(lambda kind: kind == "flat")

    @property
    def speed_notes(self) -> tuple[str, ...]:
        """The sentence of an incident wave at odds with striker_velocity while the gauges agree."""
        return self._said(lambda kind: kind == "striker")


def prepare(
    record: Record,
    *,
    window: tuple[float, float] | None = None,
    dispersion: bool = False,
    criterion: WindowCriterion = WindowCriterion(),
) -> Prepared:
    """Forces, stationary window (automatic unless ``window`` is given, in seconds) and likelihood data."""
    forces = compute_forces(record, dispersion=dispersion)
    findings = gauge_findings(forces, record.apparatus)
    wired = [g for g in findings if g.kind in ("reversed", "swapped")]
    if wired:  # a wiring fault: the record is to be mended at its source, not analysed
        raise SignalError(f"{record.path}: {wired[0].sentence}")
    # a channel's scale off by a factor (a gauge factor, a unit: eq. 5, 6 and 14): an output channel's moves f itself
    # (refused from ten times, :func:`_refuse_an_output_scale`; a warning below); the input bar's, or one every channel
    # shares, leaves f's ratio as it is but not the forces, the pressure and the velocity: said, as the balance's are
    scaled, speed = gauge_and_speed(scale_findings(forces, record.apparatus, striker_velocity=record.striker_velocity))
    notes = tuple(findings + scaled)
    if window is None:
        win, notes = _automatic_window(record, forces, criterion, notes)
    else:
        try:
            win = window_from_times(forces, *window)
        except SignalError as exc:
            raise SignalError(f"{record.path}: the window given by hand (--window) {exc}") from None
    notes = attributed_over_window(notes, forces, record.apparatus, win.slice)
    _refuse_an_output_scale(record, scaled)
    data = stationary_data(
        forces, record.apparatus, win, test_id=record.test_id, campaign=record.campaign,
        striker_velocity=record.striker_velocity,
    )
    _check_polarity(record, forces, win)
    return Prepared(record, forces, win, data, notes + flat_run_findings(record) + tuple(speed))


#: An output channel's scale off by this factor or more (an order of magnitude: a unit, a decade of gain, not a gauge
#: factor or a gain's drift) leaves no f to warn about: the record is refused. Below it the finding is a warning, as
#: strongly coloured noise on a short pre-trigger can still make a sound external bar look a few times off (one A-03
#: draw of 40 at lag-1 0.995: "5.24 times too small").
REFUSED_SCALE = 10.0


def _refuse_an_output_scale(record: Record, scaled: list[GaugeFinding]) -> None:
    """An output channel off by :data:`REFUSED_SCALE` or more (:func:`~friction_uq.gauge_scale.scale_findings`) moves
    eq. 17's ratio, f's own, by that factor: refused, naming the channel and the fix (checked once the window is
    found, so that a record without a stationary phase is refused for that)."""
    off = [g for g in scaled if g.kind == "scale" and g.channel in ("internal_output_bar", "external_output_bar")
           and g.restoring_factor is not None and abs(math.log10(g.restoring_factor)) >= math.log10(REFUSED_SCALE)]
    if off:
        raise SignalError(f"{record.path}: {off[0].sentence}; f reads the output forces' ratio, which that channel's "
                          "scale moves by the same factor")


#: The note said when the window was found from the force ratio alone (a finding of kind "window").
RATIO_WINDOW_NOTE = ("the window was found from the force ratio alone: the sample's ends do not move together by "
                     "the gauges (eq. 6)")


def _automatic_window(record: Record, forces, criterion: WindowCriterion,
                      notes: tuple[GaugeFinding, ...]) -> tuple[Window, tuple[GaugeFinding, ...]]:
    """The automatic window; when a gauge's balance is off, found without the ends' velocities (which
    the suspect gauge enters) rather than refused as "no stationary phase"; every refusal names the file."""
    try:
        return find_stationary_window(forces, record.apparatus, criterion), notes
    except NoStationaryPhase as exc:
        if not notes:
            raise NoStationaryPhase(f"{record.path}: {exc}") from None
        try:
            win = find_stationary_window(forces, record.apparatus, criterion, velocity=False)
        except NoStationaryPhase:
            raise NoStationaryPhase(
                f"{record.path}: {notes[0].sentence}; no stationary phase either way: {exc}") from None
    suspect = "" if all(g.kind == "unchecked" for g in notes) else ", as the suspect gauge makes them"
    return win, notes + (GaugeFinding("", "window", RATIO_WINDOW_NOTE + suspect),)


def _check_polarity(record: Record, forces: Forces, win: Window) -> None:
    """Refuse an output force that is negative (tensile) over the window beyond :data:`NOISE_SIGMAS` of its noise
    (:func:`friction_uq.force_noise.mean_forces`, as the gauge check over the loading weighs it).

    Friction and the transmitted load can only push: a negative stationary force means a gauge
    wired or converted with the wrong sign.
    """
    means = mean_forces(forces, record.apparatus, win.slice)
    for name, channel, mean, se in (("F_eo", "external_output_bar", means.F_eo, means.sd_eo),
                                    ("F_io", "internal_output_bar", means.F_io, means.sd_io)):
        if mean < -NOISE_SIGMAS * se:
            raise SignalError(
                f"{record.path}: /signals/{channel}: {name} is tensile over the stationary window (mean "
                f"{mean:.0f} N, standard error {se:.0f} N): the gauge looks reversed; check its wiring, "
                "its sign convention (elongation positive) or its strain_per_volt"
            )


@dataclass(frozen=True)
class Identification:
    """Deterministic results over the window (SI units); series are on ``time``."""

    nu: float
    window: tuple[float, float]
    ratio: float
    f: float
    kappa: float
    p_mean: float
    p_mean_approx: float
    p_min: float
    p_max: float
    tau_mean: float
    V: float
    F_io: float
    F_eo: float
    equilibrium_error: float
    stationarity_error: float
    time: np.ndarray
    f_series: np.ndarray
    means: MeanForces | None = None  # the forces' means over the window and their noise (the equilibrium's check)

    @property
    def equilibrium_sd(self) -> float:
        """The gauges' noise in :attr:`equilibrium_error` (:attr:`MeanForces.balance_sd`); 0 without the means."""
        return self.means.balance_sd if self.means is not None else 0.0

    def series_json(self, *, points: int = 50) -> dict:
        """f(t) over the window, decimated to about ``points`` values (it is smoothed over 10 us)."""
        step = max(1, len(self.time) // points)
        return {
            "time": [float(f"{v:.7g}") for v in self.time[::step]],
            "f": [float(f"{v:.5g}") for v in self.f_series[::step]],
        }

    def to_json(self) -> dict:
        """The keys of ``friction-uq analyze --json`` (SI units)."""
        return {
            "f": self.f,
            "f_series": self.series_json(),
            "ratio": self.ratio,
            "kappa": self.kappa,
            "nu": self.nu,
            "p_mean": self.p_mean,
            "p_mean_approx": self.p_mean_approx,
            "p_min": self.p_min,
            "p_max": self.p_max,
            "tau_mean": self.tau_mean,
            "V": self.V,
            "F_io": self.F_io,
            "F_eo": self.F_eo,
            "equilibrium_error": self.equilibrium_error,
            "equilibrium_error_noise_sd": self.equilibrium_sd,
            "stationarity_error": self.stationarity_error,
            "window": list(self.window),
        }


def identify(prepared: Prepared, *, nu: float) -> Identification:
    """f (eq. 17), p_min, p_max (eq. 19), p_mean (eq. 20 and its approximation eq. 21), tau_mean (eq. 18), V (eq. 7).

    Means are taken over the window; the ratio is the ratio of the mean forces (noise in F_io
    would bias a mean of ratios), and so are the equilibrium (eq. 5) and stationarity (eq. 6) errors
    (a mean of (F_i - F_io - F_eo) / F_i divides by F_i's noise, which strongly coloured noise on a
    short pre-trigger makes a fair share of F_i); the equilibrium error's noise from
    :func:`friction_uq.force_noise.mean_forces`.
    """
    if not 0.0 < nu < 0.5:
        raise ValueError(f"nu must lie in (0, 0.5), got {nu!r}")
    fo, win = prepared.forces, prepared.window
    app = prepared.record.apparatus
    R, L = app.sample.radius, app.sample.length
    seg = win.slice
    means = mean_forces(fo, app, seg)
    F_io, F_eo = means.F_io, means.F_eo
    ratio = F_eo / F_io
    f = float(cell.friction_from_ratio(ratio, nu, radius=R, length=L))
    tau = float(cell.mean_friction_stress(F_eo, radius=R, length=L))
    p_min = float(cell.pressure_min(F_io, nu, radius=R))
    p_max = float(cell.pressure_max(F_io, F_eo, nu, radius=R))
    smooth = max(1, int(round(10e-6 * prepared.record.sample_rate)))
    with np.errstate(divide="ignore", invalid="ignore"):
        r_t = moving_average(fo.F_eo[seg], smooth) / moving_average(fo.F_io[seg], smooth)
    return Identification(
        nu=nu,
        window=(win.t0, win.t1),
        ratio=ratio,
        f=f,
        kappa=float(cell.kappa(f, nu)),
        p_mean=tau / f if f > 0 else float("nan"),
        p_mean_approx=0.5 * (p_min + p_max),
        p_min=p_min,
        p_max=p_max,
        tau_mean=tau,
        V=float(np.mean(fo.V[seg])),
        F_io=F_io,
        F_eo=F_eo,
        equilibrium_error=1.0 - means.balance,
        means=means,
        stationarity_error=1.0 - float(np.mean(fo.V_io[seg])) / float(np.mean(fo.V_i[seg])),
        time=np.array(fo.time[seg]),
        f_series=np.asarray(cell.friction_from_ratio(np.clip(r_t, -0.999, None), nu, radius=R, length=L)),
    )
