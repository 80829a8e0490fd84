"""Simulation configurations: good ones load with their values, bad ones are refused by name."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from friction_uq.errors import ConfigError
from friction_uq.record import read_record, read_truth
from friction_uq.simulate import load_config, simulate, simulate_to_file

GOOD = """
[record]
test_id = "X-01"
campaign = "X"
dtype = "float32"
seed = 7
date = "2024-05-02"

[loading]
striker_velocity = 12
rise_time = 15e-6

[sample]
poisson_ratio = 0.35

[friction]
law = "slip_weakening"
f_s = 0.09
f_d = 0.05
d_c = 2e-3

[cell]
gap = 6e-6
tube_compliance = true

[measurement]
duration = 1.2e-3
pretrigger = 60e-6

[channels.input_bar]
white = 3e-6
ar1 = 2e-6
ar1_coef = 0.4
offset = 2e-5
quantum = 5e-7

[channels.external_output_bar]
units = "V"
strain_per_volt = 2e-4
white = 1e-6

[channels.tube_hoop]
units = "microstrain"
white = 1e-6

[apparatus.internal_output_bar]
young_modulus = 110e9
wave_speed = 4970.0
"""


def write(tmp_path: Path, text: str, name: str = "cfg.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_a_good_config_loads_with_its_values_and_defaults(tmp_path: Path) -> None:
    cfg = load_config(write(tmp_path, GOOD))
    assert cfg.test_id == "X-01" and cfg.seed == 7 and cfg.dtype == "float32"
    assert cfg.striker_velocity == 12.0 and isinstance(cfg.striker_velocity, float)
    assert cfg.friction_law == "slip_weakening" and dict(cfg.friction_params) == {"f_s": 0.09, "f_d": 0.05,
                                                                                   "d_c": 2e-3}
    assert cfg.apparatus.internal_output_bar.young_modulus == 110e9
    assert cfg.apparatus.internal_output_bar.gauge_distance == 0.33  # default kept
    assert cfg.channels["external_output_bar"].units == "V"
    assert cfg.channels["internal_output_bar"].white == 0.0
    assert cfg.apparatus.plug is not None


def test_an_empty_config_is_the_paper_set_up(tmp_path: Path) -> None:
    cfg = load_config(write(tmp_path, ""))
    assert cfg.friction_law == "coulomb" and cfg.friction_params["f"] == 0.05
    assert cfg.apparatus.input_bar.length == 2.5 and cfg.poisson_ratio == 0.4


def test_the_written_record_follows_the_contract(tmp_path: Path) -> None:
    cfg = load_config(write(tmp_path, GOOD))
    path = simulate_to_file(cfg, tmp_path / "x.h5")
    rec = read_record(path)
    sim = simulate(cfg)  # seed from the config
    assert rec.test_id == "X-01" and rec.campaign == "X" and rec.sample_rate == 5e6
    assert rec.t0 == pytest.approx(-60e-6) and rec.duration == pytest.approx(1.2e-3)
    assert rec.channels["external_output_bar"].units == "V"
    assert rec.channels["tube_hoop"].units == "microstrain"
    for name in sim.noisy:
        assert np.allclose(rec.strain(name), sim.noisy[name], rtol=1e-6, atol=1e-9)  # float32 storage
    # gauge sign in the file: a compressive incident wave reads negative
    import h5py

    with h5py.File(path) as fh:
        raw = fh["signals/input_bar"][()]
        assert raw.dtype == np.float32
        assert raw[np.argmax(np.abs(raw[:2000]))] < 0
    truth = read_truth(path)
    assert truth["friction_law"] == "slip_weakening" and truth["friction_d_c"] == 2e-3
    assert truth["gap"] == 6e-6 and truth["nu"] == 0.35 and truth["seed"] == 7
    assert rec.apparatus.internal_output_bar.young_modulus == 110e9


@pytest.mark.parametrize(
    "text, message",
    [
        ("[frction]\nf = 0.1\n", "unknown section [frction]; allowed sections: record, loading"),
        ("[loading]\nstriker_speed = 10\n", "unknown key 'loading.striker_speed'; allowed keys in [loading]: "
                                           "striker_velocity, rise_time"),
        ("[loading]\nstriker_velocity = \"ten\"\n", "key 'loading.striker_velocity' must be a number, got 'ten'"),
        ("[loading]\nstriker_velocity = true\n", "key 'loading.striker_velocity' must be a number, got True"),
        ("[sample]\npoisson_ratio = 0.6\n", "key 'sample.poisson_ratio' must lie in [0.01, 0.49], got 0.6"),
        ("[friction]\nlaw = \"colomb\"\n", "key 'friction.law' is 'colomb', allowed values: coulomb, velocity, "
                                          "pressure, hyperbolic, slip_weakening, velocity_stretched, "
                                          "pressure_saturating, slip_power"),
        ("[friction]\nlaw = \"velocity\"\nf_s = 0.1\nf_d = 0.05\n", "key 'friction.v_c' is missing; law "
                                                                  "'velocity' needs f_s, f_d, v_c"),
        ("[friction]\nlaw = \"coulomb\"\nf = 0.1\nf_s = 0.2\n", "unknown key 'friction.f_s'; allowed keys in "
                                                               "[friction]: law, f"),
        ("[friction]\nf = -0.1\n", "key 'friction.f' must lie in [0, 5], got -0.1"),
        ("[friction]\nlaw = [\"velocity\"]\n", "key 'friction.law' must be a string, got ['velocity']"),
        ("[friction]\nlaw = {name = \"velocity\"}\n", "key 'friction.law' must be a string"),
        ("[channels.input_bar]\nunits = \"V\"\n", "key 'channels.input_bar.strain_per_volt' is missing; "
                                                 "units 'V' need it"),
        ("[channels.input_bar]\nunits = \"volt\"\n", "key 'channels.input_bar.units' is 'volt', allowed values: "
                                                    "strain, microstrain, V"),
        # the reader's range (plausible.RANGES): a configuration may not write a record that read_record refuses
        ("[channels.input_bar]\nunits = \"V\"\nstrain_per_volt = 1e-11\n",
         "key 'channels.input_bar.strain_per_volt' must lie in [1e-09, 1], got 1e-11"),
        ("[channels.hoop]\nwhite = 1e-6\n", "unknown section [channels.hoop]; allowed channels: input_bar"),
        ("[cell]\ntube_compliance = 1\n", "key 'cell.tube_compliance' must be true or false, got 1"),
        ("[numerics]\nelements = 20.5\n", "key 'numerics.elements' must be an integer, got 20.5"),
        ("[apparatus.tubes]\nlength = 0.04\n", "unknown section [apparatus.tubes]; allowed parts: striker"),
        ("[apparatus.input_bar]\nlenght = 2.5\n", "unknown key 'apparatus.input_bar.lenght'"),
        ("[measurement]\nduration = 0.8e-3\n", "key 'measurement.duration' is 800 us, too short"),
        ("[apparatus.input_bar]\ngauge_distance = 3.0\n", "key 'apparatus.input_bar.gauge_distance' is 3.0 m, "
                                                         "not inside the bar"),
        ("[record]\ndate = \"yesterday\"\n", "key 'record.date' is 'yesterday', not an ISO 8601 date"),
        # what the reader refuses is refused before simulating (it once was written, or failed after the simulation)
        ("[record]\ndate = \"2024-05-02garbage\"\n", "key 'record.date' is '2024-05-02garbage', not an ISO 8601"),
        ("[record]\ntest_id = \"A\\u000001\"\n", "key 'record.test_id' holds a NUL character at position 1"),
        ("[record]\ndescription = \"x\\u0000y\"\n", "key 'record.description' holds a NUL character"),
        ("[record]\ntest_id = \"A\\n01\"\n", "key 'record.test_id' holds the control character '\\n'"),
        ("[record]\ncampaign = \"A\\u202e1\"\n", "key 'record.campaign' holds the control character '\\u202e'"),
        ("[apparatus.sample]\nmaterial = \"I1\\u0007\"\n", "key 'apparatus.sample.material' holds the control "
                                                            "character '\\x07'"),
        ("[loading\nx = 1\n", "is not valid TOML"),
    ],
)
def test_bad_configs_are_refused_with_one_sentence_naming_file_and_key(tmp_path: Path, text: str,
                                                                       message: str) -> None:
    path = write(tmp_path, text, "bad.toml")
    with pytest.raises(ConfigError, match=re.escape(message)) as info:
        load_config(path)
    text = str(info.value)
    assert text.startswith(str(path) + ": ")
    assert "\n" not in text


def test_a_sample_diameter_and_a_multi_line_description_are_simulated(tmp_path: Path) -> None:
    """The sample's ``diameter`` is its class's own (a bar's is renamed outer_diameter; the sample's once was too, an
    internal error); free text may span lines, as the reader takes it."""
    path = write(tmp_path, '[apparatus.sample]\ndiameter = 0.0099\n[record]\ndescription = "two\\nlines"\n', "ok.toml")
    cfg = load_config(path)
    assert cfg.apparatus.sample.diameter == 0.0099 and cfg.description == "two\nlines"


def test_a_missing_config_file_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=re.escape(f"{tmp_path / 'none.toml'}: configuration file not found")):
        load_config(tmp_path / "none.toml")
