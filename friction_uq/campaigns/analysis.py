"""From the per-record results of a campaign to its pooled values, friction law and flags.

Reads each analysed record's stored draws (the ``.nc`` beside its result, :mod:`.draws`), pools f
and kappa (:mod:`.pooling`: f under each test's diagnosed model when every test was diagnosed, its
prior on f_effective divided out, with the stationary f's pooling kept beside it; else the
stationary f), fits the candidate friction laws with and without a set-up offset (:mod:`.laws`:
to kappa, or, when every test was diagnosed, to f under each test's diagnosed model), chooses the
best-supported law by leave-one-test-out ELPD, gives its parameters in f (from kappa with the
campaign's nu), and flags set-ups and tests (:mod:`.flags`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from ..prior_loader import load_priors
from .flags import outlier_tests, setup_entry, setup_flags, tally_causes
from .conclusions import CampaignAnalysis
from .job import RecordResult
from .law_comparison import (WEIGHT_RULE, LawComparison, draw_summary, fits_with_loo, offset_sentence,
                             simplest_supported, supported_laws, verdict)
from .laws import LAW_PARAMS, Elpd, Fit, LawData, Model, law_mean
from .next_test_choice import advice, rank_next_tests
from .draws import RecordPosterior, pool_tests, read_test_posterior
from .pooling import implied_kappa_log_prior, strata
from .warned import pooled_without_warned

__all__ = ["WEIGHT_RULE", "CampaignAnalysis", "RecordPosterior", "analyse", "analyse_tests", "read_test_posterior",
           "supported_laws", "verdict"]

MIN_TESTS_FOR_LAWS = 5
#: draws per test the laws' likelihood reads (a kernel density of them)
LAW_DRAWS = 160


def campaign_nu(tests: Sequence[RecordPosterior], prior_mean: float, prior_sd: float) -> tuple[float, float]:
    """nu shared by the tests: normal approximations of their posteriors combined, the prior counted once. A test
    whose hoop gauge and nu's prior disagree is left out: its nu is half the prior's, which its spread can exceed
    (a negative precision), and half a reading the run could not trust."""
    tests = [t for t in tests if not t.hoop_disagrees]
    if not tests:
        return prior_mean, prior_sd
    prec = sum(1.0 / np.var(t.nu) for t in tests) - (len(tests) - 1) / prior_sd**2
    num = sum(np.mean(t.nu) / np.var(t.nu) for t in tests) - (len(tests) - 1) * prior_mean / prior_sd**2
    if prec <= 1.0 / prior_sd**2:  # the tests add nothing beyond the prior (no hoop term): keep the prior
        return prior_mean, prior_sd
    return float(num / prec), float(1.0 / np.sqrt(prec))


def _law_data(tests: Sequence[RecordPosterior], *, diagnosed: bool | None = None) -> LawData:
    """The laws' data: f under each test's diagnosed model when every test was diagnosed (a cause such as
    a clearance or a plug friction biases the stationary kappa by a load-dependent amount that a law
    in (p, V) would otherwise absorb), else the stationary kappa. Each test carries :data:`LAW_DRAWS` of its
    draws (:func:`~.pooling.strata`: those at evenly spaced ranks, so that the comparison follows the test's
    posterior, not which of its draws were kept) and their log prior: kappa's implied by the test's prior
    file; f's as the run stored it beside the draws (the diagnosed model's prior on f_effective), else, for a record of a version that
    stored none, the file's f prior (the prior of the base f the mechanism starts from).
    ``diagnosed=False`` takes the stationary kappa whatever the tests carry."""
    if diagnosed is None:
        diagnosed = all(t.f_model is not None for t in tests)
    source = [np.asarray(t.f_model if diagnosed else t.kappa, float).ravel() for t in tests]
    picks = [strata(x, LAW_DRAWS) for x in source]
    y = [x[i] for x, i in zip(source, picks)]
    priors = {t.prior_file: load_priors(t.prior_file) for t in tests}

    def log_prior_of(t: RecordPosterior, v: np.ndarray, i: np.ndarray) -> np.ndarray:
        if not diagnosed:
            return implied_kappa_log_prior(v, priors[t.prior_file])
        if t.f_model_log_prior is not None:
            return np.asarray(t.f_model_log_prior, float).ravel()[i]  # the log prior of the same draws
        return priors[t.prior_file]["f"].logpdf(v)

    log_prior = tuple(log_prior_of(t, v, i) for t, v, i in zip(tests, y, picks))
    return LawData([t.label for t in tests], [t.setup for t in tests],
                   np.array([np.mean(v) for v in y]), np.array([np.std(v) for v in y]),
                   np.array([t.V["mean"] for t in tests]), np.array([t.V["sd"] for t in tests]),
                   np.array([np.mean(t.p_mean) for t in tests]), np.array([np.std(t.p_mean) for t in tests]),
                   basis="f" if diagnosed else "kappa", draws=tuple(y), draws_log_prior=log_prior,
                   **_window_changes(tests))


def _window_changes(tests: Sequence[RecordPosterior]) -> dict[str, np.ndarray | None]:
    """The slip law's data (:class:`~.laws.LawData`'s ``slip``, ``trend``, ``halves``) when every test carries
    its window's halves; else none, and the slip law is not compared."""
    if any(t.halves is None for t in tests):
        return {"slip": None, "trend": None, "halves": None}
    hs = [t.halves for t in tests]
    return {"slip": np.array([h.mean_slip for h in hs]),
            "trend": np.array([[h.log_kappa_change, h.sd] for h in hs]),
            "halves": np.array([[[h.slip[k], h.V[k], h.pressure_rel[k]] for k in (0, 1)] for h in hs])}


def f_law_draws(fit: Fit, nu: tuple[float, float], *, seed: int) -> dict[str, np.ndarray]:
    """The law's parameters in f units: kappa-law draws times (1-nu)/nu with the campaign's nu (a law
    fitted to f directly: times its scale only)."""
    rng = np.random.default_rng(seed)
    x = fit.draws
    nu_d = np.clip(rng.normal(nu[0], nu[1], len(x)), 1e-3, 0.499)
    g = fit.kbar * fit.data.to_f(nu_d)
    col = {p: x[:, k] for k, p in enumerate(fit.model.params)}
    law = fit.model.law
    out: dict[str, np.ndarray] = {}
    if law == "constant":
        out["f"] = col["a"] * g
    elif law == "pressure":  # at the lowest and highest tested pressures: what the tests fix, not the law's limits
        p_rel = np.array([np.min(fit.data.p), np.max(fit.data.p)]) / fit.p_ref - 1.0
        at = law_mean(law, {k: v[:, None] for k, v in col.items()}, np.zeros(2), p_rel)
        out["f_at_lowest_p"], out["f_at_highest_p"] = at[:, 0] * g, at[:, 1] * g
    elif law == "slip":  # at the least and the most slip tested: what the tests fix, not the law's limits
        S = np.array([np.min(fit.data.slip), np.max(fit.data.slip)])
        at = law_mean(law, {k: v[:, None] for k, v in col.items()}, np.zeros(2), np.zeros(2), S)
        out["f_at_least_slip"], out["f_at_most_slip"] = at[:, 0] * g, at[:, 1] * g
        out["S_c_mm"] = np.exp(col["log_sc"]) * 1e3
    else:  # pressure+velocity: the velocity law's values at the mean pressure, where its pressure term is 0
        at = "" if law == "velocity" else "_at_mean_p"
        out["f_s" + at], out["f_d" + at], out["v_c"] = col["s"] * g, col["d"] * g, np.exp(col["log_vc"])
    if "log_pc" in col:
        pc = np.exp(col["log_pc"])
        amp = col["s"] - col["d"] if law == "pressure" else col["amp_p"]
        out["p_c_MPa"] = pc * fit.p_ref * 1e-6
        # dy/dp at p_ref: -amp exp(-1 / P_c) / (P_c p_ref), per MPa, in f
        out["df_dp_per_MPa"] = -amp * np.exp(-1.0 / pc) / (pc * fit.p_ref) * 1e6 * g
    for setup in fit.model.cal_setups:
        out[f"calibration_{setup}"] = col[f"cal_{setup}"]
    for setup in fit.model.freed:
        out[f"offset_{setup}"] = col[f"free_{setup}"]
    if "delta" in col:
        out[f"offset_{fit.model.offset_setup}"] = col["delta"]
    out["scatter_rel"] = col["r"]
    return out


def stationary_flags(tests: Sequence[RecordPosterior], law: str, offsets: Sequence[str], setups: Sequence[str],
                     tallies: dict[str, dict[str, object]], diagnosed_offsets: dict[str, tuple[Elpd, dict[str, float]]],
                     already: set[str], *, seed: int) -> list[dict[str, object]]:
    """Set-ups whose stationary analysis (eq. 17 over the window) departs from the shared law, for a
    campaign whose law was fitted to f under the diagnosed models: the set-up measures off the law as
    the field would read it, and the entry says what the same offset is once each test's named causes
    are in its model (``offset_diagnosed``; ``explained_by_causes`` when it is no longer decisive)."""
    data = _law_data(tests, diagnosed=False)
    kbar, p_ref = float(np.mean(data.kappa)), float(np.mean(data.p))
    cal = tuple(setups[1:])
    jobs = [(Model(law, None, cal), data, kbar, p_ref, seed + 77)]
    jobs += [(Model(law, s, cal), data, kbar, p_ref, seed + 78 + k) for k, s in enumerate(offsets)]
    (_, base), *rest = fits_with_loo(jobs)
    with_offset = {s: (e, draw_summary(fit.draws[:, -2])) for s, (fit, e) in zip(offsets, rest)}
    flags = setup_flags(base, with_offset, setups, tallies, quantity="kappa")
    for f in flags:
        s = str(f["setup"])
        e, delta = diagnosed_offsets[s]
        f["offset_diagnosed"] = delta
        f["explained_by_causes"] = s not in already
        f["note_diagnosed"] = (f"under each test's diagnosed model the offset of {s} is {delta['q50'] * 100:+.0f} % "
                               f"[{delta['q05'] * 100:+.0f}, {delta['q95'] * 100:+.0f}]: "
                               + ("the causes named account for the stationary departure" if s not in already
                                  else "the causes named do not account for it"))
    return flags


def analyse(results: Sequence[RecordResult], records_dir: str | Path, *, seed: int = 20161,
            say: Callable[[str], None] | None = None) -> CampaignAnalysis:
    """Pool, fit the laws, choose, flag (see the module docstring); ``say`` takes the progress lines."""
    ok = [r for r in results if r.ok]
    if say is not None:
        say(f"reading the draws of {len(ok)} test(s)")
    tests = [read_test_posterior(r, Path(records_dir)) for r in ok]
    return analyse_tests(tests, tally_causes(ok), seed=seed, say=say)


def analyse_tests(tests: Sequence[RecordPosterior], tallies: dict[str, dict[str, object]], *,
                  seed: int = 20161, say: Callable[[str], None] | None = None) -> CampaignAnalysis:
    """The campaign's conclusions from the tests' draws and the tally of their causes."""
    say = say or (lambda _line: None)
    t0 = time.perf_counter()
    tests = list(tests)
    pooled, stationary, note = pool_tests(tests)
    ca = CampaignAnalysis(tests, pooled, tallies, pooled_stationary=stationary,
                          pooled_without_warned=pooled_without_warned(tests, pooled.get("f")))
    ca.sentences += note
    if len(tests) < MIN_TESTS_FOR_LAWS:
        ca.sentences.append(f"friction law: {len(tests)} analysed test(s); comparing laws needs at least "
                            f"{MIN_TESTS_FOR_LAWS}")
        return ca
    data = _law_data(tests)
    ca.law_data = data
    n_diag = sum(t.f_model is not None for t in tests)
    if 0 < n_diag < len(tests):
        ca.sentences.append(f"friction law: fitted to the stationary kappa, since only {n_diag} of {len(tests)} tests "
                            "were diagnosed (f under the diagnosed models needs every test diagnosed)")
    kbar, p_ref = float(np.mean(data.kappa)), float(np.mean(data.p))
    setups = sorted(set(data.setups))
    offsets = [setups[-1]] if len(setups) == 2 else (setups if len(setups) > 2 else [])
    cal = tuple(setups[1:])  # every set-up but the first: a calibration offset (laws.CALIBRATION_SD)
    laws = LawComparison(ca, data, kbar, p_ref, seed, say, t0)
    two = len(setups) == 2
    # with two set-ups the flag's first round fits every law with the second's offset, whatever the comparison
    # finds: fitted in the comparison's batch, which keeps both processes busy to its end
    elpds = laws.compare(cal, (), ahead=[Model(law, offsets[0], cal) for law in data.laws] if two else ())
    law_for_flags = simplest_supported(ca.weights, ca.ranking)
    pressure_named = any("log_pc" in LAW_PARAMS[law] for law in supported_laws(ca.weights, ca.ranking))
    first, freed = laws.flag(law_for_flags, offsets, cal, setups, tallies, every_law=two)
    if not freed and two:
        freed = _offset_or_pressure(ca, laws, data, offsets[0], cal, setups, tallies, pressure_named=pressure_named)
    if freed:  # the laws again, the flagged set-ups' levels left out (a free offset each): never fitted by them
        done = laws.offset_models(freed[0], cal) if two else None  # with two set-ups: the offset models themselves
        elpds = laws.compare(cal, tuple(freed), {k: v[0] for k, v in done.items()} if done else None)
        law_for_flags = simplest_supported(ca.weights, ca.ranking)
        if "sentence" in ca.pressure_or_setup:  # why the set-up was flagged, before what follows from it
            ca.sentences.append(str(ca.pressure_or_setup["sentence"]))
        ca.sentences.append(f"the friction law is compared with the level of set-up {', '.join(freed)} left out: it "
                            "departs from the shared law beyond its calibration (3 %), a finding for diagnose to "
                            "explain, not a part of any law")
    ca.sentences += verdict(ca.weights, ca.ranking, data.labels)
    if "sentence" in ca.pressure_or_setup and not freed:  # the alternative the named law leaves open
        ca.sentences.append(str(ca.pressure_or_setup["sentence"]))
    _best_or_next_test(ca, say)
    prior0 = load_priors(tests[0].prior_file)["nu"]
    pm, psd = float(prior0.ppf(0.5)), float(np.std(prior0.rvs(np.random.default_rng(seed), 20000)))
    if data.basis == "f" and offsets:
        ca.flagged += stationary_flags(tests, law_for_flags, offsets, setups, tallies, first,
                                       {str(f["setup"]) for f in ca.flagged}, seed=seed)
    ca.nu = campaign_nu(_trusted(ca, tests, data.basis, setups), pm, psd)
    name = ca.chosen or ca.law_models[max(ca.weights, key=ca.weights.get)]
    ca.law_draws = f_law_draws(ca.fits[name], ca.nu, seed=seed)
    ca.law_posterior = {k: draw_summary(v) for k, v in ca.law_draws.items()}
    chosen_elpd = elpds[name]
    ca.flagged += outlier_tests(chosen_elpd, data.labels)
    return ca


def _offset_or_pressure(ca: CampaignAnalysis, laws: LawComparison, data, offset: str, cal: tuple, setups: list,
                        tallies: dict, *, pressure_named: bool) -> list[str]:
    """With two set-ups: every law with and without the second set-up's offset, weighed together, so the flag does
    not hang on which law the ELPD could not rule out (under a constant law barely not ruled out, whose scatter
    takes up an unmodelled trend, an offset of 20 % was not decisive), nor on a pressure term standing for the
    offset. The set-up flagged where the laws without the offset are ruled out (returned as freed, else [])."""
    alt = laws.offset_alternative(offset, cal)
    freed = []
    if alt["without_ruled_out"]:  # the offset, not a law's term, is what the tests need
        ca.flagged.append(setup_entry(offset, alt["offset"], alt["d_elpd"], alt["d_se"], setups, tallies,
                                      quantity=data.basis) | {"weight_with_offset": alt["weight_with_offset"]})
        freed = [offset]
    ca.pressure_or_setup = alt
    if freed or pressure_named:  # said where it flagged the set-up or a pressure term may stand for the offset
        ca.pressure_or_setup |= {"sentence": offset_sentence(alt, bool(freed), pressure=pressure_named)}
    return freed


def _best_or_next_test(ca: CampaignAnalysis, say: Callable[[str], None]) -> None:
    """One supported law: the campaign's law; several: the next test that would tell them apart best."""
    supported = supported_laws(ca.weights, ca.ranking)
    if len(supported) == 1:
        ca.best, ca.chosen = supported[0], ca.law_models[supported[0]]
        return
    say("the expected information of one more test at each set-up and speed")
    ca.next_tests = rank_next_tests({law: ca.fits[m] for law, m in ca.law_models.items()}, ca.weights, supported)
    tip = advice(ca.next_tests, ca.weights, supported)
    if tip:
        ca.sentences.append(tip)


def _trusted(ca: CampaignAnalysis, tests: list, basis: str, setups: list) -> list:
    """The tests the campaign's nu is read from: those of set-ups not flagged (with two set-ups, a flag leaves
    neither trusted, unless the causes named one), all tests where none is left."""
    primary = [f for f in ca.flagged if f["basis"] == basis]
    flagged_setups = {str(f["setup"]) for f in primary}
    if len(setups) == 2 and flagged_setups:
        flagged_setups = set(setups)
    trusted = [t for t in tests if t.setup not in flagged_setups] or tests
    if len(setups) == 2 and primary and "named_by_causes" in primary[0]:
        trusted = [t for t in tests if t.setup != primary[0]["named_by_causes"]]
    return trusted

