"""How a run's results are named and written: the file stem, the netCDF bytes, the terminal table."""

from __future__ import annotations

import hashlib
import re
import unicodedata
from pathlib import Path

from ..diagnostics import Convergence, VariableSummary
from ..errors import OutputError, os_error_text
from ..models.parameters import summarize_draws
from ..prior_sensitivity import PriorDataConflict


def safe_stem(campaign: str, test_id: str) -> str:
    """``<campaign>_<test_id>`` in Unicode's composed form (NFC), with anything but letters and digits (of any script:
    a lab's "Essai-é1" keeps its accent, and differs from "Essai-è1"), '.', '-' and '_' replaced by '_', and no
    leading dot."""
    return re.sub(r"[^\w.-]", "_", unicodedata.normalize("NFC", f"{campaign}_{test_id}")).lstrip(".")



def sha256_hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()



def netcdf_bytes(dt) -> bytes:
    """The DataTree as netCDF bytes, built in memory: nothing is written to TMPDIR (a full one made the HDF5
    library crash on close, and a run killed meanwhile left its file there). Inside a Dask worker xarray
    would guard the write with a distributed lock named after its target, which an in-memory buffer does
    not have: the write runs under dask's synchronous scheduler, so a local lock guards it.

    The bytes depend on the analysis only: the creation times ArviZ stamps on each group are removed
    (:func:`reproducible`), so the same analysis gives the same bytes and the checksum the JSON names."""
    import dask

    try:
        with dask.config.set(scheduler="synchronous"):
            return bytes(reproducible(dt).to_netcdf(engine="h5netcdf"))
    except OSError as exc:
        raise OutputError(f"cannot build the netCDF output in memory ({os_error_text(exc)})") from None


#: Attributes that say when or how fast a result was made, not what it is: left out of the ``.nc``.
TIME_ATTRIBUTES = ("created_at", "sampling_seconds")


def reproducible(dt):
    """A copy of ``dt`` without :data:`TIME_ATTRIBUTES` on any group (the JSON keeps the run's times)."""
    out = dt.copy()
    for node in out.subtree:
        for key in TIME_ATTRIBUTES:
            node.attrs.pop(key, None)
    return out



#: The run's JSON: its schema name and version (14: ``discrepancy.pair_tried``, the pair fitted together on an
#: unexplained first round, named or refused and why; 13: ``discrepancy.named_together``, two causes named together
#: where neither alone explained the misfit; 12: ``warning_kinds``, each warning's kind beside it, a misfit
#: ``misfit_diagnosed`` where f under the causes ``diagnose`` named is the f to quote; 11: a diagnosed ``f`` holds, where the hoop gauge and nu's prior
#: disagree, the diagnosed f and the stationary f from nu's prior alone in equal parts, their medians in
#: ``f.readings_of_nu``; 10: ``hoop_or_prior``, f with the hoop gauge and from nu's prior
#: alone when the two disagree, ``f`` then the two in equal parts; 9: ``discrepancy.shared_delay``, the delay on one gauge the candidates
#: the record does not tell apart agree on; 8: ``discrepancy.causes`` leaves out a later round's chain entry kept
#: in the model within the whole-record check's tolerance, listed in ``discrepancy.within_tolerance``; 7: a ranking
#: entry's ``f_from`` says whether its f is the cut posterior's or the whole-record fit's; 6: a diagnosed model's f and ``nu_extended`` are the cut posterior's,
#: nu from the stationary windows (``discrepancy.nu_source``), the whole record's own reading ``nu_whole_record``;
#: 5: ``window_halves``, kappa's change across the window; 4: ``f``'s interval carries the output bars' calibration, the
#: posterior's own is ``f.given_bar_headers``; 3: ``discrepancy.causes`` holds only the named causes, beside
#: ``fitted_in_turn`` and ``open_candidates``; 2: ``f`` is the f to quote, the stationary analysis' f is
#: ``f_stationary``; version 1 had the stationary f as ``f`` and the f to quote as ``f_headline``: docs/outputs.md).
RUN_SCHEMA = "friction-uq/run-result"
RUN_SCHEMA_VERSION = 14


def quoted_f(f_stationary: dict[str, float], f_stationary_posterior: dict[str, float],
             diagnosis=None, *, hoop: bool = True,
             both: dict[str, float] | None = None) -> dict[str, object]:
    """The JSON's ``f``: the f to quote (:func:`friction_uq.report.quote.f_to_quote`, with the output bars'
    calibration: :mod:`friction_uq.quoted`), the model it comes from, the calibration's sd (the budget, and what was
    folded in beyond what the model's likelihood carries) and the same f given
    the bars' header values (``given_bar_headers``, the posterior's own); where it comes from a fitted model or a
    stacking mixture, how its draws were obtained and the Pareto k of the final model's importance step. ``f_stationary``: the stationary f to quote,
    ``f_stationary_posterior`` its posterior summary."""
    from ..discrepancy.diagnosed_f import f_draws_to_quote, folded_of, headline, readings_of_nu
    from ..likelihood.force_level import RATIO_MODEL_FORM
    from ..physics.bars import FORCE_RATIO_CALIBRATION_SD
    from ..quoted import folded_sd
    from ..report.quote import f_to_quote

    source, fx = f_to_quote(f_stationary, diagnosis, hoop=hoop, both=both)
    named = None if diagnosis is None else headline(diagnosis)
    model = "stationary" if named is None else named[0]
    given = f_stationary_posterior if named is None else summarize_draws(f_draws_to_quote(diagnosis))
    out: dict[str, object] = ({"model": model, "source": source}
                              | {k: fx[k] for k in ("mean", "sd", "q05", "q50", "q95")}
                              | {"bar_calibration_sd": FORCE_RATIO_CALIBRATION_SD, "model_form_sd": RATIO_MODEL_FORM,
                                 "calibration_folded_in_sd": folded_sd() if named is None else folded_of(diagnosis),
                                 "given_bar_headers": {k: given[k] for k in ("mean", "sd", "q05", "q50", "q95")}})
    if named is not None and (two := readings_of_nu(diagnosis)) is not None:  # the two halves' medians
        out["readings_of_nu"] = {"with_hoop_gauge": two["diagnosed"], "prior_nu_alone": two["prior"]}
    if diagnosis is not None and (diagnosis.causes or diagnosis.mixture_f is not None):
        from ..discrepancy.outcome import posterior_method_of

        # the Pareto k judges the importance step of the final model's exact posterior, which a mixture holds in part
        out |= {"posterior_method": posterior_method_of(diagnosis),
                "pareto_k": diagnosis.pareto_k if diagnosis.causes else None,
                "pareto_k_model": diagnosis.final.label if diagnosis.causes else None}
    return out


def summary_table(campaign: str, test_id: str, allv: dict[str, VariableSummary], conv: Convergence,
                  outputs: dict[str, Path], seconds: float, conflict: PriorDataConflict | None = None,
                  findings: list[str] | None = None, *, both: bool = False) -> str:
    """The table the terminal ends with (``both``: the headline is two readings, this table the hoop gauge's)."""
    units = {"p_mean": ("MPa", 1e-6), "tau_mean": ("MPa", 1e-6), "V": ("m/s", 1.0)}
    lines = [f"{campaign} {test_id}: posterior (90 % credible intervals), given the output bars' header values"
             + (", with the hoop gauge (the headline also holds f with nu from the prior file alone)" if both else ""),
             f"{'quantity':<10} {'unit':<5} {'q50':>10} {'q05':>10} {'q95':>10} {'mean':>10} {'sd':>10}"]
    for name in ("f", "nu", "kappa", "hoop_gain", "ratio", "p_mean", "tau_mean", "V"):
        if name not in allv:
            continue
        v = allv[name]
        u, s = units.get(name, ("-", 1.0))
        lines.append(f"{name:<10} {u:<5} {v.q50 * s:>10.4g} {v.q05 * s:>10.4g} {v.q95 * s:>10.4g} "
                     f"{v.mean * s:>10.4g} {v.sd * s:>10.4g}")
    lines.append(f"convergence {'OK' if conv.ok else 'NOT REACHED'}: R-hat max {conv.r_hat_max:.4f}, "
                 f"ESS min {min(conv.ess_bulk_min, conv.ess_tail_min):.0f}, {conv.ess_per_second:.0f} ESS/s; "
                 f"{seconds:.1f} s in all")
    if conflict is not None:
        lines.append(conflict.sentence())
    lines += findings or []
    for k, pth in outputs.items():
        lines.append(f"wrote {pth}")
    return "\n".join(lines)
