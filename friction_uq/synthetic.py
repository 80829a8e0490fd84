"""Closed-form synthetic records: trapezoidal waves at the force levels of eq. 15-16.

The simplest record that is consistent with the paper's model: the incident wave is a trapezoid
of amplitude V_s / (2 C_i) (eq. 14); the two output forces follow the same trapezoid at their
stationary levels (eq. 15-16), the input force is their sum (eq. 5), so the reflected wave is
F_i / (A_i E_i) - eps_i (eq. 2) and the ends of the sample move together in the plateau (eq. 6).
The hoop gauge reads the Lame strain of the eq. 20 wall pressure, seen through the tube kernel
(docs/physics.md section 6) as the sample slides past it, plus the Poisson widening of the tube under
the axial friction load it carries at the gauge: the closed-form model's own prediction
(:class:`friction_uq.models.closed_form.HoopPrediction`) on the true histories. Noise is white plus AR(1), with offsets.

These records test the analysis against the paper's own model. The simulator
(:mod:`friction_uq.simulate`) adds the physics the model leaves out. Both write through
:func:`friction_uq.record.write_record`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from .models.closed_form import HoopPrediction
from .noise import white_and_ar1_noise
from .physics import bars, cell, design, tube
from .record import Apparatus, paper_apparatus, write_record


@dataclass(frozen=True)
class ClosedFormTest:
    """Parameters of a closed-form record (SI units)."""

    f: float = 0.05
    nu: float = 0.4
    striker_velocity: float = 10.0
    rise_time: float = 20e-6
    sample_rate: float = 5e6
    duration: float = 1.3e-3
    pretrigger: float = 80e-6
    noise_sd: Mapping[str, float] = field(
        default_factory=lambda: {
            "input_bar": 4e-6, "internal_output_bar": 3e-6, "external_output_bar": 2e-6, "tube_hoop": 2e-6,
        }
    )
    noise_rho: float = 0.5
    white_fraction: float = 0.3
    offsets: Mapping[str, float] = field(
        default_factory=lambda: {
            "input_bar": 1.5e-5, "internal_output_bar": -8e-6, "external_output_bar": 5e-6, "tube_hoop": -3e-6,
        }
    )
    gains: Mapping[str, float] = field(default_factory=dict)
    hoop: bool = True
    hoop_beta: float = tube.BETA_EFF_PAPER_TUBE
    #: Relative departure of the external output force from eq. 17's (the world's ratio is eq. 17's times
    #: 1 + ratio_error): the model-form error the stationary analysis allows for (likelihood.force_level).
    ratio_error: float = 0.0


def closed_form_strains(test: ClosedFormTest, apparatus: Apparatus) -> tuple[np.ndarray, dict[str, np.ndarray], dict]:
    """Noise-free gauge strains (compression positive) and the stationary truth.

    Returns
    -------
    time, strains, truth
    """
    a = apparatus
    ib, io, eo, tb = a.input_bar, a.internal_output_bar, a.external_output_bar, a.tube
    R, L = a.sample.radius, a.sample.length
    fs = test.sample_rate
    n = int(round(test.duration * fs))
    t0 = -test.pretrigger
    t = t0 + np.arange(n) / fs
    T = a.pulse_duration
    kw = dict(striker_velocity=test.striker_velocity, z_input=ib.impedance, z_internal=io.impedance, radius=R, length=L)
    F_io0 = float(design.stationary_internal_force(test.f, test.nu, **kw))
    F_eo0 = float(design.stationary_external_force(test.f, test.nu, **kw)) * (1.0 + test.ratio_error)
    eps_i0 = test.striker_velocity / (2.0 * ib.wave_speed)

    # time 0: incident front at the input gauge; the cell sees it d/c later
    t_cell = ib.gauge_delay

    def at_cell(tt: np.ndarray) -> np.ndarray:
        return bars.trapezoid_pulse(tt - t_cell, rise_time=test.rise_time, end=T)

    eps_inc = lambda tt: eps_i0 * at_cell(tt)  # noqa: E731 - incident wave at the interface
    F_io = lambda tt: F_io0 * at_cell(tt)  # noqa: E731
    F_eo = lambda tt: F_eo0 * at_cell(tt)  # noqa: E731
    eps_ref = lambda tt: (F_io(tt) + F_eo(tt)) / (ib.area * ib.young_modulus) - eps_inc(tt)  # noqa: E731

    strains = {
        "input_bar": eps_inc(t + ib.gauge_delay) + eps_ref(t - ib.gauge_delay),
        "internal_output_bar": F_io(t - io.gauge_delay) / (io.area * io.young_modulus),
        "external_output_bar": F_eo(t - eo.gauge_delay) / (eo.area * eo.young_modulus),
    }
    V = F_io(t) / io.impedance - F_eo(t) / eo.impedance  # eq. 7 with V = C eps on each bar
    slip = np.cumsum(V) / fs
    if test.hoop:
        # the closed form's hoop reading (eq. 8, 11-13, 20, the tube kernel and the tube's axial Poisson
        # term) on the true force and slip histories, a knot on every sample
        history = SimpleNamespace(tube=tb, radius=R, length=L, n=n, sample_rate=fs, F_io=F_io(t), slip=slip)
        hoop = HoopPrediction(history, smooth=0.0, knot_step=0.0, kernel_beta=test.hoop_beta)  # type: ignore[arg-type]
        strains["tube_hoop"] = hoop.predict(test.f, test.nu, 1.0)[0]
    truth = {
        "f": test.f, "nu": test.nu, "kappa": float(cell.kappa(test.f, test.nu)),
        "striker_velocity_true": test.striker_velocity, "F_io": F_io0, "F_eo": F_eo0,
        "ratio": F_eo0 / F_io0, "V": float(F_io0 / io.impedance - F_eo0 / eo.impedance),
        "p_mean": float(F_eo0 / (2 * math.pi * R * L * test.f)) if test.f > 0 else 0.0,
        "generator_model": "closed-form trapezoids (eq. 14-16)",
    }
    return t, strains, truth


def write_closed_form_record(
    path: str | os.PathLike[str],
    test: ClosedFormTest = ClosedFormTest(),
    *,
    seed: int,
    apparatus: Apparatus | None = None,
    test_id: str = "S-01",
    campaign: str = "S",
    units: Mapping[str, str] | None = None,
    strain_per_volt: Mapping[str, float] | None = None,
    strains_override: Mapping[str, np.ndarray] | None = None,
) -> Path:
    """Write a closed-form record with noise, offsets and gains; ``/truth`` holds what made it.

    ``strains_override`` replaces noise-free channels before noise is added (tests use it to
    break a record on purpose).
    """
    app = apparatus or paper_apparatus()
    rng = np.random.default_rng(seed)
    t, strains, truth = closed_form_strains(test, app)
    if strains_override:
        strains.update(strains_override)
    noisy: dict[str, np.ndarray] = {}
    for name, eps in strains.items():
        sd = test.noise_sd.get(name, 0.0)
        noise = white_and_ar1_noise(len(t), sd=sd, rho=test.noise_rho, white_fraction=test.white_fraction, rng=rng) \
            if sd > 0 else 0.0
        noisy[name] = test.gains.get(name, 1.0) * eps + noise + test.offsets.get(name, 0.0)
        truth[f"noise_sd_{name}"] = sd
    truth["noise_rho"] = test.noise_rho
    truth["white_fraction"] = test.white_fraction
    truth["seed"] = seed
    for k, g in test.gains.items():
        truth[f"gain_{k}"] = g
    return write_record(
        path,
        test_id=test_id,
        campaign=campaign,
        sample_rate=test.sample_rate,
        t0=float(t[0]),
        strains=noisy,
        apparatus=app,
        units=units,
        strain_per_volt=strain_per_volt,
        striker_velocity=test.striker_velocity,
        truth=truth,
        description="closed-form synthetic record (friction_uq.synthetic)",
    )


__all__ = ["ClosedFormTest", "closed_form_strains", "write_closed_form_record", "replace"]
