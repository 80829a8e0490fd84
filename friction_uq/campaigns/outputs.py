"""The campaign's outputs: ``campaign.json`` (schema below), ``campaign.nc`` and the text summary.

``campaign.json`` (``schema = "friction-uq/campaign"``, ``schema_version = 7``; version 6 had no record's
``warning_kinds``, and counted a misfit whose causes ``diagnose`` named as a warning against the pooled diagnosed f;
version 5 had no record's ``warnings`` nor ``pooled_without_warned``; version 1 had no weights, and its
set-up offsets were free; version 2 pooled the stationary f whatever the records carried, and had no ``basis``
nor ``pooled_stationary``; version 3's pressure law was a straight line in p, its parameters ``f_ref`` and
``c_per_p_ref``; version 4 had no slip law, and its ELPDs were of the tests' levels alone, without each
test's change across its window, so they are not comparable with version 5's): ``records`` (each
record's path, set-up, test id, ``status`` done | skipped | failed, the refusal ``message``,
seconds, the ``causes`` its diagnosis named or null, the run's ``warnings`` and their ``warning_kinds``), ``counts``, ``pooled`` (``f`` and ``kappa``: population mean ``mu`` and between-test
scatter ``sigma`` with 90 % intervals, each test's effective sample size, the Monte Carlo variance
of the hyper-log-likelihood, or ``refused`` with the reason; ``basis``: ``diagnosed`` when f is f under each
test's diagnosed model (every test diagnosed), its prior on f_effective divided out, else ``stationary``),
``pooled_stationary`` (``f`` of the stationary analysis, as in ``pooled``, when ``pooled.f`` is the diagnosed f;
else empty), ``pooled_without_warned`` (``f`` pooled as ``pooled.f`` from the tests whose runs gave no warning
that ``pooled.f`` leaves open, or null when none did: :mod:`.warned`), ``friction_law`` (``best``: the law that
carries the stacking weight (one of constant, velocity, pressure, slip, pressure+velocity) or null;
``chosen_model``; ``weights``: each law's stacking weight; ``supported``: the fewest laws carrying 90 %
of it; ``ranking``: every model with ELPD, dELPD and its SE against the top, and its weight;
``posterior`` of the best (else heaviest) law's parameters in f units; ``models``: the same for every
model; ``meanings``: each parameter in words with its unit; ``next_tests``: when the laws are not separated,
each candidate test (set-up, V, p) with the expected information it brings on which law holds, most
informative first (:mod:`.next_test_choice`); ``pressure_or_setup``: with two set-ups, when a law with a pressure term
is named or the second set-up is flagged by the laws with and without its offset, the best law with a free offset
on that set-up against the best without (dELPD, SE, ``d_elpd_rest`` with the test that favours it most left out, the
weight the laws with the offset carry among all the models, ``without_ruled_out``: the laws without it ruled out by
the package's rule, which flags the set-up, ``laws`` the number of laws compared; empty otherwise); ``windows_read``: whether each test's change across its window entered the laws'
likelihood (the slip law is compared only then); ``nu`` the campaign's nu),
``wall_seconds`` (``records``: the records' tasks, ``analysis``: the campaign's own analysis; added by
``run_campaign``), ``flagged`` (set-ups and tests; a set-up's entry says the ``basis`` its offset was measured on:
the law's, or, for a diagnosed campaign, also ``kappa`` of the stationary analysis with
``offset_diagnosed`` and ``explained_by_causes``), ``causes`` (per set-up tally of the per-record causes) and
``statements`` (the sentences the summary prints).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from .._atomic import atomic_path, write_bytes
from .._json_text import json_text
from .analysis import CampaignAnalysis, f_law_draws, supported_laws
from .job import RecordResult
from .warned import warned_statement

SCHEMA = "friction-uq/campaign"
SCHEMA_VERSION = 7


#: The law parameters' meanings and units, as the JSON's ``friction_law.meanings`` and the sentences give them.
MEANINGS = {
    "f": "f (-)",
    "f_s": "f at rest, V -> 0 (-)",
    "f_d": "f at high sliding speed (-)",
    "f_s_at_mean_p": "f at rest, V -> 0, at the campaign's mean wall pressure (-)",
    "f_d_at_mean_p": "f at high sliding speed, at the campaign's mean wall pressure (-)",
    "v_c": "sliding speed over which f changes by 63 % of its way from its value at rest to its value at high speed (m/s)",
    "f_at_least_slip": "f at the smallest mean slip over a window tested (-)",
    "f_at_most_slip": "f at the largest mean slip over a window tested (-)",
    "S_c_mm": "slip over which the slip law changes f by 63 % of its whole change (mm)",
    "f_at_lowest_p": "f at the lowest wall pressure tested (-)",
    "f_at_highest_p": "f at the highest wall pressure tested (-)",
    "p_c_MPa": "wall pressure over which the pressure term changes f by 63 % of its whole change (MPa)",
    "df_dp_per_MPa": "change of f per MPa of wall pressure, at the campaign's mean pressure (1/MPa)",
    "scatter_rel": "test-to-test scatter of f beyond each test's own uncertainty (relative)",
}


#: What a pooled value's draws are, by its ``basis`` (pooling.Pooled.basis).
POOLED_BASIS = {
    "stationary": "of the stationary analysis",
    "diagnosed": "under each test's diagnosed model (its prior on f_effective divided out)",
}


def parameter_words(name: str) -> str:
    """A law parameter in words with its unit ('calibration_B': set-up B's calibration offset, relative)."""
    if name in MEANINGS:
        return MEANINGS[name]
    if name.startswith("calibration_"):
        return f"set-up {name[12:]}'s calibration offset (relative)"
    if name.startswith("offset_"):
        return f"set-up {name[7:]}'s free offset (relative)"
    return name


def statements(ca: CampaignAnalysis) -> list[str]:
    """The campaign's conclusions in sentences (what the terminal and the report's first page say)."""
    out = []
    out.extend(ca.sentences)
    if ca.law_posterior:
        name = ca.chosen or ca.law_models[max(ca.weights, key=ca.weights.get)]
        parts = [f"{parameter_words(k)} {v['q50']:.3g} [{v['q05']:.3g}, {v['q95']:.3g}]"
                 for k, v in ca.law_posterior.items()]
        basis = "" if ca.law_data.basis == "kappa" else f", fitted to {ca.law_data.meaning}"
        out.append(f"{name} law{basis} (median [90 %]): " + "; ".join(parts))
    for f in ca.flagged:
        if "setup" in f:
            off = f["offset"]
            rel = f" relative to {f['relative_to']}" if "relative_to" in f else ""
            basis = str(f.get("basis", ca.law_data.basis))
            what = "'s stationary analysis" if basis != ca.law_data.basis else ""
            out.append(f"flagged: set-up {f['setup']}{what} does not follow the shared law{rel}: {basis} offset "
                       f"{off['q50'] * 100:+.0f} % [{off['q05'] * 100:+.0f}, {off['q95'] * 100:+.0f}], dELPD "
                       f"{f['d_elpd']:.1f} (SE {f['d_se']:.1f})"
                       + (f", the laws with this offset carrying {f['weight_with_offset']:.2f} of the weight"
                          if "weight_with_offset" in f else ""))
            out.extend(str(f[key]) for key in ("note", "note_diagnosed", "note_causes") if key in f)
            out.extend(str(c) for c in f["causes"].values())
        else:
            out.append(f"flagged: test {f['test']} lies {f['below_median_by']:.1f} below the others' leave-one-out "
                       "log density under the chosen law")
    disagree = [t.label for t in ca.tests if t.hoop_disagrees]
    if disagree:
        many = len(disagree) > 1
        their, are = ("their", "they are") if many else ("its", "it is")
        out.append(f"{'tests' if many else 'test'} {', '.join(disagree)}: the hoop gauge and the prior file disagree "
                   f"on nu ({'each' if many else 'the'} run's warning): {their} stationary f is both readings in "
                   f"equal parts (in place of the diagnosed f, whose models read nu through the hoop gauge, when "
                   f"diagnosed), {their} kappa the forces' own, and {are} left out of the campaign's nu")
    # after the law: what the tests share; the stationary f's pooling just after the diagnosed f's
    for p in [q for name, p in ca.pooled.items() for q in (p, ca.pooled_stationary.get(name)) if q is not None]:
        if p.refused:
            out.append(p.refused + ("" if p.basis == "stationary" else f" ({POOLED_BASIS[p.basis]})"))
        else:
            out.append(f"pooled {p.variable} {POOLED_BASIS[p.basis]}: population mean {p.mu['q50']:.4g} "
                       f"[{p.mu['q05']:.4g}, {p.mu['q95']:.4g}], between-test scatter {p.sigma['q50']:.2g} "
                       f"[{p.sigma['q05']:.2g}, {p.sigma['q95']:.2g}] (90 %; {len(p.tests)} tests, smallest ESS "
                       f"{min(p.ess.values()):.0f}, Monte Carlo variance of the pooled log-likelihood "
                       f"{p.mc_variance:.2g})")
    if said := warned_statement(ca.tests, ca.pooled.get("f"), ca.pooled_without_warned):
        out.append(said)
    return out


def campaign_doc(results: Sequence[RecordResult], ca: CampaignAnalysis | None, *, seed: int,
                 settings: dict[str, Any]) -> dict[str, Any]:
    counts = {s: sum(r.status == s for r in results) for s in ("done", "skipped", "failed")}
    doc: dict[str, Any] = {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION, "friction_uq_version": __version__, "seed": seed,
        "settings": settings, "counts": counts,
        "records": [{"path": r.path, "campaign": r.campaign, "test_id": r.test_id, "status": r.status,
                     "message": r.message, "seconds": r.seconds, "converged": r.converged, "notes": r.notes,
                     "causes": r.causes, "warnings": r.warnings,
                     "warning_kinds": r.warning_kinds}
                    for r in results],
    }
    if ca is None:
        doc |= {"pooled": {}, "pooled_stationary": {}, "pooled_without_warned": None,
                "friction_law": {"best": None, "ranking": []}, "flagged": [],
                "causes": {}, "statements": ["no record was analysed: nothing to pool"]}
        return doc
    models = {}
    for name, fit in ca.fits.items():
        draws = f_law_draws(fit, ca.nu, seed=seed)
        models[name] = {k: {"q05": float(np.quantile(v, 0.05)), "q50": float(np.median(v)),
                            "q95": float(np.quantile(v, 0.95))} for k, v in draws.items()}
    doc |= {
        "pooled": {k: p.to_json() for k, p in ca.pooled.items()},
        "pooled_stationary": {k: p.to_json() for k, p in ca.pooled_stationary.items()},
        "pooled_without_warned": None if ca.pooled_without_warned is None else ca.pooled_without_warned.to_json(),
        "friction_law": {"best": ca.best, "chosen_model": ca.chosen, "ranking": ca.ranking,
                         "weights": ca.weights, "supported": supported_laws(ca.weights, ca.ranking) if ca.weights else [],
                         "posterior": ca.law_posterior, "models": models,
                         "meanings": {k: parameter_words(k) for m in models.values() for k in m},
                         "next_tests": [{"setup": c.setup, "V": c.V, "p": c.p, "information_nats": c.information}
                                        for c in ca.next_tests],
                         "pressure_or_setup": {k: v for k, v in ca.pressure_or_setup.items() if k != "sentence"},
                         "nu": {"mean": ca.nu[0], "sd": ca.nu[1]},
                         "fitted_to": None if ca.law_data is None else ca.law_data.meaning,
                         "windows_read": bool(ca.law_data is not None and ca.law_data.reads_window_changes)},
        "flagged": ca.flagged,
        "causes": ca.tallies,
        "statements": statements(ca),
    }
    return doc


def write_json(doc: dict[str, Any], path: Path) -> Path:
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json_text(doc))
    return path


def _group(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]", "_", name)


def write_netcdf(ca: CampaignAnalysis, path: Path) -> Path:
    """Grid hyper-posteriors, the per-test points and every law's draws as an xarray DataTree."""
    import xarray as xr

    groups: dict[str, xr.Dataset] = {}
    for prefix, pooled in (("pooled", ca.pooled), ("pooled_stationary", ca.pooled_stationary)):
        for name, p in pooled.items():
            if p.log_post is not None:
                groups[f"{prefix}_{name}"] = xr.Dataset({"log_posterior": (("sigma", "mu"), p.log_post)},
                                                        coords={"mu": p.grid_mu, "sigma": p.grid_sigma},
                                                        attrs={"basis": p.basis, "draws": POOLED_BASIS[p.basis]})
    if ca.law_data is not None:
        d = ca.law_data
        window = {}
        if d.slip is not None and d.trend is not None and d.halves is not None:
            window = {"slip": ("test", d.slip, {"units": "m"}),
                      "log_kappa_change": ("test", d.trend[:, 0], {"meaning": "ln(kappa_2 / kappa_1) across the window"}),
                      "log_kappa_change_sd": ("test", d.trend[:, 1]),
                      "half_slip": (("test", "half"), d.halves[:, :, 0], {"units": "m"}),
                      "half_V": (("test", "half"), d.halves[:, :, 1], {"units": "m/s"}),
                      "half_p_over_p": (("test", "half"), d.halves[:, :, 2])}
        groups["tests"] = xr.Dataset(
            {k: ("test", getattr(d, k)) for k in ("kappa", "kappa_sd", "V", "V_sd", "p", "p_sd")}
            | {"setup": ("test", np.array(d.setups, dtype=str))} | window,
            coords={"test": np.array(d.labels, dtype=str)},
            attrs={"kappa_holds": d.basis, "windows_read": int(d.reads_window_changes)})
        for name, fit in ca.fits.items():
            groups[f"law_{_group(name)}"] = xr.Dataset(
                {"draws": (("draw", "parameter"), fit.draws)},
                coords={"parameter": list(fit.model.params)},
                attrs={"model": name, "kappa_bar": fit.kbar, "p_ref": fit.p_ref,
                       "units": "kappa / kappa_bar" if fit.data.basis == "kappa" else "f / f_bar",
                       "parameter_units": "log_vc: ln(m/s); log_pc: ln(p / p_ref); log_sc: ln(m); r: relative"})
    dt = xr.DataTree.from_dict({"/": xr.Dataset(attrs={"friction_uq_version": __version__,
                                                       "best_law": ca.best or "none"})}
                               | {f"/{k}": v for k, v in groups.items()})
    from ..record_run import netcdf_bytes

    return write_bytes(path, netcdf_bytes(dt))  # built in memory (HDF5 crashes on a disk that fills mid-file)


def summary_text(doc: dict[str, Any]) -> str:
    """Plain-text campaign summary: one line per record, then the statements."""
    lines = [f"{'record':<28} {'set-up':<7} {'test':<8} {'status':<8} {'s':>6} {'warnings':>8}  message"]
    for r in doc["records"]:
        lines.append(f"{Path(r['path']).name:<28} {r['campaign'] or '-'!s:<7} {r['test_id'] or '-'!s:<8} "
                     f"{r['status']:<8} {r['seconds']:>6.1f} {len(r.get('warnings') or []):>8}  {r['message'] or ''}")
    c = doc["counts"]
    lines.append(f"{c['done']} analysed, {c['skipped']} up to date, {c['failed']} failed")
    ranking = doc["friction_law"].get("ranking") or []
    if ranking:
        lines.append(f"{'model':<32} {'ELPD':>8} {'SE':>6} {'dELPD':>7} {'dSE':>6}")
        for m in ranking:
            lines.append(f"{m['model']:<32} {m['elpd']:>8.1f} {m['se']:>6.1f} {m['d_elpd']:>7.1f} {m['d_se']:>6.1f}")
    lines.extend(doc["statements"])
    return "\n".join(lines)
