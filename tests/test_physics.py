"""Physics functions against the reference values of docs/physics.md (independent of the code)."""

import math

import pytest

from friction_uq.physics import bars, cell, design, tube
from friction_uq.record import paper_apparatus

# docs/physics.md section 4, Table 1: V_s = 10 m/s, nu = 0.4 (computed independently of this code)
TABLE = [
    # f, F_io (N), F_eo (N), F_eo/F_io, p_mean (MPa), V (m/s)
    (0.01, 10201, 276, 0.0270, 87.76, 9.072),
    (0.05, 10097, 1440, 0.1426, 91.68, 8.926),
    (0.10, 9954, 3042, 0.3056, 96.83, 8.726),
    (0.20, 9620, 6779, 0.7046, 107.88, 8.257),
    (0.50, 8184, 22863, 2.7937, 145.55, 6.241),
]
R, L = 0.005, 0.01


def sig3(x: float) -> str:
    return f"{x:.3g}"


@pytest.fixture(scope="module")
def kw():
    a = paper_apparatus()
    return dict(
        striker_velocity=10.0, z_input=a.input_bar.impedance, z_internal=a.internal_output_bar.impedance,
        radius=R, length=L,
    )


def test_impedances_match_physics_md():
    a = paper_apparatus()
    assert a.input_bar.impedance == pytest.approx(11449.1, rel=1e-5)
    assert a.internal_output_bar.impedance == pytest.approx(1122.88, rel=1e-5)
    assert a.external_output_bar.impedance == pytest.approx(21833.5, rel=1e-5)
    assert a.pulse_duration * 1e6 == pytest.approx(461, abs=0.5)


@pytest.mark.parametrize("f, F_io, F_eo, ratio, p_mean, V", TABLE)
def test_design_table_to_three_significant_digits(kw, f, F_io, F_eo, ratio, p_mean, V):
    z_eo = paper_apparatus().external_output_bar.impedance
    assert sig3(float(design.stationary_internal_force(f, 0.4, **kw))) == sig3(F_io)
    assert sig3(float(design.stationary_external_force(f, 0.4, **kw))) == sig3(F_eo)
    assert sig3(float(cell.force_ratio(f, 0.4, radius=R, length=L))) == sig3(ratio)
    assert sig3(float(design.stationary_mean_pressure(f, 0.4, **kw)) / 1e6) == sig3(p_mean)
    assert sig3(float(design.stationary_sliding_velocity(f, 0.4, z_external=z_eo, **kw))) == sig3(V)


@pytest.mark.parametrize("f, F_io, F_eo, ratio, p_mean, V", TABLE)
def test_eq17_inverts_the_table(f, F_io, F_eo, ratio, p_mean, V):
    # the table's forces are rounded to 1 N: f back within that rounding
    assert float(cell.friction_from_ratio(F_eo / F_io, 0.4, radius=R, length=L)) == pytest.approx(f, rel=3e-3)


def test_paper_reading_gives_the_papers_f():
    # docs/physics.md section 3: F_eo/F_io ~ 0.14 -> f ~ 0.131 (nu 0.2), ~ 0.049 (nu 0.4)
    assert float(cell.friction_from_ratio(0.14, 0.2, radius=R, length=L)) == pytest.approx(0.131, abs=5e-4)
    assert float(cell.friction_from_ratio(0.14, 0.4, radius=R, length=L)) == pytest.approx(0.049, abs=5e-4)


def test_pressure_profile_integrates_to_p_mean_and_spans_p_min_p_max():
    import numpy as np

    f, nu, F_io = 0.2, 0.4, 9620.0
    F_eo = F_io * float(cell.force_ratio(f, nu, radius=R, length=L))
    p_mean = float(cell.pressure_mean(F_eo, f, radius=R, length=L))
    z = np.linspace(0, L, 20001)
    p = cell.pressure_profile(z, p_mean=p_mean, f=f, nu=nu, radius=R, length=L)
    assert np.trapezoid(p, z) / L == pytest.approx(p_mean, rel=1e-6)
    assert p[-1] == pytest.approx(float(cell.pressure_min(F_io, nu, radius=R)), rel=1e-6)
    assert p[0] == pytest.approx(float(cell.pressure_max(F_io, F_eo, nu, radius=R)), rel=1e-6)


def test_incident_strain_eq14():
    assert bars.incident_strain(10.0, wave_speed=4555.0) == pytest.approx(10.0 / 9110.0)


def test_lame_and_hoop_kernel_reference_values():
    t = paper_apparatus().tube
    # docs/physics.md section 6: 2.10 microstrain per MPa for this tube
    assert t.lame_hoop_strain_per_pressure * 1e12 == pytest.approx(2.10, abs=0.005)
    # kernel integrates to one
    import numpy as np

    x = np.linspace(-0.2, 0.2, 400001)
    assert np.trapezoid(tube.hoop_kernel(x), x) == pytest.approx(1.0, rel=1e-6)
    # uniform 10 mm band: 0.77, 0.52, 0.14, ~0 of Lame at 0, 5, 10, 15 mm (fit within 2.4 % of peak)
    got = tube.band_response([0.0, 0.005, 0.010, 0.015], band_length=0.010)
    for g, ref in zip(got, [0.77, 0.52, 0.14, 0.0]):
        assert g == pytest.approx(ref, abs=0.024 * 0.77)
    # C_t = 1.71 (docs/physics.md section 6)
    assert tube.bore_compliance_factor(inner_radius=0.005, outer_radius=0.012, poisson_ratio=0.29) == pytest.approx(
        1.71, abs=0.005
    )


def test_gap_threshold_one_mpa_per_micrometre():
    # docs/physics.md section 6: sigma* = E_s g / (nu R), 1 MPa per micrometre here
    assert 2e9 * 1e-6 / (0.4 * R) / 1e6 == pytest.approx(1.0)
    assert math.isclose(float(cell.beta(0.4, radius=R, length=L)), 8.0 / 3.0)
