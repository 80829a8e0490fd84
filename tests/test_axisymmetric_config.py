"""The [model] table: the axisymmetric simulator from the CLI, its refusals, the paper's configuration."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from friction_uq.cli import main
from friction_uq.errors import ConfigError
from friction_uq.record import read_record, read_truth
from friction_uq.simulate import load_config
from friction_uq.simulate.axisymmetric.settings import ModelSettings

PAPER = Path(__file__).resolve().parents[1] / "data" / "configs" / "paper-axisymmetric.toml"
SHORT = "[measurement]\nduration = 1.1e-3\npretrigger = 20e-6\n"
AXI = '[model]\nfidelity = "axisymmetric"\n'


def write(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_default_simulator_stays_the_1d_one(tmp_path: Path) -> None:
    cfg = load_config(write(tmp_path, SHORT))
    assert cfg.model == ModelSettings() and not cfg.model.axisymmetric


def test_the_papers_configuration_asks_for_the_axisymmetric_model_of_table_1() -> None:
    cfg = load_config(PAPER)
    assert cfg.model.axisymmetric and cfg.model.sample_plasticity == "drucker_prager"
    assert (cfg.friction_law, dict(cfg.friction_params)) == ("coulomb", {"f": 0.05})
    assert (cfg.poisson_ratio, cfg.striker_velocity) == (0.4, 10.0)
    assert (cfg.model.cohesion, cfg.model.dp_alpha) == (25e6, 0.64)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (AXI + "element_size = 2e-3\n", "key 'model.element_size' is 2 mm, too coarse for the sample"),
        (AXI + "plug_insertion = 0.01\n", "key 'model.plug_insertion' is 10 mm, not shorter than the plug"),
        (AXI + "[apparatus.tube]\nlength = 0.012\n", "key 'apparatus.tube.length' is 12 mm, shorter than the plug"),
        (AXI + "[apparatus.tube]\ngauge_offset = -0.0099\n", "key 'apparatus.tube.gauge_offset' is -9.9 mm, "
                                                              "which puts the hoop gauge off the tube"),
        ("[model]\nfidelity = \"3d\"\n", "key 'model.fidelity' is '3d', allowed values: 1d, axisymmetric"),
        ('[model]\nfidelity = "axisymmetric"\nmesh = 1\n', "unknown key 'model.mesh'; allowed keys in [model]"),
        (AXI + "sample_plasticity = \"mohr\"\n", "key 'model.sample_plasticity' is 'mohr', allowed values"),
    ],
)
def test_bad_model_tables_are_refused_naming_the_key(tmp_path: Path, text: str, message: str) -> None:
    path = write(tmp_path, SHORT + text)
    with pytest.raises(ConfigError, match=re.escape(message)) as info:
        load_config(path)
    assert str(info.value).startswith(f"{path}: ") and "\n" not in str(info.value)


def test_an_unstable_time_step_is_refused_by_the_cli_with_exit_2(tmp_path: Path, capsys) -> None:
    path = write(tmp_path, SHORT + AXI + "element_size = 1e-3\ntime_step = 5e-7\n")
    out = tmp_path / "t.h5"
    assert main(["simulate", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "key 'model.time_step' is 5e-07 s, above the mesh's stability limit" in err
    assert len(err.splitlines()) == 1 and not out.exists()


def test_a_mesh_too_coarse_is_refused_by_the_cli_with_exit_2(tmp_path: Path, capsys) -> None:
    path = write(tmp_path, SHORT + AXI + "element_size = 1.5e-3\n")
    assert main(["simulate", str(path), "-o", str(tmp_path / "t.h5")]) == 2
    assert "key 'model.element_size' is 1.5 mm, too coarse for the sample" in capsys.readouterr().err


def test_simulate_without_output_or_compare_is_refused(tmp_path: Path, capsys) -> None:
    assert main(["simulate", str(write(tmp_path, SHORT))]) == 2
    assert "give -o RECORD.h5, --compare PAGES.pdf, or both" in capsys.readouterr().err


def test_cli_writes_an_axisymmetric_record_and_the_comparison_pages(tmp_path: Path, capsys) -> None:
    noise = "".join(f"[channels.{c}]\nwhite = 2e-6\n" for c in
                    ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"))
    path = write(tmp_path, SHORT + AXI + "element_size = 1e-3\n" + noise)
    out, pages = tmp_path / "axi.h5", tmp_path / "compare.pdf"
    assert main(["simulate", str(path), "-o", str(out), "--compare", str(pages), "--seed", "3"]) == 0
    text = capsys.readouterr().out
    assert "stationary  F_eo" in text and f"wrote {pages}" in text
    assert pages.read_bytes().startswith(b"%PDF") and pages.stat().st_size > 10_000
    rec = read_record(out)
    truth = read_truth(out)
    assert truth["fidelity"] == "axisymmetric" and truth["element_size"] == 1e-3
    assert rec.channels["tube_hoop"].strain.min() < -100e-6  # the tube swells: compression positive, negative
