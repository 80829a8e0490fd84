"""The catalogue's friction families (issue 24 item 3): each a direction of change with a shape n, whose n = 1 is the
simple law the catalogue held before, and whose f_effective is the wall's coefficient at the window's state."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.discrepancy.mechanisms import MECHANISMS, Context, power_weight
from friction_uq.simulate.friction import LAWS, shear_strength

CTX = Context(V=9.0, tau_mean=0.05 * 9e7, slip=2e-3, sigma_mean=1.35e8)


def test_at_shape_one_each_family_states_the_simple_laws_coefficient():
    s = MECHANISMS["slip_friction"].f_effective({"f": 0.05, "f_s": 0.1, "d_c": 5e-3, "n_d": 1.0}, CTX)
    assert s == pytest.approx(0.05 + 0.05 * (1 - 2e-3 / 5e-3), rel=1e-12)


@pytest.mark.parametrize("name,values,law,params", [
    ("velocity_friction", {"f": 0.04, "f_s": 0.08, "v_c": 6.0}, "velocity", ("f_s", "f", "v_c")),
    ("slip_friction", {"f": 0.05, "f_s": 0.1, "d_c": 5e-3, "n_d": 0.6}, "slip_power", ("f_s", "f", "d_c", "n_d")),
    ("pressure_friction", {"f": 0.08, "p0": 1.2e8, "n_p": 3.0, "nu": 0.4}, "pressure_saturating", ("f", "p0", "n_p")),
])
def test_f_effective_is_what_the_simulators_wall_does_at_the_windows_state(name, values, law, params):
    """The coefficient the mechanism states is tau / p of the law the simulator runs under it, at the window's V,
    slip and mean wall pressure (nu / (1 - nu) sigma_mean: 90 MPa here)."""
    got = MECHANISMS[name].f_effective(values, CTX)
    par = np.array([values[k] for k in params])
    p = CTX.wall_pressure(0.4)
    assert got == pytest.approx(shear_strength(LAWS[law].code, par, p, CTX.V, CTX.slip) / p, rel=1e-12)


def test_the_power_slip_family_with_a_long_reach_states_an_exponential_drop():
    """(1 - x / n)^n = exp(-x) (1 - x^2 / (2 n) + ...): d_c = n d_e with n = 2000, at slip = 5 d_e."""
    d_e, n = 4e-4, 2000.0
    x = CTX.slip / d_e
    assert power_weight(CTX.slip / (n * d_e), n) == pytest.approx(math.exp(-x), rel=1.1 * x**2 / (2 * n))


@settings(max_examples=60, deadline=None)
@given(f=st.floats(0.0, 0.5), df=st.floats(1e-4, 0.2), fs=st.floats(0.0, 0.5), x=st.floats(0.0, 40.0),
       n=st.floats(0.05, 50.0), law=st.sampled_from(["velocity_friction", "slip_friction", "pressure_friction"]))
def test_f_effective_never_falls_as_f_rises(f, df, fs, x, n, law):
    """The push-forward of f's prior through f_effective (effective_prior) needs it nondecreasing in f."""
    mech = MECHANISMS[law]
    extra = {"velocity_friction": {"f_s": fs, "v_c": CTX.V / max(x, 1e-3)},
             "slip_friction": {"f_s": fs, "d_c": CTX.slip / max(x, 1e-3), "n_d": n},
             "pressure_friction": {"p0": 1e9 / max(x, 1e-3), "n_p": n, "nu": 0.4}}[law]
    lo, hi = (float(mech.f_effective({"f": v, **extra}, CTX)) for v in (f, f + df))
    assert hi >= lo - 1e-15


def test_the_pressure_familys_further_start_is_a_cap_the_window_sits_on():
    """A search from the simple law alone (p0 = 1 GPa, n_p = 1) stopped at a mild hyperbola on a capped record of the
    axisymmetric simulation; the further start is a sharp cap below the window's mean wall pressure."""
    mech = MECHANISMS["pressure_friction"]
    (s,) = mech.further_starts(CTX, 0.4)
    p = CTX.wall_pressure(0.4)
    assert s["p0"] < p and s["n_p"] > mech.start["n_p"]
    assert mech.f_effective({"f": 0.08, "nu": 0.4, **s}, CTX) == pytest.approx(0.08 * s["p0"] / p, rel=0.01)
    assert all(m.further_starts(CTX, 0.4) == () for m in MECHANISMS.values() if m.name != "pressure_friction")
