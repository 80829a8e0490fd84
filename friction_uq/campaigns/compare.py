"""Compare tests across campaigns from the JSON summaries that ``friction-uq run`` writes.

Per test: the posterior of f and of kappa = f nu/(1-nu) (what the forces fix without nu), the
sliding velocity V and the mean wall pressure p_mean. Across tests: weighted least-squares fits
of kappa against V alone, p_mean alone, and both together (weights 1/sd^2 of each test's
posterior). In one set-up V and p_mean both scale with the striker speed, so a trend against
either is confounded; a second campaign with another impedance ratio puts the tests at other
(V, p) pairs, and the joint fit then separates a velocity effect from a pressure effect
(docs/physics.md section 5). Fits on kappa do not depend on the nu prior; f's scale does.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import FrictionUQError
from ..plausible import RANGES

REQUIRED = ("f", "kappa", "nu", "V", "p_mean", "test_id", "campaign")
SUMMARIES = ("f", "kappa", "nu", "V", "p_mean")
STATISTICS = ("mean", "sd", "q05", "q50", "q95")
#: A run's settings that change its summaries, as its JSON names them, and in words
SETTINGS = {"dispersion_correction": "the dispersion correction", "hoop_term": "the hoop term",
            "prior_file": "the prior file"}


@dataclass(frozen=True)
class TestResult:
    """One test's posterior summary (SI units)."""

    campaign: str
    test_id: str
    f: dict[str, float]
    kappa: dict[str, float]
    nu: dict[str, float]
    V: dict[str, float]
    p_mean: dict[str, float]
    path: str
    #: how the run analysed it (the JSON's ``dispersion_correction``, ``hoop_term``, ``prior_file``; None where the
    #: file does not say): tests analysed otherwise are said apart in the table
    settings: tuple[tuple[str, object], ...] = ()


@dataclass(frozen=True)
class TrendFit:
    """kappa = c0 + sum_j c_j x_j, weighted least squares; coefficients, standard errors, chi2/dof."""

    regressors: tuple[str, ...]
    coef: np.ndarray
    se: np.ndarray
    chi2_dof: float
    n: int

    def slope_z(self, name: str) -> float:
        """Slope of ``name`` in standard errors (|z| > 3: a trend the noise does not explain)."""
        j = 1 + self.regressors.index(name)
        return float(self.coef[j] / self.se[j])


#: Where a run's summaries lie (a friction coefficient, a Poisson ratio, a sliding speed and a pressure are not
#: negative; nu is below 0.5; the sample slides no faster than the fastest striker a record may declare,
#: friction_uq.plausible's 200 m/s; the wall's pressure is below 10 GPa, beyond what any bar transmits elastically):
#: a result file outside is not what a run wrote.
SUMMARY_RANGES = {"f": (0.0, math.inf), "kappa": (0.0, math.inf), "nu": (0.0, 0.5),
                  "V": (0.0, RANGES["striker_velocity"][1]), "p_mean": (0.0, 1e10)}


def _check_summary(p: Path, key: str, v: object, *, positive_sd: bool = False) -> None:
    """Refuse, naming the file and the key, a summary that is not finite numbers ``STATISTICS`` with sd >= 0 (> 0
    with ``positive_sd``), or whose mean or median lies outside :data:`SUMMARY_RANGES`."""
    bad = [s for s in STATISTICS if not isinstance(v, dict) or isinstance(v.get(s), bool)
           or not isinstance(v.get(s), (int, float)) or not math.isfinite(v[s])]
    if bad:
        raise FrictionUQError(f"{p}: key {key!r} must hold finite numbers {', '.join(STATISTICS)}; "
                              f"{', '.join(bad)} {'is' if len(bad) == 1 else 'are'} not")
    assert isinstance(v, dict)
    if v["sd"] < 0 or (positive_sd and v["sd"] == 0):
        raise FrictionUQError(f"{p}: key '{key}': sd is {v['sd']!r}, it must be > 0")
    if not v["q05"] <= v["q50"] <= v["q95"]:
        raise FrictionUQError(f"{p}: key '{key}': its quantiles q05 {v['q05']!r}, q50 {v['q50']!r}, q95 {v['q95']!r} "
                              "are not in order")
    low, high = SUMMARY_RANGES.get(key, (-math.inf, math.inf))
    out = [s for s in ("mean", "q50") if not low <= v[s] <= high]  # the tails of a small V may cross 0
    if out:
        raise FrictionUQError(f"{p}: key '{key}': {out[0]} is {v[out[0]]!r}, outside [{low:g}, {high:g}], where a "
                              f"run's {key} lies")


def load_result(path: str | os.PathLike[str]) -> TestResult:
    """Read one ``<campaign>_<test_id>.json`` written by ``friction-uq run``; refuse, in one sentence naming the
    file and the key, one that is not a JSON object with the ids as text and each summary as finite numbers. Its
    f is the stationary analysis' (``f_stationary``, given the bars' header values, as its kappa; ``f`` in a
    file of schema 1)."""
    from .._json_text import read_json_file
    from ..plausible import escaped, unprintable

    p = Path(path)
    doc = read_json_file(p)
    if not isinstance(doc, dict):
        raise FrictionUQError(f"{p}: not a friction-uq run result (a JSON {type(doc).__name__}, not an object)")
    from ..record_run.outputs import RUN_SCHEMA, RUN_SCHEMA_VERSION

    # schema 1 files carry neither key; every later one carries both
    if "schema" in doc or "schema_version" in doc:
        if doc.get("schema") != RUN_SCHEMA:
            raise FrictionUQError(f"{p}: key 'schema' is {doc.get('schema')!r}, not {RUN_SCHEMA!r}: not a friction-uq "
                                  "run result")
        version = doc.get("schema_version")
        if isinstance(version, bool) or not isinstance(version, int) or not 2 <= version <= RUN_SCHEMA_VERSION:
            raise FrictionUQError(f"{p}: key 'schema_version' is {version!r}; this friction-uq reads run results of "
                                  f"versions 1 to {RUN_SCHEMA_VERSION}")
        if "f_stationary" not in doc:
            raise FrictionUQError(f"{p}: key 'f_stationary' is missing, which a result of schema version {version} "
                                  "holds")
    missing = [k for k in REQUIRED if k not in doc]
    if missing:
        raise FrictionUQError(f"{p}: not a friction-uq run result: key(s) {', '.join(missing)} missing")
    # schema >= 2: f_stationary is the stationary f, given the bars' header values as kappa is (f: the f to quote,
    # checked as the others are, though the comparison reads f_stationary)
    field = {"f": "f_stationary"} if "f_stationary" in doc else {}
    if field:
        _check_summary(p, "f", doc["f"])
    doc = doc | {k: doc[v] for k, v in field.items()}
    for key in ("campaign", "test_id"):
        if not isinstance(doc[key], str) or not doc[key].strip() or unprintable(doc[key]):
            shown = escaped(doc[key]) if isinstance(doc[key], str) else repr(doc[key])
            raise FrictionUQError(f"{p}: key {key!r} is {shown!r}, not an id (non-empty text, no control characters)")
    for key in SUMMARIES:
        _check_summary(p, field.get(key, key), doc[key], positive_sd=key == "kappa")
    settings = tuple((k, doc.get(k) if isinstance(doc.get(k), (bool, str)) else None) for k in SETTINGS)
    return TestResult(doc["campaign"], doc["test_id"], doc["f"], doc["kappa"], doc["nu"], doc["V"], doc["p_mean"],
                      str(p), settings)


def fit_trend(results: list[TestResult], regressors: tuple[str, ...]) -> TrendFit:
    """Weighted least squares of kappa (posterior median, weight 1/sd^2) on V and/or p_mean."""
    y = np.array([r.kappa["q50"] for r in results])
    w = 1.0 / np.array([r.kappa["sd"] for r in results]) ** 2
    cols = [np.ones_like(y)] + [np.array([getattr(r, x)["mean"] for r in results]) for x in regressors]
    X = np.column_stack(cols)
    n, k = X.shape
    if n <= k:
        raise FrictionUQError(f"{n} tests cannot fit kappa against {' and '.join(regressors)} ({k} coefficients)")
    sw = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(X * sw[:, None], y * sw, rcond=None)
    resid = (y - X @ coef) * sw
    chi2_dof = float(resid @ resid / (n - k))
    cov = np.linalg.inv((X * w[:, None]).T @ X)
    # scatter beyond the posterior widths widens the standard errors (never narrows them)
    se = np.sqrt(np.diag(cov) * max(1.0, chi2_dof))
    return TrendFit(regressors, coef, se, chi2_dof, n)


@dataclass(frozen=True)
class Comparison:
    results: list[TestResult]
    fits: dict[str, TrendFit]

    @property
    def campaigns(self) -> list[str]:
        return sorted({r.campaign for r in self.results})


def compare(paths: list[str | os.PathLike[str]]) -> Comparison:
    """Load the results and fit the trends that the number of tests allows."""
    results = sorted((load_result(p) for p in paths), key=lambda r: (r.campaign, r.test_id))
    if not results:
        raise FrictionUQError("no result files given")
    for a, b in zip(results, results[1:]):  # one test counted twice would weigh twice in the trends
        if (a.campaign, a.test_id) == (b.campaign, b.test_id):
            raise FrictionUQError(f"{b.path}: test {a.campaign} {a.test_id} is also given as {a.path}; a test "
                                  "counts once in a comparison")
    fits: dict[str, TrendFit] = {}
    for name, regs in (("V", ("V",)), ("p_mean", ("p_mean",)), ("V+p_mean", ("V", "p_mean"))):
        X = np.column_stack([np.ones(len(results))] + [[getattr(r, x)["mean"] for r in results] for x in regs])
        if len(results) > len(regs) + 1 and np.linalg.matrix_rank(X) == X.shape[1]:  # the regressors vary
            fits[name] = fit_trend(results, regs)
    return Comparison(results, fits)


def comparison_table(c: Comparison) -> str:
    """Plain-text table of the tests and the trend fits."""
    lines = [f"{'campaign':<9} {'test':<8} {'V m/s':>7} {'p_mean MPa':>10} {'kappa q50':>10} {'kappa sd':>9} "
             f"{'f q50':>7} {'f q05':>7} {'f q95':>7} {'nu q50':>7}"]
    for r in c.results:
        lines.append(f"{r.campaign:<9} {r.test_id:<8} {r.V['mean']:>7.2f} {r.p_mean['q50'] / 1e6:>10.1f} "
                     f"{r.kappa['q50']:>10.5f} {r.kappa['sd']:>9.5f} {r.f['q50']:>7.4f} {r.f['q05']:>7.4f} "
                     f"{r.f['q95']:>7.4f} {r.nu['q50']:>7.3f}")
    units = {"V": ("per m/s", 1.0), "p_mean": ("per MPa", 1e6)}
    for name, fit in c.fits.items():
        parts = []
        for j, reg in enumerate(fit.regressors, start=1):
            u, s = units[reg]
            parts.append(f"d kappa/d {reg} = {fit.coef[j] * s:+.2e} +- {fit.se[j] * s:.1e} {u} "
                         f"({fit.slope_z(reg):+.1f} se)")
        lines.append(f"fit kappa ~ {name}: " + "; ".join(parts) + f"; chi2/dof {fit.chi2_dof:.2f} ({fit.n} tests)")
    lines += settings_differences(c.results)
    if len(c.campaigns) < 2 and "V" in c.fits:
        lines.append("one campaign: V and p_mean rise together with the striker speed, so a trend cannot be "
                     "assigned to one of them (docs/physics.md section 5)")
    return "\n".join(lines)


def settings_differences(results: list[TestResult]) -> list[str]:
    """One line per setting the tests were analysed with that differs among them (the trends then mix analyses:
    a dispersion correction moves kappa by a few per cent), naming each test's value."""
    out = []
    for key, words in SETTINGS.items():
        values = {r.test_id if len({q.test_id for q in results}) == len(results) else f"{r.campaign} {r.test_id}":
                  dict(r.settings).get(key) for r in results}
        distinct = set(values.values())
        if len(distinct) > 1:
            whole = len({_setting_text(v) for v in distinct}) < len(distinct)  # two files of one name: their paths
            said = "; ".join(f"{t}: {v if whole and isinstance(v, str) else _setting_text(v)}"
                             for t, v in values.items())
            out.append(f"analysed differently, {words}: {said} (the trends above mix them)")
    return out


def _setting_text(value: object) -> str:
    if value is None:
        return "not recorded"
    if isinstance(value, bool):
        return "on" if value else "off"
    return Path(str(value)).name
