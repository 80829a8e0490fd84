"""Campaign verdicts that do not follow the sampler's bits (issue 20): the bundled campaign with five campaign
seeds (each record's sampler and the law fits seeded anew), and a hand-made two-set-up campaign whose tests'
posterior draws and law fits change with the seed while the tests themselves do not. On 1 or 2 workers the
results are the same bits (tests/test_campaign_runner.py), so the verdict is too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from friction_uq.campaigns import run_campaign
from friction_uq.campaigns.analysis import RecordPosterior, analyse_tests, supported_laws
from friction_uq.campaigns.flags import tally_causes
from friction_uq.prior_loader import PRIORS_DIR

DATA = Path(__file__).resolve().parents[1] / "data"
PRIOR = str(PRIORS_DIR / "I1.toml")
NU = 0.4


def _verdict(ca) -> tuple:
    """What a reader takes from a campaign: the laws named, whether f is said not to be constant, the set-ups
    flagged."""
    return (tuple(supported_laws(ca.weights, ca.ranking)),
            any(s.startswith("f is not constant") for s in ca.sentences),
            tuple(sorted({str(f["setup"]) for f in ca.flagged if "setup" in f})))


@pytest.mark.long
@pytest.mark.slow  # five campaigns of the ten bundled records without PDF reports, about 6.5 minutes on 2 cores
def test_the_bundled_campaign_gives_one_verdict_over_five_seeds(tmp_path):
    """The laws' fits are sampled in coordinates where their autocorrelation time is tens of steps
    (friction_uq/campaigns/law_coordinates.py); before, it was 200-250 steps against 700 kept, the fits' tails
    followed the seed, and so did the verdict (seed 4 read pressure+velocity with no set-up flagged, the others
    named laws and flagged B). The verdict asserted is what every seed reads: f not constant, constant not among
    the laws named, and set-up B flagged (it departs from the shared law by more than its calibration allows;
    B hides a plug friction, data/README.md). Which of the non-constant laws are named is compared across the
    seeds, not fixed here; the measured ELPDs and weights, which move with the law's form, are in
    docs/validation.md ("Campaigns on the bundled data"). With other numerical libraries (thirtieth session) seed 5
    fell below the flag's 4-nat line again: the fits' chains were a few autocorrelation times long; run on to 50
    (friction_uq/campaigns/law_chain.py, TAU_MULTIPLE), the flag's dELPD is 4.2-4.6 on every records and fit seed tried."""
    records = sorted(DATA.glob("[AB]/*.h5"))
    verdicts = [_verdict(run_campaign(records, tmp_path / f"s{seed}", seed=seed, pdf=False, progress=False).analysis)
                for seed in range(1, 6)]
    assert len(set(verdicts)) == 1, verdicts
    laws, not_constant, flagged = verdicts[0]
    assert not_constant and "constant" not in laws and flagged == ("B",)


def _two_setups(seed: int) -> list[RecordPosterior]:
    """Ten tests of a velocity-weakening wall on two set-ups (B's bars put it at 1.7 times A's pressure): each
    test's measured kappa (its data: noise of 0.7 %, the model-form 2.5 %) is fixed; its posterior draws, the
    sampler's part, are drawn with ``seed``."""
    data_rng, draw_rng = np.random.default_rng(7), np.random.default_rng(seed)
    tests = []
    for setup, p_of_v in (("A", lambda v: 9e6 * v), ("B", lambda v: 15e6 * v)):
        for k, V in enumerate(np.linspace(5.5, 12.5, 5)):
            kappa_true = (0.035 + 0.040 * np.exp(-V / 8.0)) * NU / (1 - NU)
            sd = kappa_true * float(np.hypot(0.007, 0.025))
            measured = kappa_true + data_rng.normal(0.0, sd)
            nu_measured = NU + data_rng.normal(0.0, 0.013)
            kappa = draw_rng.normal(measured, sd, 1000)
            nu = draw_rng.normal(nu_measured, 0.013, 1000)
            p = p_of_v(V)
            tests.append(RecordPosterior(f"{setup}-0{k + 1}", setup, kappa * (1 - nu) / nu, kappa, nu,
                                         draw_rng.normal(p, 0.05 * p, 1000),
                                         {"mean": V, "sd": 1e-3, "q05": V, "q50": V, "q95": V}, PRIOR))
    return tests


@pytest.mark.long
@pytest.mark.slow  # five law comparisons of ten tests, about 3 minutes
def test_a_two_setup_campaign_gives_one_verdict_over_five_seeds():
    verdicts = [_verdict(analyse_tests(_two_setups(seed), tally_causes([]), seed=seed)) for seed in range(1, 6)]
    assert len(set(verdicts)) == 1, verdicts
    laws, not_constant, flagged = verdicts[0]
    assert not_constant and "velocity" in laws and flagged == ()
