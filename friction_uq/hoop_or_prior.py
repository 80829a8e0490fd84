"""When the tube's hoop gauge and the prior file disagree on nu: f both ways, and the f to quote from both.

The hoop gauge is the record's only witness of nu (docs/physics.md): it reads g times the tube's response to
the wall pressure, and that pressure is the axial stress times nu / (1 - nu) (eq. 18), so the gauge's calibration
g and nu trade off. The prior file holds nu to a few hundredths and g to 5 %. A hoop gauge whose scale is off by
more (a bridge declared quarter that is a half bridge, a gauge factor or an amplifier gain entered wrong, a lead's
resistance) pulls nu far outside its prior, and f = kappa (1 - nu) / nu with it: on A-03 with its hoop gauge read
at half its scale, f = 0.090 [0.080, 0.101] for 0.049. The same record cannot say whether the gauge or the
prior file is wrong; a sample whose nu is not the prior's reads alike.

So when the power-scaling check (:func:`friction_uq.prior_sensitivity.prior_data_conflict`) flags a parameter
while the hoop term is on, the posterior is sampled again with the hoop gauge left out (nu from the prior file
alone). The two readings disagree when the check flags nu or the gauge's gain (a prior-data conflict), or when
neither f's median lies within the other's 90 % interval (a gauge read at twice its scale or more cannot be
fitted through nu, which stops at 0.5, and is fitted through f, whose prior is then flagged). Then the f to quote
is the two posteriors in equal parts: its interval holds f whichever of the two is wrong. Both are kept and said
(the JSON's ``hoop_or_prior``, a warning naming the two values and the hoop gauge's scale against the prior's
nu). The trigger is the check's own; how often it fires on records the likelihood did not make, and what it
does to f there, is in docs/trust.md. Under ``diagnose`` every whole-record model reads nu through the hoop gauge
too: the diagnosed f to quote then holds the reading from the prior's nu alone for half
(:attr:`HoopOrPrior.f_prior_draws`, friction_uq.discrepancy.diagnosed_f).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .diagnostics import VariableSummary
from .diagnostics.datatree import derived_draws
from .likelihood.hoop import HoopTerm
from .models.parameters import summarize_draws
from .prior_sensitivity import PriorDataConflict
from .priors import Priors
from .quoted import quoted_summary
from .sampler import PosteriorSamples
from .stats.thinning import equal_parts, evenly_spaced
from .window import StationaryData

#: The ``.nc`` group holding the f quoted's draws (the two posteriors in equal parts), which a campaign pools.
HOOP_OR_PRIOR_GROUP = "hoop_or_prior"
#: The prior's quantiles said beside the hoop gauge's nu.
QUANTILES = (0.05, 0.5, 0.95)


#: The parameters whose flag implicates the hoop gauge: it is nu's only witness, through g nu / (1 - nu).
HOOP_WITNESSED = ("nu", "hoop_gain")


def worth_asking(conflict: PriorDataConflict, hoop_on: bool) -> bool:
    """Whether to sample the posterior again with the hoop gauge left out: the hoop term is on and the power-scaling
    check flags a parameter."""
    return bool(hoop_on and conflict.flagged)


def disagree(conflict: PriorDataConflict, f_hoop: np.ndarray, f_prior: np.ndarray) -> bool:
    """Whether the two readings disagree (module docstring): the check flags nu or the hoop gauge's gain (a
    prior-data conflict), or each f's median lies outside the other's 90 % interval (a hoop gauge read far off
    its scale is fitted through f rather than nu, and only f is flagged). A flag on f that both readings share
    (its prior squeezing it) is not the hoop gauge's."""
    if any(n in conflict.flagged for n in HOOP_WITNESSED):
        return True
    qh, qp = np.quantile(f_hoop, [0.05, 0.5, 0.95]), np.quantile(f_prior, [0.05, 0.5, 0.95])
    return not (qh[0] <= qp[1] <= qh[2]) and not (qp[0] <= qh[1] <= qp[2])


def _summary(x: np.ndarray) -> dict[str, float]:
    q = np.quantile(x, QUANTILES)
    return {"q05": float(q[0]), "q50": float(q[1]), "q95": float(q[2])}


@dataclass(frozen=True)
class TwoReadings(VariableSummary):
    """f's summary over the two readings in equal parts: its median can sit between them, where neither puts
    weight, so the warnings say it as its interval (:mod:`friction_uq.record_run.warnings`)."""


@dataclass(frozen=True)
class HoopOrPrior:
    """nu and f read with the hoop gauge and from the prior file alone, and the f to quote from both."""

    nu_hoop: dict[str, float]  # nu's posterior with the hoop gauge: q05, q50, q95
    nu_prior: dict[str, float]  # nu's prior: q05, q50, q95
    gauge_scale: float  # the gauge's window mean over the model's from the forces and the prior's nu
    f_hoop: dict[str, float]  # f to quote with the hoop gauge (output bars' calibration folded in)
    f_prior: dict[str, float]  # f to quote with the hoop gauge left out
    f_quoted: dict[str, float]  # the two in equal parts
    f_given_headers: dict[str, float]  # the two in equal parts, given the bars' header values: mean, sd, q05, q50, q95
    flagged: tuple[tuple[str, str], ...]  # what the power-scaling check flagged, and its diagnosis of each
    #: the equal mixture's joint draws of f, nu, kappa and p_mean (Pa), given the bars' header values
    draws: dict[str, np.ndarray] = field(repr=False, default_factory=dict)
    prior_converged: bool = True  # whether the sampling with the hoop gauge left out met the stopping rule

    @property
    def f_prior_draws(self) -> np.ndarray:
        """f's draws with nu from the prior file alone (the equal mixture's second half), given the bars' headers."""
        f = self.draws["f"]
        return f[f.size // 2:]

    @property
    def medians(self) -> dict[str, float]:
        """The two readings' f to quote, medians: "prior" (nu from the prior file alone) and "hoop"."""
        return {"prior": self.f_prior["q50"], "hoop": self.f_hoop["q50"]}

    def sentence(self, *, diagnosed: dict[str, float] | None = None) -> str:
        """The warning: what disagrees, f both ways, and what is quoted (``diagnosed``: the f to quote when it is
        ``diagnose``'s, whose models read nu through the hoop gauge as well, in equal parts with f from the prior's
        nu alone: friction_uq.discrepancy.diagnosed_f)."""
        def f(x: dict[str, float]) -> str:
            return f"f = {x['q50']:.4g} [{x['q05']:.4g}, {x['q95']:.4g}]"

        h, p, q = self.nu_hoop, self.nu_prior, diagnosed or self.f_quoted
        quoted = (f"`diagnose`'s models read nu through the hoop gauge as well: the f quoted holds their f and f from "
                  f"the prior's nu alone in equal parts, from {q['q05']:.4g} to {q['q95']:.4g} (90 %)" if diagnosed
                  else f"the f quoted holds both in equal parts: from {q['q05']:.4g} to {q['q95']:.4g} (90 %)")
        return (f"The tube's hoop gauge and the prior file disagree (the prior-data check: "
                f"{'; '.join(f'{n}: {d}' for n, d in self.flagged)}): with the hoop gauge nu = {h['q50']:.3g} "
                f"[{h['q05']:.3g}, {h['q95']:.3g}] and {f(self.f_hoop)}; from the prior file's nu ({p['q50']:.3g} "
                f"[{p['q05']:.3g}, {p['q95']:.3g}]) alone {f(self.f_prior)}. The hoop gauge reads "
                f"{self.gauge_scale:.2g} times what the forces and the prior's nu predict: either its scale is off "
                "(gauge factor, bridge, amplifier gain) or the prior file is not this sample's, and one record cannot "
                f"tell which; {quoted}. A calibration of the hoop gauge or a measured nu decides."
                + ("" if self.prior_converged else " (The sampling with nu from the prior alone stopped short of its "
                   "convergence rule: its interval is not reliable; run again with another --seed.)"))

    def datatree_group(self):
        """The ``.nc`` group :data:`HOOP_OR_PRIOR_GROUP`: the equal mixture's joint draws of f, nu, kappa and
        p_mean (given the bars' header values), which a campaign pools in place of the hoop gauge's posterior."""
        import xarray as xr

        ds = xr.Dataset({k: (("draw",), np.asarray(v, float)) for k, v in self.draws.items()},
                        attrs={"description": "the stationary posterior with the hoop gauge (first half of each "
                                              "array) and with nu from the prior file alone (second half), equal parts",
                               "flagged": "; ".join(f"{n}: {d}" for n, d in self.flagged)})
        return xr.DataTree(ds)

    def to_json(self) -> dict[str, object]:
        return {"flagged": dict(self.flagged), "nu_with_hoop": self.nu_hoop, "nu_prior": self.nu_prior,
                "hoop_scale_against_prior_nu": self.gauge_scale, "f_with_hoop": self.f_hoop,
                "f_prior_nu_alone": self.f_prior, "f_quoted": self.f_quoted, "f_given_bar_headers": self.f_given_headers,
                "mixture": "equal parts of the two posteriors", "prior_nu_alone_converged": self.prior_converged}


def reading_over_prediction(hoop: HoopTerm, prior_only: PosteriorSamples, draws: int = 400) -> float:
    """The hoop gauge's window mean over what the model predicts for it from the forces and the prior's nu (the
    prior-only posterior's f and nu, the gauge's calibration 1): the median over ``draws`` of its draws."""
    f, nu = evenly_spaced(prior_only.flat("f"), draws), evenly_spaced(prior_only.flat("nu"), draws)
    predicted = hoop.predict(f, nu, np.ones_like(f)).mean(axis=1)
    return float(np.median(np.mean(hoop.observed) / predicted))


def _readings(samples: PosteriorSamples, data: StationaryData) -> dict[str, np.ndarray]:
    """Every draw's f, nu, kappa and p_mean (Pa)."""
    f, nu = samples.flat("f"), samples.flat("nu")
    derived = derived_draws({"f": f, "nu": nu}, data)
    return {"f": f, "nu": nu, "kappa": derived["kappa"], "p_mean": derived["p_mean"]}


def hoop_or_prior(with_hoop: PosteriorSamples, prior_only: PosteriorSamples, priors: Priors,
                  conflict: PriorDataConflict, hoop: HoopTerm, data: StationaryData) -> HoopOrPrior:
    """The two readings of one record (module docstring): ``with_hoop`` the run's posterior, ``prior_only`` the
    same with the hoop gauge left out; ``hoop`` the likelihood's hoop term (its reading and prediction), ``data``
    the stationary data (for kappa and p_mean)."""
    nu = with_hoop.flat("nu")
    nu_p = np.asarray(priors["nu"].ppf(np.array(QUANTILES)), float)
    a, b = _readings(with_hoop, data), _readings(prior_only, data)
    draws = {k: equal_parts(a[k], b[k]) for k in a}
    f_h, f_p = a["f"], b["f"]
    return HoopOrPrior(_summary(nu), {"q05": float(nu_p[0]), "q50": float(nu_p[1]), "q95": float(nu_p[2])},
                       reading_over_prediction(hoop, prior_only), quoted_summary(f_h), quoted_summary(f_p),
                       quoted_summary(draws["f"]), summarize_draws(draws["f"]),
                       tuple((n, conflict.diagnosis[n]) for n in conflict.flagged), draws, bool(prior_only.converged))
