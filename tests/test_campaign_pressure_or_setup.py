"""Two set-ups at different pressures: a pressure term and an offset of one set-up are told apart only by the
pressures within each set-up (friction_uq.campaigns.analysis, ``_Laws.offset_alternative``). A velocity-weakening
wall whose second set-up reads 20 % high (a plug friction the stationary analysis cannot see) is not a pressure
law; a pressure law measured without an offset is not a set-up flag. The three campaigns' sampled law comparisons
are slow studies (-m slow); the rule that reads them is tested here on fixed densities in the default suite."""

from __future__ import annotations

import numpy as np
import pytest

from friction_uq.campaigns.analysis import RecordPosterior, analyse_tests, supported_laws
from friction_uq.prior_loader import PRIORS_DIR

PRIOR = str(PRIORS_DIR / "I1.toml")
NU = 0.4


def _tests(f_of, offset_b: float, *, p_with_v: bool, seed: int = 7) -> list[RecordPosterior]:
    """Ten tests, five per set-up at 5.5-12.5 m/s, B's bars at 1.7 times A's pressure; each test's kappa carries
    its noise (0.7 %) and eq. 17's model-form term (2.5 %). ``p_with_v``: the wall pressure grows with the
    striker speed (as on one bar set: pressure and speed go together within a set-up); else it is varied apart
    from the speed (sample lengths, say): 0.75-1.25 times the set-up's level, in an order unlike the speeds'."""
    rng = np.random.default_rng(seed)
    tests = []
    spread = np.array([1.0, 0.75, 1.25, 0.875, 1.125])
    for setup, p_per_v, scale in (("A", 9e6, 1.0), ("B", 15e6, 1.0 + offset_b)):
        for k, V in enumerate(np.linspace(5.5, 12.5, 5)):
            p = p_per_v * V if p_with_v else p_per_v * 9.0 * spread[k]
            kappa_true = f_of(V, p) * NU / (1 - NU) * scale
            sd = kappa_true * float(np.hypot(0.007, 0.025))
            kappa = rng.normal(kappa_true + rng.normal(0.0, sd), sd, 1000)
            nu = rng.normal(NU + rng.normal(0.0, 0.013), 0.013, 1000)
            tests.append(RecordPosterior(f"{setup}-0{k + 1}", setup, kappa * (1 - nu) / nu, kappa, nu,
                                         rng.normal(p, 0.05 * p, 1000),
                                         {"mean": V, "sd": 1e-3, "q05": V, "q50": V, "q95": V}, PRIOR))
    return tests


@pytest.mark.slow  # ten tests' law comparison, every law and offset sampled: 30-50 s each on 2 cores
def test_a_set_up_reading_high_is_flagged_where_pressure_varies_within_each_set_up():
    ca = analyse_tests(_tests(lambda V, p: 0.035 + 0.040 * np.exp(-V / 8.0), 0.20, p_with_v=False), {}, seed=2)
    assert [f["setup"] for f in ca.flagged if "setup" in f] == ["B"]
    assert "velocity" in supported_laws(ca.weights, ca.ranking)
    if "sentence" in ca.pressure_or_setup:  # flagged by the laws with and without the offset, not by the offset's
        # ELPD under the simplest law: those without it are ruled out by the package's rule, by more than 4 nats
        # also with the test that favours the offset most left out (8.0 +- 2.7 and 5.5 on the twenty-sixth's install)
        alt = ca.pressure_or_setup
        assert alt["without_ruled_out"] and alt["d_elpd"] > 4.0 and alt["d_elpd_rest"] > 4.0, alt
        assert ca.pressure_or_setup["sentence"] in ca.sentences
        assert "so the laws without it are ruled out and set-up B is flagged" in ca.pressure_or_setup["sentence"]
    flag = next(f for f in ca.flagged if "setup" in f)
    assert 0.10 < flag["offset"]["q50"] < 0.30  # B's departure, measured


@pytest.mark.slow  # ten tests' law comparison, every law and offset sampled: 30-50 s each on 2 cores
def test_where_pressure_goes_with_speed_in_each_set_up_the_two_readings_are_both_said():
    """Within each set-up p grows with V: a pressure term on a velocity law mimics B's 20 %: on these ten tests
    velocity + offset B and pressure+velocity predict alike (within 4 nats), so the campaign does not flag B nor
    hide the alternative. Their stacking shares follow the sampler's bits (the laws with the offset carried 0.42
    of the weight in the nineteenth session, 0.82-0.91 over analysis seeds 1-6 on the twenty-sixth's install):
    below 4 nats the weight does not decide (``WeightRule.ruled_out``), else seed 2's 0.905 flagged B."""
    ca = analyse_tests(_tests(lambda V, p: 0.035 + 0.040 * np.exp(-V / 8.0), 0.20, p_with_v=True), {}, seed=2)
    alt = ca.pressure_or_setup
    assert "offset B" in alt["best_with_offset"] and abs(alt["d_elpd"]) < 4.0, alt  # 1.7-2.6 over seeds 1-3
    assert not alt["without_ruled_out"]
    assert not [f for f in ca.flagged if "setup" in f]
    said = [s for s in ca.sentences if "told apart only by the pressures" in s]
    assert said and "velocity + offset B" in said[0]


@pytest.mark.slow  # ten tests' law comparison, every law and offset sampled: 30-50 s each on 2 cores
def test_a_pressure_law_without_an_offset_flags_no_set_up():
    ca = analyse_tests(_tests(lambda V, p: 0.05 * (1.0 + 0.5 * (p - 1.1e8) / 1.1e8), 0.0, p_with_v=False), {}, seed=2)
    assert not [f for f in ca.flagged if "setup" in f]
    assert "pressure" in supported_laws(ca.weights, ca.ranking)


def _alternative(with_offset: np.ndarray, without: np.ndarray) -> dict:
    """LawComparison.offset_alternative on fixed pointwise densities: the laws without the offset, the best of them
    ``without`` (another 30 nats behind), those with it, the best ``with_offset`` (another 30 behind)."""
    from types import SimpleNamespace

    from friction_uq.campaigns.law_comparison import LawComparison
    from friction_uq.campaigns.laws import Elpd

    def elpd(name, pw):
        return Elpd(name, float(np.sum(pw)), 0.0, np.asarray(pw, float), np.zeros(len(pw)), 0)

    base = {"velocity": elpd("velocity", without), "constant": elpd("constant", without - 3.0)}
    done = {"velocity + offset B": (elpd("velocity + offset B", with_offset), {"q50": 0.2, "q05": 0.1, "q95": 0.3}),
            "constant + offset B": (elpd("constant + offset B", with_offset - 3.0), {"q50": 0.2, "q05": 0.1,
                                                                                   "q95": 0.3})}
    laws = SimpleNamespace(base=base, offset_models=lambda setup, cal: done)
    return LawComparison.offset_alternative(laws, "B", ("B",))


def test_the_laws_without_the_offset_are_ruled_out_only_by_the_package_s_rule():
    """Ten tests: what the flag reads, on fixed densities (no sampler): within 4 nats the weight decides nothing;
    decisively ahead flags; more than 4 ahead without the test that favours it most, at no weight, flags."""
    rng = np.random.default_rng(5)
    without = rng.normal(2.0, 0.3, 10)
    # 2.6 nats ahead, spread unevenly: stacking gives the offset's laws nearly all the weight, but the rule does not
    close = without + np.array([1.4, 0.9, 0.6, 0.3, 0.2, 0.1, 0.0, -0.2, -0.3, -0.4])
    alt = _alternative(close, without)
    assert alt["weight_with_offset"] > 0.9 and 0 < alt["d_elpd"] < 4 and not alt["without_ruled_out"], alt
    # 4.5 +- 0.5 over ten tests, every test the same way: decisive
    alt = _alternative(without + 0.45 + rng.normal(0, 0.05, 10), without)
    assert alt["d_elpd"] > 4 and alt["without_ruled_out"], alt
    # the other way round, the laws without the offset ahead: never flagged
    alt = _alternative(without - 0.45, without)
    assert alt["d_elpd"] < 0 and not alt["without_ruled_out"], alt
    # 6 nats ahead, 4 of them on one test: not decisive over ten tests (SE 3.6), and 2 with it left out: not flagged
    lumpy = np.array([4.0, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.1, 0.1])
    alt = _alternative(without + lumpy, without)
    assert 4 < alt["d_elpd"] and alt["d_elpd_rest"] < 4 and not alt["without_ruled_out"], alt
    # 10.4 ahead, 6 of them on one test (not decisive, SE 5.3), 4.4 with it left out, at no weight: the weight route
    lumpy = np.array([6.0, 0.6, 0.6, 0.6, 0.6, 0.6, 0.6, 0.6, 0.1, 0.1])
    alt = _alternative(without + lumpy, without)
    assert alt["d_elpd"] < 2.262 * alt["d_se"] and alt["d_elpd_rest"] > 4 and alt["without_ruled_out"], alt
    assert 1.0 - alt["weight_with_offset"] < 0.1
