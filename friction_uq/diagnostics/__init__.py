"""Posterior diagnostics and summaries: plain data for the report (which only draws them).

* :func:`build_datatree`: ArviZ 1.x ``xarray.DataTree`` with groups posterior (sampled and
  derived variables), log_likelihood (per time segment), observed_data, sample_stats, prior;
  dims ("chain", "draw") where chain = an independent emcee ensemble (see
  :mod:`friction_uq.sampler`).
* :func:`convergence`: R-hat max and ESS min (arviz_stats), ESS per second.
* :func:`summarize`: mean, sd, q05, q50, q95 (+ R-hat, ESS) per variable as floats.
* :func:`f_given_nu`, :func:`nu_variance_share`: how the uncertainty of nu propagates into f;
  :func:`nu_sensitivity` and :func:`prior_data_conflict` live in
  :mod:`friction_uq.prior_sensitivity` (re-exported here).
* :func:`ratio_ppc`: posterior predictive of F_eo/F_io over the window.

Derived variables per draw (SI units): ratio r = expm1(f beta(nu)) (eq. 5, 13); kappa = f nu/(1-nu);
tau_mean = r <x> / (2 pi R L) (eq. 18, with <x> the window mean of the latent true F_io given r,
:meth:`~friction_uq.likelihood.ForceTerm.latent_internal_force`); p_mean = tau_mean / f (eq. 20).
"""

from ..prior_sensitivity import FUnderPrior, PriorDataConflict, nu_sensitivity, prior_data_conflict
from .convergence import QUANTILES, SUMMARY_VARIABLES, Convergence, VariableSummary, convergence, summarize
from .datatree import build_datatree, derived_draws, pointwise_log_likelihood
from .ppc import RatioPPC, ratio_ppc
from .propagation import FNuBand, f_given_nu, nu_variance_share


__all__ = [
    "QUANTILES", "SUMMARY_VARIABLES", "Convergence", "FNuBand", "FUnderPrior", "PriorDataConflict", "RatioPPC",
    "VariableSummary", "build_datatree", "convergence", "derived_draws", "f_given_nu", "nu_sensitivity",
    "nu_variance_share", "pointwise_log_likelihood", "prior_data_conflict", "ratio_ppc", "summarize",
]
