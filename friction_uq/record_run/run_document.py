"""A run's JSON document (docs/outputs.md): the f to quote, the stationary posterior's summaries, the run's
settings, checks and provenance, the whole-record check and the diagnosis. Written by :mod:`.pipeline` through
the strict JSON text of :mod:`friction_uq._json_text`."""

from __future__ import annotations

from .. import __version__
from ..diagnostics import VariableSummary
from ..discrepancy.check import WholeRecordCheck
from .outputs import RUN_SCHEMA, RUN_SCHEMA_VERSION, quoted_f, sha256_hex
from .steps import RunSetup, StationaryPosterior

#: The stationary posterior's variables summarised in the JSON (``f`` as ``f_stationary``).
JSON_VARIABLES = ("f", "nu", "kappa", "p_mean", "tau_mean", "V", "ratio")


def _summary_json(v: VariableSummary) -> dict[str, float]:
    return {"mean": v.mean, "sd": v.sd, "q05": v.q05, "q50": v.q50, "q95": v.q95}


def run_document(s: RunSetup, post: StationaryPosterior, *, seed: int, seconds: float, warns: list[str],
                 kinds: list[str], notes: list[str], wrc: WholeRecordCheck | None, diag: object | None, dispersion: bool,
                 nc_bytes: bytes, pdf_bytes: bytes | None) -> dict[str, object]:
    """The run's JSON (docs/outputs.md)."""
    summary, conv = post.summary, post.convergence
    doc: dict[str, object] = {"schema": RUN_SCHEMA, "schema_version": RUN_SCHEMA_VERSION, "warnings": warns,
                              "warning_kinds": kinds,
                              "f": quoted_f(post.f_quoted, post.f_read.to_json(), diag, hoop=post.samples.hoop,
                                            both=None if post.hoop_or_prior is None else post.hoop_or_prior.medians)}
    allv = dict(summary) | {"V": post.V}
    for name in JSON_VARIABLES:
        doc["f_stationary" if name == "f" else name] = _summary_json(allv[name])
    if "hoop_gain" in summary:
        doc["hoop_gain"] = _summary_json(summary["hoop_gain"])
    lab = s.lab
    doc |= {
        "window": [s.prepared.window.t0, s.prepared.window.t1],
        "window_halves": None if s.halves is None else s.halves.to_json(),
        "rhat_max": conv.r_hat_max,
        "ess_min": min(conv.ess_bulk_min, conv.ess_tail_min),
        "seed": seed,
        "seconds": seconds,
        "converged": conv.ok,
        "test_id": s.record.test_id,
        "campaign": s.record.campaign,
        "record_sha256": s.record.sha256,
        "prior_file": str(s.prior_path),
        "hoop_term": s.use_hoop,
        "hoop_left_out": s.hoop_left_out,
        "dispersion_correction": dispersion,
        "analysis_settings": s.settings.to_json(),
        "nu_variance_share_of_f": post.nu_share,
        "f_under_nu_priors": {k: x.to_json() for k, x in post.sensitivity.items()},
        "prior_data_conflict": post.conflict.to_json(),
        "hoop_or_prior": None if post.hoop_or_prior is None else post.hoop_or_prior.to_json(),
        "ppc_ratio_coverage_90": post.ppc.coverage,
        "lab_point_estimate_nominal_nu": {"nu": lab.nu, "f": lab.f, "ratio": lab.ratio},
        "ess_per_second": conv.ess_per_second,
        "notes": notes,
        "outputs": {"netcdf": {"file": s.names["netcdf"].name, "sha256": sha256_hex(nc_bytes)},
                    "pdf": None if pdf_bytes is None else {"file": s.names["pdf"].name,
                                                           "sha256": sha256_hex(pdf_bytes)}},
        "friction_uq_version": __version__,
    }
    if wrc is not None:
        doc["misfit"] = wrc.to_json()
    if diag is not None:
        from ..discrepancy import outcome

        doc["discrepancy"] = outcome.to_json(diag, summary["f"].to_json(), post.f_quoted)
    return doc
