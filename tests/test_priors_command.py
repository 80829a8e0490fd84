"""friction-uq priors: materials listed apart from nu alternatives; a new material's starting files read back."""

from __future__ import annotations

import tomllib

import pytest
from scipy import stats

from friction_uq.cli import main
from friction_uq.errors import PriorError
from friction_uq.prior_loader import PRIORS_DIR, default_prior_path, load_priors, prior_files
from friction_uq.record_run.inputs import alternative_nu_priors


def test_shipped_priors_are_the_repositorys_top_level_folder():
    assert PRIORS_DIR.name in ("priors", "prior_files") and (PRIORS_DIR / "I1.toml").is_file()
    assert prior_files() == {"I1": ["I1-nu-tight", "I1-nu-wide"]}


def test_listing_separates_materials_from_alternatives(capsys):
    assert main(["priors"]) == 0
    out = capsys.readouterr().out
    assert "I1               nu alternatives: nu-tight, nu-wide" in out
    assert "\n  I1-nu" not in out  # an alternative is not listed as a material


def test_unknown_material_lists_materials_apart_and_says_how_to_start_one():
    with pytest.raises(PriorError, match=r"no prior file for material 'PMMA'; materials: I1 \(nu alternatives: "
                       r"I1-nu-tight, I1-nu-wide\); write one with 'friction-uq priors PMMA --nu ESTIMATE"):
        default_prior_path("PMMA")


def test_new_material_files_encode_the_estimate(tmp_path, capsys):
    assert main(["priors", "PMMA", "--nu", "0.35", "--nu-sd", "0.03", "--out", str(tmp_path)]) == 0
    default = load_priors(tmp_path / "PMMA.toml")
    nu = default["nu"].frozen()
    # a normal of mean 0.35, sd 0.03 truncated to (0, 0.5): its moments are those of the untruncated one here
    assert nu.mean() == pytest.approx(0.35, abs=1e-6) and nu.std() == pytest.approx(0.03, rel=1e-3)
    assert default.material == "PMMA"
    assert default["f"].frozen().median() == pytest.approx(stats.halfnorm(scale=0.3).median())
    tight = load_priors(tmp_path / "PMMA-nu-tight.toml")["nu"].frozen()
    wide = load_priors(tmp_path / "PMMA-nu-wide.toml")["nu"]
    assert tight.std() == pytest.approx(0.01, rel=1e-3) and wide.support == (0.15, 0.4)
    # a run given PMMA.toml finds the alternatives beside it
    alts = alternative_nu_priors(tmp_path / "PMMA.toml", default)
    assert sorted(alts) == ["default", "nu-tight", "nu-wide"]
    assert "#" in (tmp_path / "PMMA.toml").read_text()  # commented for the lab
    # not replaced without --force; a nu outside (0, 0.5) refused
    assert main(["priors", "PMMA", "--nu", "0.3", "--nu-sd", "0.03", "--out", str(tmp_path)]) == 2
    assert "exists; choose another --out or give --force" in capsys.readouterr().err
    assert main(["priors", "PMMA", "--nu", "0.6", "--nu-sd", "0.03", "--out", str(tmp_path), "--force"]) == 2
    assert "--nu must lie in (0, 0.5)" in capsys.readouterr().err
    # an uncertainty of nu narrower than a measurement gives (1e-300 wrote files that run then refused)
    assert main(["priors", "PMMA", "--nu", "0.35", "--nu-sd", "1e-300", "--out", str(tmp_path), "--force"]) == 2
    assert "--nu-sd must lie in [0.005, 0.25]" in capsys.readouterr().err
    assert tomllib.loads((tmp_path / "PMMA.toml").read_text())["nu"]["mean"] == 0.35
