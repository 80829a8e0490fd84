"""The studies' truth (benchmarks/bench_diagnose.true_f): the wall's coefficient, not what a fault of the measurement
chain makes the record read. A pressure-dependent wall's truth reads the window's mean wall shear from the external
bar's force; a bar whose modulus differs from the header the record carries (the bar_modulus fault) makes the record
read that force off by the two moduli's ratio, and the truth must use the force the bar carries."""

import math
import os
import sys
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
from bench_diagnose import true_f  # noqa: E402


def _case(e_true: float, e_header: float):
    f0, p0, radius, length = 0.085, 67e6, 0.005, 0.01
    f_eo = np.full(50, 1250.0)  # N, as the record reads it through its header's modulus
    cfg = SimpleNamespace(friction_law="hyperbolic", friction_params={"f0": f0, "p0": p0},
                          apparatus=SimpleNamespace(external_output_bar=SimpleNamespace(young_modulus=e_true)))
    prep = SimpleNamespace(data=SimpleNamespace(F_eo=f_eo, radius=radius, length=length, V=np.full(50, 9.0),
                                                slip=np.full(50, 1e-3)),
                           record=SimpleNamespace(apparatus=SimpleNamespace(
                               external_output_bar=SimpleNamespace(young_modulus=e_header))))
    tau_carried = (e_true / e_header) * 1250.0 / (2 * math.pi * radius * length)
    return cfg, prep, f0 - tau_carried / p0  # f = f0 / (1 + p / p0) with p = tau / f: f = f0 - tau / p0


@pytest.mark.parametrize("ratio", [1.0, 0.935, 1.076])
def test_a_pressure_walls_truth_reads_the_force_the_external_bar_carries(ratio):
    cfg, prep, expected = _case(205e9 * ratio, 205e9)
    assert true_f(cfg, prep) == pytest.approx(expected, rel=1e-6)  # the fixed point, 50 steps
    if ratio != 1.0:  # the record's own force would give another truth: by some per cent of f here
        _, _, as_read = _case(205e9, 205e9)
        assert abs(expected - as_read) > 0.05 * expected


def _capped(tau_max_over_f: float):
    """A capped wall (the simulator's ``pressure`` law) and its noise-free simulation's window."""
    import dataclasses
    from types import MappingProxyType

    from bench_diagnose import capped_wall_f
    from bench_misfit import clean_config

    from friction_uq.simulate.simulation import run_any

    cfg = clean_config(np.random.default_rng(5), "A")
    f = cfg.friction_params["f"]
    cfg = dataclasses.replace(cfg, friction_law="pressure",
                              friction_params=MappingProxyType({"f": f, "tau_max": f * tau_max_over_f}))
    model = run_any(cfg)
    t0, t1 = model.time[len(model.time) // 2], model.time[3 * len(model.time) // 4]
    w = (model.time >= t0) & (model.time <= t1)
    return f, capped_wall_f(cfg, t0, t1), float(model.wall_pressure[w].mean())


def test_a_shear_caps_truth_is_the_walls_mean_shear_over_its_mean_pressure():
    """A cap the wall never reaches leaves Coulomb's f; a cap at half the mean wall pressure's Coulomb shear brings
    the truth to the cap over the mean pressure or below it (below where the pressure varies along the wall: the
    mean of min(f p, tau_max) is at most min(f p_mean, tau_max)), never to the coefficient f the law was given."""
    f, truth, _ = _capped(1e12)
    assert truth == pytest.approx(f, rel=0.02)
    f, _, p_mean = _capped(1.0)  # the window's mean wall pressure, uncapped at first
    f, truth, p_capped = _capped(0.5 * p_mean)
    cap = f * 0.5 * p_mean
    assert truth <= cap / p_capped * (1 + 1e-9)
    assert truth < 0.75 * f
