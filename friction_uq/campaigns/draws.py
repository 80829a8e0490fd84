"""Each analysed test's draws as the campaign reads them from the record's ``.nc``, and the campaign's pooled
f and kappa from them (:mod:`.pooling`).

With ``--diagnose`` each record's ``.nc`` names the group of the model its headline f comes from
(``discrepancy_final_group``); that group holds the draws of f_effective and, beside them, the log
density of the prior they were drawn under (``log_prior_f_effective``, written by the run:
friction_uq.discrepancy.effective_prior). The campaign reads both and divides that prior out. Where the run found the hoop gauge and nu's prior in
disagreement, the stationary draws it reads (f, nu, p_mean) are both readings in equal parts, as the run quotes
f, and kappa the reading without the hoop gauge (the ``.nc`` group ``hoop_or_prior``, friction_uq.hoop_or_prior);
such a test is left out of the campaign's nu, and, diagnosed, gives its stationary f (both readings) in place of
its models' f, which read nu through the hoop gauge. A cause ``diagnose`` named gives f under its model, as the
run's headline does.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FrictionUQError
from ..hoop_or_prior import HOOP_OR_PRIOR_GROUP
from ..prior_loader import load_priors
from ..window_halves import WindowHalves
from .job import RecordResult
from .pooling import Pooled, StoredDraws, implied_kappa_log_prior, pool, thin


@dataclass
class RecordPosterior:
    """One analysed test's draws (thinned) read back from its ``.nc``."""

    label: str
    setup: str
    f: np.ndarray
    kappa: np.ndarray
    nu: np.ndarray
    p_mean: np.ndarray
    V: dict[str, float]
    prior_file: str
    #: f under the model the record's diagnosis chose (its headline f): the extended model's f_effective
    #: when a cause was named, the stationary posterior's f when none was; None without a diagnosis
    f_model: np.ndarray | None = None
    #: log density at each of ``f_model``'s draws of the prior they were drawn under: the model's prior on
    #: f_effective as the run stored it beside them, or the prior file's f prior for the stationary f; None
    #: when the record's version stored no prior (the diagnosed f is then not pooled)
    f_model_log_prior: np.ndarray | None = None
    #: kappa's change across the stationary window and the halves' slip, speed and pressure (the slip law's
    #: data); None when the run gave none
    halves: WindowHalves | None = None
    #: the run found the hoop gauge and nu's prior in disagreement (friction_uq.hoop_or_prior): its nu is not a
    #: witness of the campaign's nu
    hoop_disagrees: bool = False
    #: the run's warnings (its JSON's), each a sentence, and each one's kind (none from a result without them)
    warnings: tuple[str, ...] = ()
    warning_kinds: tuple[str, ...] = ()


def read_test_posterior(r: RecordResult, records_dir: Path) -> RecordPosterior:
    """Thinned posterior draws of f, kappa, nu and p_mean from the record's ``.nc``, read with h5py: the groups
    needed, not the whole tree (a diagnosed record's ``.nc`` holds a group per fitted model, and building its
    DataTree took 2.5-4 s where these reads take milliseconds)."""
    import h5py

    nc = records_dir / r.outputs.get("netcdf", "")
    try:
        with h5py.File(nc, "r") as h:
            post = h["posterior"]
            draws = {k: thin(post[k][()]) for k in ("f", "kappa", "nu", "p_mean")}
            both = HOOP_OR_PRIOR_GROUP in h  # the hoop gauge and nu's prior disagree: both readings, as the run quotes f
            if both:
                draws |= _both_readings(h[HOOP_OR_PRIOR_GROUP])
            f_model = f_log_prior = None
            # diagnosed (absent: no diagnosis, or an older version; "": no cause named)
            final = _text(h.attrs.get("discrepancy_final_group"))
            if final and not both:
                group = h[f"{final}/posterior"]
                f_model = thin(group["f_effective"][()])
                if "log_prior_f_effective" in group:
                    f_log_prior = thin(group["log_prior_f_effective"][()])
            elif final is not None:  # diagnosed, no cause named (or its models read nu through a hoop gauge the
                # prior file disputes: the run quotes their f with nu's prior alone in equal parts, a mixture whose
                # prior the campaign cannot divide out): the stationary f, under the prior file's f prior
                f_model = draws["f"]
                f_log_prior = np.asarray(load_priors(r.prior_file)["f"].logpdf(f_model), float)
    except (OSError, KeyError, ValueError) as exc:
        raise FrictionUQError(f"{nc}: cannot read the posterior draws of {r.label} ({exc})") from None
    try:
        halves = None if r.window_halves is None else WindowHalves.from_json(r.window_halves)
    except ValueError as exc:
        raise FrictionUQError(f"the result of {r.label} ({r.path}): key 'window_halves': {exc}") from None
    if f_log_prior is not None and not np.all(np.isfinite(f_log_prior)):
        raise FrictionUQError(f"{nc}: group {final or 'posterior'}: the log prior of f under the diagnosed model is "
                              "not finite at some draws (a draw where its prior has no density cannot be pooled)")
    return RecordPosterior(r.label, str(r.campaign), draws["f"], draws["kappa"], draws["nu"], draws["p_mean"],
                           r.summary["V"], str(r.prior_file), f_model, f_log_prior,
                           halves, both, tuple(r.warnings), tuple(r.warning_kinds))


def _both_readings(group) -> dict[str, np.ndarray]:
    """f, nu and p_mean of the two readings in equal parts; kappa of the reading without the hoop gauge (the
    group's second half), the forces' own: kappa does not depend on nu, and a gauge far off its scale is fitted
    through f and moves the hoop reading's kappa with it (tenfold at three times its scale). A group that holds f
    alone (written by this session's first version) gives f only."""
    out = {"f": thin(group["f"][()])}
    if "kappa" in group:
        kappa = np.asarray(group["kappa"][()], float)
        out |= {"kappa": thin(kappa[kappa.size // 2:]), "nu": thin(group["nu"][()]), "p_mean": thin(group["p_mean"][()])}
    return out


def _text(value: object) -> str | None:
    """An HDF5 attribute read back as text (h5py gives str, bytes or a numpy scalar of either); None if absent."""
    if value is None:
        return None
    if isinstance(value, np.ndarray):
        value = value.item() if value.size == 1 else value.tolist()
    return value.decode() if isinstance(value, bytes | np.bytes_) else str(value)


def pool_tests(tests: Sequence[RecordPosterior]) -> tuple[dict[str, Pooled], dict[str, Pooled], list[str]]:
    """The campaign's pooled f and kappa, the stationary f's pooling when the pooled f is another, and a
    sentence when some tests were diagnosed but the diagnosed f could not be pooled.

    When every test carries f under its diagnosed model with the log prior its draws were made under,
    the pooled f is that f, the prior divided out (``basis`` "diagnosed"); the stationary f's pooling
    is returned beside it. kappa is the stationary analysis's in every case."""
    if not tests:
        return {}, {}, []
    priors = {t.prior_file: load_priors(t.prior_file) for t in tests}
    f_stat = pool(f_draws(tests, "stationary"), "f")
    kappa = pool([StoredDraws(t.label, t.setup, t.kappa, implied_kappa_log_prior(t.kappa, priors[t.prior_file]))
                  for t in tests], "kappa")
    n_diag = sum(t.f_model is not None and t.f_model_log_prior is not None for t in tests)
    if n_diag < len(tests):
        note = [] if not any(t.f_model is not None for t in tests) else [
            f"pooled f: the stationary analysis's, since {n_diag} of {len(tests)} tests carry f under a diagnosed "
            "model with the prior its draws were made under (pooling the diagnosed f needs every test)"]
        return {"f": f_stat, "kappa": kappa}, {}, note
    f_diag = pool(f_draws(tests, "diagnosed"), "f", basis="diagnosed")
    return {"f": f_diag, "kappa": kappa}, {"f": f_stat}, []


def f_draws(tests: Sequence[RecordPosterior], basis: str) -> list[StoredDraws]:
    """Each test's draws of f and the log density of the prior they were drawn under, as the pooling reads them:
    ``basis`` "stationary" (the stationary analysis' f, under its prior file's f prior) or "diagnosed" (f under
    each test's diagnosed model, under the prior the run stored beside it)."""
    if basis == "diagnosed":
        return [StoredDraws(t.label, t.setup, t.f_model, t.f_model_log_prior) for t in tests]
    priors = {t.prior_file: load_priors(t.prior_file) for t in tests}
    return [StoredDraws(t.label, t.setup, t.f, priors[t.prior_file]["f"].logpdf(t.f)) for t in tests]
