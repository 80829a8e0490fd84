"""Each physics option moves the records the way docs/physics.md section 5 says (one test per option)."""

from __future__ import annotations

import math
from dataclasses import replace
from types import MappingProxyType

import numpy as np
import pytest

from friction_uq.physics.cell import friction_from_ratio
from friction_uq.record import paper_apparatus
from friction_uq.simulate import ChannelSpec, SimulationConfig, run_model, simulate
from friction_uq.simulate.friction import LAWS, shear_strength

NU, R, L = 0.4, 0.005, 0.010


def config(law: str = "coulomb", **kw: object) -> SimulationConfig:
    params = kw.pop("params", {"f": 0.05})
    return replace(SimulationConfig(), friction_law=law, friction_params=MappingProxyType(params), **kw)


def window(out, start: float = 0.0, end: float = 1.0) -> np.ndarray:
    a, b = out.plateau
    return (out.time >= a + start * (b - a)) & (out.time <= a + end * (b - a))


def after_arrival(out, start: float, end: float) -> np.ndarray:
    """Times between ``start`` and ``end`` (s) after the incident foot reaches the cell."""
    t_cell = paper_apparatus().input_bar.gauge_delay
    return (out.time >= t_cell + start) & (out.time <= t_cell + end)


def apparent_f(out, start: float = 0.0, end: float = 1.0, *, mask: np.ndarray | None = None) -> float:
    """Eq. 17 with the true nu, from the interface forces over (part of) the stationary window."""
    m = window(out, start, end) if mask is None else mask
    ratio = out.force_external[m].mean() / out.force_internal[m].mean()
    return float(friction_from_ratio(ratio, NU, radius=R, length=L))


def test_coulomb_ratio_does_not_depend_on_striker_speed() -> None:
    slow, fast = (run_model(config(striker_velocity=v)) for v in (6.0, 14.0))
    assert apparent_f(slow) == pytest.approx(0.05, rel=0.005)
    assert apparent_f(fast) == pytest.approx(0.05, rel=0.005)


def test_velocity_weakening_lowers_the_ratio_at_higher_sliding_speed() -> None:
    params = {"f_s": 0.08, "f_d": 0.03, "v_c": 8.0}
    slow, fast = (run_model(config("velocity", params=params, striker_velocity=v)) for v in (6.0, 14.0))
    v_slow, v_fast = (float(o.sliding_velocity[window(o)].mean()) for o in (slow, fast))
    assert v_fast > 2 * v_slow
    f_slow, f_fast = apparent_f(slow), apparent_f(fast)
    # the apparent coefficient is the law at the sliding speed (pressure-independent law)
    for f_app, v in ((f_slow, v_slow), (f_fast, v_fast)):
        assert f_app == pytest.approx(0.03 + 0.05 * math.exp(-v / 8.0), rel=0.02)
    assert f_fast < 0.8 * f_slow


def test_shear_strength_limit_lowers_the_apparent_friction_at_higher_load() -> None:
    params = {"f": 0.08, "tau_max": 6e6}
    low, high = (run_model(config("pressure", params=params, striker_velocity=v)) for v in (6.0, 14.0))
    assert np.max(low.wall_pressure[window(low)]) * 0.08 < 6e6  # below the limit: plain Coulomb
    assert apparent_f(low) == pytest.approx(0.08, rel=0.01)
    assert np.max(high.wall_pressure[window(high)]) * 0.08 > 6e6  # the limit binds
    assert apparent_f(high) < 0.7 * apparent_f(low)


def test_slip_weakening_makes_the_ratio_drift_down_through_the_test() -> None:
    weak = run_model(config("slip_weakening", params={"f_s": 0.1, "f_d": 0.04, "d_c": 3e-3}))
    ref = run_model(config())
    # 150-200 us and 400-450 us after the incident reached the cell, both in the incident plateau:
    # the Coulomb ratio is flat, the slip-weakening one falls as the slip grows past d_c
    first, last = after_arrival(ref, 150e-6, 200e-6), after_arrival(ref, 400e-6, 450e-6)
    assert apparent_f(ref, mask=first) == pytest.approx(apparent_f(ref, mask=last), rel=0.005)
    early, late = apparent_f(weak, mask=first), apparent_f(weak, mask=last)
    assert weak.sliding_displacement[first].max() < 2e-3 < 3e-3 < weak.sliding_displacement[last].min()
    assert late < 0.6 * early
    assert late == pytest.approx(0.04, rel=0.05)  # slid past d_c: the coefficient is f_d


def test_radial_gap_delays_the_hoop_strain_and_lowers_the_ratio() -> None:
    ref, gap = run_model(config()), run_model(config(gap=10e-6))

    def onset(out) -> float:
        return float(out.time[np.argmax(-out.strains["tube_hoop"] > 10e-6)])

    assert onset(gap) > onset(ref) + 2e-6
    f_gap = apparent_f(gap)
    assert f_gap < 0.95 * 0.05
    # docs/physics.md section 6: (F_i - F*) = (F_io - F*) exp(f beta), F* = pi R^2 E g / (nu R)
    m = window(gap)
    f_star = math.pi * R**2 * 2e9 * 10e-6 / (NU * R)
    fi, fio = gap.force_input[m].mean(), gap.force_internal[m].mean()
    beta = 2 * NU * L / ((1 - NU) * R)
    assert math.log((fi - f_star) / (fio - f_star)) / beta == pytest.approx(0.05, rel=0.01)


def test_tube_compliance_lowers_the_wall_pressure_as_section_6_says() -> None:
    rigid, soft = run_model(config()), run_model(config(tube_compliance=True))
    d_rigid, d_soft = 1 - NU, (1 - NU) + 2e9 * 1.71 / 200e9  # C_t = 1.71 (docs/physics.md section 6)
    f_rigid, f_soft = apparent_f(rigid), apparent_f(soft)
    assert f_soft / f_rigid == pytest.approx(d_rigid / d_soft, rel=0.003)


def test_plug_friction_adds_a_force_that_bypasses_the_sample() -> None:
    ref, plug = run_model(config()), run_model(config(plug_friction_force=500.0))
    m = window(ref)
    assert plug.plug_friction[m].mean() == pytest.approx(-500.0, rel=1e-6)
    extra = plug.force_external[m].mean() - ref.force_external[m].mean()
    assert extra == pytest.approx(500.0, rel=0.05)
    assert apparent_f(plug) > 1.25 * apparent_f(ref)  # F_eo too high for the sample's friction


def test_gauge_gain_error_breaks_the_equilibrium_by_the_gain_factor() -> None:
    gain = 1.05
    base = config()
    cfg = replace(base, channels=MappingProxyType({**base.channels, "internal_output_bar": ChannelSpec(gain=gain)}))
    sim = simulate(cfg, seed=1)
    app = paper_apparatus()
    t = sim.time
    forces = {}
    for name in ("internal_output_bar", "external_output_bar"):
        bar = app.bars[name]
        forces[name] = bar.area * bar.young_modulus * np.interp(t + bar.gauge_delay, t, sim.noisy[name])
    ib = app.input_bar
    g = sim.noisy["input_bar"]
    f_i = ib.area * ib.young_modulus * (np.interp(t - ib.gauge_delay, t, g) + np.interp(t + ib.gauge_delay, t, g))
    m = window(sim.model, 0.0, 0.5)
    measured = forces["internal_output_bar"][m].mean()
    assert measured == pytest.approx(gain * sim.force_internal[m].mean(), rel=1e-3)
    imbalance = (f_i[m] - forces["internal_output_bar"][m] - forces["external_output_bar"][m]).mean()
    assert imbalance == pytest.approx(-(gain - 1) * sim.force_internal[m].mean(), rel=0.05)


def test_dispersion_puts_oscillations_on_the_fronts() -> None:
    plain, disp = (run_model(config(rise_time=3e-6, dispersion=d)) for d in (False, True))
    t = plain.time
    amp = plain.incident_strain
    front = (t > 0) & (t < 120e-6)  # the incident front at the input gauge (after 1.28 m of bar)
    a, b = plain.strains["input_bar"][front], disp.strains["input_bar"][front]
    assert np.max(a) == pytest.approx(amp, rel=1e-6)  # the trapezoid, no overshoot
    assert np.max(b) > 1.03 * amp  # Pochhammer-Chree ringing overshoots the plateau
    wiggles = np.count_nonzero(np.diff(np.sign(np.diff(b[b > 0.5 * amp]))))
    assert wiggles >= 6
    # the plateau itself is unchanged further on
    late = (t > 150e-6) & (t < 400e-6)
    assert disp.strains["input_bar"][late].mean() == pytest.approx(amp, rel=0.01)


def test_every_registered_law_reduces_to_coulomb_in_its_limit() -> None:
    p, f = 80e6, 0.07
    limits = {"coulomb": [f], "velocity": [f, f, 1.0], "pressure": [f, 1e12], "hyperbolic": [f, 1e20],
              "slip_weakening": [f, f, 1e-3], "velocity_stretched": [f, f, 1.0, 2.0],
              "pressure_saturating": [f, 1e20, 3.0], "slip_power": [f, f, 1e-3, 0.5]}
    assert set(limits) == set(LAWS)
    for name, law in LAWS.items():
        value = shear_strength(law.code, np.array(limits[name]), p, 5.0, 2e-3)
        assert value == pytest.approx(f * p, rel=1e-9), name


@pytest.mark.parametrize("p", [1e6, 5e7, 8e7, 3e8])
@pytest.mark.parametrize("v", [0.0, 2.0, 9.0])
@pytest.mark.parametrize("d", [0.0, 4e-4, 2e-3])
def test_each_shaped_family_is_its_simple_law_at_n_one(p, v, d) -> None:
    pairs = {"velocity_stretched": ("velocity", [0.09, 0.04, 5.0]), "pressure_saturating": ("hyperbolic", [0.08, 7e7]),
             "slip_power": ("slip_weakening", [0.11, 0.05, 1e-3])}
    for family, (simple, par) in pairs.items():
        shaped = shear_strength(LAWS[family].code, np.array(par + [1.0]), p, v, d)
        assert shaped == pytest.approx(shear_strength(LAWS[simple].code, np.array(par), p, v, d), rel=1e-12), family


def test_the_saturating_family_bends_from_coulomb_to_the_shear_cap_as_n_grows() -> None:
    f0, p0 = 0.08, 6e7
    code = LAWS["pressure_saturating"].code
    cap = shear_strength(LAWS["pressure"].code, np.array([f0, f0 * p0]), 2e8, 0.0, 0.0)
    assert shear_strength(code, np.array([f0, p0, 400.0]), 2e8, 0.0, 0.0) == pytest.approx(cap, rel=1e-3)
    assert shear_strength(code, np.array([f0, p0, 400.0]), 2e7, 0.0, 0.0) == pytest.approx(f0 * 2e7, rel=1e-3)
    below = [shear_strength(code, np.array([f0, p0, n]), p0, 0.0, 0.0) for n in (0.5, 1.0, 2.0, 8.0)]
    assert below == pytest.approx([f0 * p0 * 2.0 ** (-1.0 / n) for n in (0.5, 1.0, 2.0, 8.0)], rel=1e-12)
    assert np.all(np.diff(below) > 0)  # the larger n, the later the turn
    assert np.isfinite(shear_strength(code, np.array([f0, 1e3, 1e3]), 1e9, 0.0, 0.0))  # x^n would overflow


def test_the_power_slip_family_with_a_long_reach_is_an_exponential_drop() -> None:
    """max(0, 1 - d/d_c)^n -> exp(-d/d_e) with d_c = n d_e as n grows (an exponential slip-weakening wall)."""
    d_e, code = 5e-4, LAWS["slip_power"].code
    for d in (0.0, 2e-4, 1e-3, 3e-3):
        got = shear_strength(code, np.array([0.1, 0.04, 200 * d_e, 200.0]), 1e8, 0.0, d)
        assert got == pytest.approx((0.04 + 0.06 * np.exp(-d / d_e)) * 1e8, rel=2e-3)


def test_hoop_axial_term_adds_the_poisson_swelling_of_the_tube_load() -> None:
    plain = run_model(config(params={"f": 0.2}, hoop_axial_term=False))
    axial = run_model(config(params={"f": 0.2}, hoop_axial_term=True))
    m = window(plain)
    extra = (plain.strains["tube_hoop"] - axial.strains["tube_hoop"])[m]  # swelling: more negative channel
    tube = paper_apparatus().tube
    bound = tube.poisson_ratio * plain.force_external[m] / (tube.young_modulus * tube.area)  # all friction upstream
    assert np.all(extra > 0.1 * bound) and np.all(extra < bound)
    assert np.max(bound) == pytest.approx(26e-6, rel=0.05)  # docs/physics.md: ~19 microstrain per 5 kN
