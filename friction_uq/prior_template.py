"""Starting prior files for a new sample material, from the lab's estimate of nu and its uncertainty.

``friction-uq priors MATERIAL --nu 0.35 --nu-sd 0.03`` writes three files a run uses together:

* ``MATERIAL.toml``: f weakly informative (half-normal, scale 0.3), nu a normal of the estimate and
  its uncertainty truncated to the physical range (0, 0.5), the hoop gauge's calibration 5 %;
* ``MATERIAL-nu-tight.toml``: nu as a dedicated measurement would know it (a third of the
  uncertainty, at least 0.005);
* ``MATERIAL-nu-wide.toml``: nu unknown within a range about the estimate (uniform from 0.2 below
  to 0.05 above, inside 0.01-0.49): f falls fastest with nu at low nu, so the range reaches further
  down. A run finds the alternatives beside the file it is given and reports f under each.

Each is commented for the lab to edit; docs/priors.md describes the format.
"""

from __future__ import annotations

import json

from .plausible import RANGES, out_of_range, unprintable

#: The starting files' alternative nu priors keep within these (the lower bound the records' own, plausible.RANGES)
NU_MIN, NU_MAX = RANGES["sample.poisson_ratio"][0], 0.49

_COMMON_F = """\
[f]
# Friction coefficient, f >= 0. Weakly informative: a half-normal of scale 0.3 has median 0.20 and
# 90 % quantile 0.49, so coefficients from 0.02 to 0.6 all keep substantial mass and f > 1 is very
# unlikely (0.1 %). Narrow it only with evidence on this material pair (earlier tests, the literature).
distribution = "halfnormal"
scale = 0.3
note = "half-normal, scale 0.3: weakly informative on f >= 0"
"""

_COMMON_HOOP = """\
[hoop_gain]
# Calibration factor g of the tube's hoop gauge (reading = g x model): gauge factor tolerance (~1 %),
# transverse sensitivity and bonding (~2 %), the fit of the tube's influence function (2.4 %, docs/physics.md
# section 6): about 5 %. It depends on the gauge, not on the sample: keep it unless your calibration says more.
distribution = "lognormal"
median = 1.0
sigma = 0.05
note = "lognormal around 1, 5 %: gauge factor, bonding, kernel fit"
"""


#: Smallest uncertainty of nu a prior file may state: what a dedicated measurement gives (the tight alternative's
#: floor too); a narrower one would let the prior, not the data, fix f (eq. 17 reads only f nu / (1 - nu)).
MIN_NU_SD = 0.005


def _check(nu: float, sd: float) -> None:
    if not 0.0 < nu < 0.5:
        raise ValueError(f"--nu must lie in (0, 0.5), the Poisson ratio of an elastic solid, got {nu:g}")
    if odd := out_of_range("sample.poisson_ratio", nu):  # the range a record's sample and `analyze --nu` take
        raise ValueError(f"--nu {odd}")
    if not MIN_NU_SD <= sd <= 0.25:
        raise ValueError(f"--nu-sd must lie in [{MIN_NU_SD:g}, 0.25] (a measurement of nu knows it to {MIN_NU_SD:g} at "
                         f"best), got {sd:g}")


def _check_source(source: str) -> None:
    try:
        source.encode("utf-8")
    except UnicodeEncodeError:  # bytes of another encoding, passed through as lone surrogates
        raise ValueError("--source holds bytes that are not UTF-8 text") from None
    bad = unprintable(source)
    if bad:
        raise ValueError(f"--source {bad}: it is written on one line of the prior files")


def _head(material: str, description: str, source: str) -> str:
    """The files' head; ``description`` as a TOML basic string (a JSON string is one: quotes and backslashes
    escaped)."""
    return (f"# Priors for the sample material {material} (written by friction-uq priors; edit to suit).\n"
            f"# {source}\n"
            "# Read by friction-uq run --priors THIS_FILE; every key is checked (a typo is refused). docs/priors.md.\n"
            f'material = "{material}"\n'
            f"description = {json.dumps(description)}\n\n")


def default_text(material: str, nu: float, sd: float, source: str = "") -> str:
    """The text of ``MATERIAL.toml``."""
    _check(nu, sd)
    _check_source(source)
    src = source or "nu estimated by the lab"
    return (_head(material, f"{material} default: nu {nu:g} +- {sd:g} ({src}), f weakly informative, hoop gauge 5 %",
                  f"nu: {src}.")
            + _COMMON_F + "\n"
            + "[nu]\n"
            + f"# Sample Poisson ratio: the lab's estimate {nu:g} with uncertainty {sd:g} (1 sd), truncated to the\n"
            + "# physical range of an isotropic elastic solid (0, 0.5). f is identified through f nu / (1 - nu)\n"
            + "# (docs/physics.md section 3): the uncertainty of nu passes almost whole into f. State it honestly.\n"
            + f'distribution = "truncnormal"\nmean = {nu:g}\nsd = {sd:g}\nlower = 0.0\nupper = 0.5\n'
            + f'note = "nu {nu:g} +- {sd:g}: truncated normal on (0, 0.5)"\n\n'
            + _COMMON_HOOP)


def tight_text(material: str, nu: float, sd: float) -> str:
    """The text of ``MATERIAL-nu-tight.toml`` (nu as a measurement would know it)."""
    _check(nu, sd)
    tight = max(sd / 3.0, MIN_NU_SD)
    return (_head(material, f"{material} sensitivity: nu measured, {nu:g} +- {tight:.3g}",
                  "Sensitivity alternative: how f would tighten if nu were measured (e.g. by ultrasonic wave speeds).")
            + _COMMON_F + "\n"
            + "[nu]\n# nu known to a third of the lab's uncertainty (at least 0.005), as a dedicated measurement\n"
            + "# would give.\n"
            + f'distribution = "truncnormal"\nmean = {nu:g}\nsd = {tight:.3g}\nlower = 0.0\nupper = 0.5\n'
            + f'note = "nu measured: truncated normal sd {tight:.3g}"\n\n'
            + _COMMON_HOOP)


def wide_text(material: str, nu: float, sd: float) -> str:
    """The text of ``MATERIAL-nu-wide.toml`` (nu unknown within a range about the estimate)."""
    _check(nu, sd)
    lo, hi = max(NU_MIN, round(nu - 0.2, 3)), min(NU_MAX, round(nu + 0.05, 3))
    return (_head(material, f"{material} sensitivity: nu uniform {lo:g}-{hi:g}",
                  "Sensitivity alternative: nothing known about nu beyond a range about the estimate.")
            + _COMMON_F + "\n"
            + "[nu]\n# Uniform from 0.2 below the estimate to 0.05 above (inside 0.01-0.49): f grows fastest as nu\n"
            + "# falls, so the range reaches further down.\n"
            + f'distribution = "uniform"\nlower = {lo:g}\nupper = {hi:g}\n'
            + f'note = "nu unknown within {lo:g}-{hi:g}: uniform"\n\n'
            + _COMMON_HOOP)


def prior_texts(material: str, nu: float, sd: float, source: str = "") -> dict[str, str]:
    """File name -> text of the three starting files of ``material``."""
    return {f"{material}.toml": default_text(material, nu, sd, source),
            f"{material}-nu-tight.toml": tight_text(material, nu, sd),
            f"{material}-nu-wide.toml": wide_text(material, nu, sd)}
