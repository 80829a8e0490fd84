"""The comparison of friction laws over a campaign's tests: the models fitted (on two processes), their
leave-one-test-out ELPD, stacking weights, the verdict in sentences, and the set-ups flagged.

Which laws are named (:func:`supported_laws`) and how a set-up is flagged are in ``docs/campaigns.md``; the laws
and their likelihood in :mod:`.laws`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence

import numpy as np

from .._parallel import forked_map
from ..stats import RULE, WeightRule, paired_difference, stacking_weights
from ..stats.trimmed import trimmed_difference
from .conclusions import CampaignAnalysis
from .flags import setup_flags
from .kernels import warm_up_kernels
from .law_loo import loo_elpd, psis_loo, refit_elpd, to_refit
from .laws import LAW_PARAMS, SPECIAL_CASES, Elpd, Fit, LawData, Model, rank

#: The verdict's rule on the laws' stacking weights (friction_uq.stats.weights).
WEIGHT_RULE = WeightRule(mass=0.9, little=0.1)


#: processes the law models of one comparison are fitted on (forked where the process may fork; the
#: results do not depend on it)
LAW_WORKERS = min(2, os.cpu_count() or 1)


def supported_laws(weights: dict[str, float], ranking: Sequence[dict[str, object]], *,
                   by_weight: bool = True) -> list[str]:
    """The laws the comparison cannot set apart: those that carry the stacking weight (:data:`WEIGHT_RULE`) and
    every law it does not rule out (:meth:`~friction_uq.stats.WeightRule.ruled_out`: decisively behind the best,
    :data:`friction_uq.stats.RULE`, dELPD > 4 and beyond t(0.975, n - 1) SE over the n tests; or, ``by_weight``,
    more than 4 behind with and without the test that favours the best most, while it and the laws within 4 of
    it that are as far behind carry less than 0.1 of the weight), less a law that holds another of them as a special case
    (:data:`~.laws.SPECIAL_CASES`, constant excepted) without predicting the tests more than 4 better than it:
    its extra term is not asked for by the data. Stacking puts its weight on one of several laws that predict the
    tests alike, and which one follows the sampler's bits (on the bundled campaign, three laws within 1.3 ELPD
    of each other took weights 0.83, 0.65 and 0.96 in turn over seeds 1-3); the set of laws not ruled out does
    not. Simplest first (fewest parameters, then name), so that the same set reads the same."""
    rows = {str(r.get("law", r["model"])): r for r in ranking if str(r.get("law", r["model"])) in weights}
    behind = {law: float(r["d_elpd"]) for law, r in rows.items()}

    def ruled_out(law: str) -> bool:
        r = rows[law]
        alike = WEIGHT_RULE.alike_weight(weights, behind, law)  # with the laws as far behind that predict alike
        rest = r.get("d_elpd_rest") if by_weight else None
        return WEIGHT_RULE.ruled_out(alike, behind[law], float(r["d_se"]),
                                     n=int(r["n_tests"]) if r.get("n_tests") else None,
                                     d_rest=None if rest is None else float(rest))

    kept = set(WEIGHT_RULE.supported(weights)) | {law for law in rows if not ruled_out(law)}
    richer = {law for law in kept for simple in SPECIAL_CASES.get(law, ())
              if simple != "constant" and simple in kept and law in behind and simple in behind
              and behind[simple] - behind[law] <= RULE.min_delpd}
    return sorted(kept - richer, key=lambda law: (len(LAW_PARAMS.get(law, ())), law))


def simplest_supported(weights: dict[str, float], ranking: Sequence[dict[str, object]]) -> str:
    """The law with the fewest parameters among those the ELPD alone does not rule out (:func:`supported_laws`
    without the weight route; the heaviest among equals): set-ups are flagged under it, since a richer law can
    absorb a set-up's offset into the term it adds (a pressure term fits a set-up whose bars put it at other
    pressures). Not the weight route: one set-up off by its calibration puts its evidence in its own tests, and
    a law it pushes ahead could then take the offset into its term and leave the set-up unflagged."""
    return min(supported_laws(weights, ranking, by_weight=False), key=lambda law: (len(LAW_PARAMS[law]), -weights[law]))


#: Said beside a verdict that names a law with a velocity term when the slip law was not compared (a test without
#: its change across the window, or the laws fitted to f under diagnosed models: docs/campaigns.md).
SLIP_CAVEAT = ("a dependence on the distance slid would read the same: at each test's window the mean slip grows in "
               "proportion to V within a set-up, and the slip law was not compared here (it reads each test's change "
               "across its window: the stationary analysis' change, without --diagnose), so a velocity term may stand "
               "for slip weakening (docs/campaigns.md)")


def verdict(weights: dict[str, float], ranking: Sequence[dict[str, object]],
            labels: Sequence[str] | None = None) -> list[str]:
    """What the comparison supports (:func:`supported_laws`), in sentences: the law, or the laws the data do not
    separate (with their stacking weights and how far behind the best each is); and that f is not constant
    whenever the constant law carries little weight and is ruled out. ``labels``: the tests' names, in the
    order of the pointwise densities (to name a test the evidence rests on)."""
    supported = supported_laws(weights, ranking)
    by_name = {str(r.get("law", r["model"])): r for r in ranking}

    def w(name: str) -> str:
        r = by_name[name]
        gap = "" if float(r["d_elpd"]) == 0.0 else f", {float(r['d_elpd']):.1f} +- {float(r['d_se']):.1f} behind"
        return f"{name} (weight {weights[name]:.2f}{gap})"

    if len(supported) == 1 and weights[supported[0]] >= WEIGHT_RULE.mass - 1e-9:
        out = [f"friction law: {w(supported[0])}, the law that carries the weight"]
    elif len(supported) == 1:
        richer = [law for law, cases in SPECIAL_CASES.items() if supported[0] in cases and law in weights]
        out = [f"friction law: {w(supported[0])}: the laws that contain it ({', '.join(richer)}) predict the tests "
               "no better, the others are ruled out"]
    else:
        out = ["friction law: the data do not separate " + ", ".join(w(n) for n in supported)]
    if "constant" not in supported and weights.get("constant", 1.0) < WEIGHT_RULE.little:
        out.append(f"f is not constant: the constant law carries {weights['constant']:.2f} of the weight")
    elif "constant" in supported and len(supported) > 1:
        out.append(_unresolved(weights, by_name["constant"], labels))
    if "slip" not in weights and any("log_vc" in LAW_PARAMS[law] for law in supported if law in LAW_PARAMS):
        out.append(SLIP_CAVEAT)  # the slip law was not compared (no change across the windows, or f of diagnosed models)
    return out


def _unresolved(weights: dict[str, float], const: dict[str, object], labels: Sequence[str] | None) -> str:
    """Why a dependence of f is not resolved while the constant law is named beside others: it predicts the tests
    about as well; or it is far behind but not decisively, and (with little weight) the evidence against it
    rests on one test."""
    on = "V, p or the slip" if "slip" in weights else "V or p"
    d, rest, w = float(const["d_elpd"]), const.get("d_elpd_rest"), weights["constant"]
    if d <= RULE.min_delpd:
        return (f"no dependence of f on {on} is resolved: a constant f carries {w:.2f} of the weight, and the laws "
                "beside it predict the tests as well")
    n = const.get("n_tests")
    head = (f"no dependence of f on {on} is resolved beyond doubt: a constant f carries {w:.2f} of the weight and "
            f"is {d:.1f} +- {float(const['d_se']):.1f} behind, short of decisive over {n or 'these'} tests")
    if w < WEIGHT_RULE.little and rest is not None and float(rest) <= RULE.min_delpd:
        i = const.get("rest_without_test")
        test = f"test {labels[int(i)]}" if labels is not None and i is not None and int(i) < len(labels) else "one test"
        return (f"{head}, and {float(rest):.1f} with {test} left out: the evidence against it rests on that test, and "
                "another at its conditions would say whether it holds")
    return head


def draw_summary(x: np.ndarray) -> dict[str, float]:
    """Mean, sd and the 5, 50 and 95 % quantiles of draws."""
    q = np.quantile(x, [0.05, 0.5, 0.95])
    return {"mean": float(np.mean(x)), "sd": float(np.std(x)), "q05": float(q[0]), "q50": float(q[1]),
            "q95": float(q[2])}



def _fit(job: tuple[Model, LawData, float, float, int]) -> tuple[Fit, tuple[np.ndarray, np.ndarray]]:
    model, data, kbar, p_ref, seed = job
    fit = Fit(model, data, kbar=kbar, p_ref=p_ref, seed=seed)
    return fit, psis_loo(fit)


def _refit(job: tuple[Fit, int, int]) -> float:
    fit, i, seed = job
    return refit_elpd(fit, i, seed=seed)


def fits_with_loo(jobs: Sequence[tuple[Model, LawData, float, float, int]]) -> list[tuple[Fit, Elpd]]:
    """Each (model, data, kbar, p_ref, seed) job fitted, with its leave-one-test-out ELPD, on up to
    :data:`LAW_WORKERS` forked processes: the fits first, then every model's exact refits (tests with a high
    Pareto k) as jobs of their own, so that a model with many refits does not keep one process busy while the
    other waits; each refit has the seed ``seed + 1 + i`` of its model's seed and test, whichever process runs it."""
    warm_up_kernels()  # loaded here once, before the fork, not in every child (0.5-1 s each)
    import arviz  # noqa: F401 - the same: the children's PSIS uses it, and a child that imports it pays ~1 s

    # the longest chains first (most parameters), so that the last job to start is a short one; the values come back
    # in the jobs' order whichever process ran each
    order = sorted(range(len(jobs)), key=lambda n: -len(jobs[n][0].params))
    done = dict(zip(order, forked_map(_fit, [jobs[n] for n in order], workers=LAW_WORKERS)))
    fits, psis = zip(*(done[n] for n in range(len(jobs)))) if jobs else ((), ())
    todo = [(n, i) for n, (_, k) in enumerate(psis) for i in to_refit(k)]
    values = forked_map(_refit, [(fits[n], i, jobs[n][4]) for n, i in todo], workers=LAW_WORKERS)
    refits: list[dict[int, float]] = [{} for _ in fits]
    for (n, i), v in zip(todo, values):
        refits[n][i] = v
    return [(fit, loo_elpd(fit, *psis[n], refits[n])) for n, fit in enumerate(fits)]


class LawComparison:
    """The law fits of one campaign analysis: the comparison (fits, LOO, ranking, weights) and the flags."""

    def __init__(self, ca: CampaignAnalysis, data: LawData, kbar: float, p_ref: float, seed: int,
                 say: Callable[[str], None], t0: float) -> None:
        self.ca, self.data, self.kbar, self.p_ref, self.seed, self.say, self.t0 = ca, data, kbar, p_ref, seed, say, t0
        self.k = 0
        #: model name -> (ELPD, summary of its offset's draws) of every model with a free offset fitted so far
        self.offset_fits: dict[str, tuple[Elpd, dict[str, float]]] = {}
        #: model -> (fit, ELPD) of every model fitted so far, those fitted ahead of being asked for among them (keyed by
        #: the model, not its name: a free offset to flag a set-up and one that leaves its level out share a name)
        self._fitted: dict[Model, tuple[Fit, Elpd]] = {}

    def fit_all(self, models: Sequence[Model], ahead: Sequence[Model] = ()) -> list[tuple[Fit, Elpd]]:
        """Each model fitted with its leave-one-test-out ELPD, on up to :data:`LAW_WORKERS` forked processes; the
        k-th model of the analysis takes seed ``seed + 1000 k`` whichever process fits it. ``ahead``: models the
        analysis will ask for next, fitted in the same batch (the processes kept busy; the same seeds as when asked
        for later); a model fitted ahead is not fitted again."""
        new = list(dict.fromkeys(m for m in [*models, *ahead] if m not in self._fitted))
        if new:
            first = self.k + 1
            self.k += len(new)
            self.say(f"friction law model{'s' if len(new) > 1 else ''} {first}{f'-{self.k}' if len(new) > 1 else ''} "
                     f"({', '.join(m.name for m in new)}): fit and leave-one-test-out; "
                     f"{time.perf_counter() - self.t0:.0f} s so far")
            jobs = [(m, self.data, self.kbar, self.p_ref, self.seed + 1000 * (first - 1 + i)) for i, m in enumerate(new)]
            self._fitted |= dict(zip(new, fits_with_loo(jobs)))
        out = [self._fitted[m] for m in models]
        for m, (fit, _) in zip(models, out):
            self.ca.fits[m.name] = fit
        return out

    def compare(self, cal: tuple[str, ...], freed: tuple[str, ...],
                elpds: dict[str, Elpd] | None = None, *, ahead: Sequence[Model] = ()) -> dict[str, Elpd]:
        """Every law with calibration offsets (and the ``freed`` set-ups' levels left out): ranking and weights.
        ``elpds``: the four models fitted already (a free offset on one set-up is the same model whether it was
        fitted to flag the set-up or to leave its level out). ``ahead``: models fitted in the same batch for what
        follows (:meth:`fit_all`)."""
        if elpds is None:
            models = [Model(law, None, cal, freed) for law in self.data.laws]
            elpds = {m.name: e for m, (_, e) in zip(models, self.fit_all(models, ahead))}
        self.ca.ranking = rank(list(elpds.values()))
        self.ca.weights = {Model(k.split(" + ")[0]).law: w
                           for k, w in stacking_weights({n: e.pointwise for n, e in elpds.items()}).items()}
        self.ca.law_models = {m.split(" + ")[0]: m for m in elpds}
        for r in self.ca.ranking:
            r["law"] = str(r["model"]).split(" + ")[0]
            r["weight"] = self.ca.weights[r["law"]]
        self.base = elpds
        return elpds

    def flag(self, law: str, offsets: Sequence[str], cal: tuple[str, ...], setups: Sequence[str],
             tallies: dict[str, dict[str, object]], *, every_law: bool = False,
             ) -> tuple[dict[str, tuple[Elpd, dict[str, float]]], list[str]]:
        """Set-ups off the shared law beyond their calibration, the most decisive first, each tested with the
        ones found before left out (one set-up pulling the law makes the others look off). Returns the
        first round's offsets (every candidate set-up) and the set-ups flagged. ``every_law``: the first round
        also fits the other laws with each offset (:meth:`offset_alternative` reads them), in the same batch."""
        base = self.base[Model(law, None, cal).name]
        freed: list[str] = []
        first: dict[str, tuple[Elpd, dict[str, float]]] = {}
        while True:
            laws = self.data.laws if every_law and not first else (law,)
            models = [Model(x, s, cal, tuple(freed)) for s in offsets if s not in freed for x in laws]
            fitted = {m: (e, draw_summary(fit.draws[:, -2])) for m, (fit, e) in zip(models, self.fit_all(models))}
            if not freed:
                self.offset_fits |= {m.name: v for m, v in fitted.items()}
            trial = {str(m.offset_setup): v for m, v in fitted.items() if m.law == law}
            first = first or trial
            flags = setup_flags(base, trial, setups, tallies, quantity=self.data.basis) if trial else []
            if not flags:
                return first, freed
            top = max(flags, key=lambda f: float(f["d_elpd"]))
            self.ca.flagged.append(top)
            freed.append(str(top["setup"]))
            base = trial[str(top["setup"])][0]
            if len(setups) == 2:  # with two set-ups one offset is all that can be told
                return first, freed

    def offset_models(self, setup: str, cal: tuple[str, ...]) -> dict[str, tuple[Elpd, dict[str, float]]]:
        """Every law with a free offset on ``setup`` (those not fitted yet are fitted now): name -> (ELPD, summary
        of the offset's draws)."""
        todo = [m for m in (Model(law, setup, cal) for law in self.data.laws) if m.name not in self.offset_fits]
        if todo:
            self.offset_fits |= {m.name: (e, draw_summary(fit.draws[:, -2]))
                                 for m, (fit, e) in zip(todo, self.fit_all(todo))}
        return {m.name: self.offset_fits[m.name] for m in (Model(law, setup, cal) for law in self.data.laws)}

    def offset_alternative(self, setup: str, cal: tuple[str, ...]) -> dict[str, object]:
        """With two set-ups: every law with a free offset on ``setup`` beside every law without, their stacking
        weights together, and the best with the offset against the best without. A law with a pressure term
        can stand for a difference between the set-ups (a plug friction or a gauge's calibration in one), since
        one set-up's bars put all its tests at other pressures: the two readings are told apart only by the
        pressures within each set-up."""
        done = self.offset_models(setup, cal)
        models = self.base | {k: v[0] for k, v in done.items()}
        weights = stacking_weights({n: e.pointwise for n, e in models.items()})
        best = max(done, key=lambda k: done[k][0].elpd)
        top = max(self.base, key=lambda k: self.base[k].elpd)
        d, se = paired_difference(done[best][0].pointwise, self.base[top].pointwise)
        rest = trimmed_difference(done[best][0].pointwise, self.base[top].pointwise, drop=1)[0]
        with_offset = float(sum(weights[k] for k in done))
        # the weight the rule reads for the laws without the offset: theirs, and that of any law with it that predicts
        # alike with the best of them (a twin that takes the share stacking would give it)
        lead = max(e.elpd for e in models.values())
        behind = {k: lead - e.elpd for k, e in models.items()}
        twins = WEIGHT_RULE.alike_weight({k: w for k, w in weights.items() if k in done}, behind, top)
        return {"setup": setup, "best_with_offset": best, "offset": done[best][1], "best_without": self.base[top].model,
                "d_elpd": d, "d_se": se, "d_elpd_rest": rest, "weight_with_offset": with_offset, "laws": len(done),
                # the laws without the offset ruled out by the package's rule (the ELPD's, or the weight route's):
                # below 4 nats the weight never decides, since stacking's share among models that predict alike
                # follows the sampler's bits
                "without_ruled_out": WEIGHT_RULE.ruled_out(1.0 - with_offset + twins, d, se,
                                                           n=len(self.base[top].pointwise), d_rest=rest)}


def offset_sentence(alt: dict[str, object], flagged: bool, *, pressure: bool = True) -> str:
    """What :meth:`LawComparison.offset_alternative` found, in one sentence (``flagged``: the set-up was flagged
    by it; ``pressure``: a law with a pressure term is among those named)."""
    delta = alt["offset"]
    n = int(alt.get("laws", 4))  # the laws compared (an analysis stored before the slip law had four)
    lead = (f"{alt['best_with_offset']} (set-up {alt['setup']} {delta['q50'] * 100:+.0f} % [{delta['q05'] * 100:+.0f}, "
            f"{delta['q95'] * 100:+.0f}] off the shared law) predicts the tests {alt['d_elpd']:+.1f} +- {alt['d_se']:.1f} "
            f"against {alt['best_without']}, and the laws with that offset carry {alt['weight_with_offset']:.2f} of "
            f"the weight of all {2 * n} models (the {n} laws with and without the offset)")
    why = "so the laws without it are ruled out and" if flagged else ""
    if not pressure:  # the weights of every law with and without the offset, no pressure term named
        return (f"with two set-ups, {lead}" + (f", {why} set-up {alt['setup']} is flagged; `--diagnose` (a plug "
                "friction or a gauge's gain fitted per test), or a third set-up, says which set-up is off"
                if flagged else ""))
    head = "with two set-ups a pressure term and a difference between the set-ups are told apart only by the pressures "
    if flagged:
        return (head + f"within each: {lead}, {why} set-up {alt['setup']} is flagged and the laws compared with its "
                "level left out; a third set-up, or `--diagnose` (a plug friction or a gauge's gain fitted per test), "
                "tells the two readings apart")
    return (head + f"within each: {lead}; the laws without the offset are not ruled out (within 4 nats the weight "
            "decides nothing), and a third set-up, or `--diagnose`, tells them apart")
