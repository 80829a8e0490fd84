"""The command line, end to end, as a user runs it."""

import json
import subprocess
import sys

import pytest

from friction_uq import __version__
from friction_uq.cli import build_parser, main
from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

SUBCOMMANDS = ["inspect", "analyze", "design", "simulate", "run", "compare", "diagnose", "campaign", "import", "priors"]


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    return write_closed_form_record(tmp_path_factory.mktemp("cli") / "c.h5", ClosedFormTest(), seed=3,
                                    units={"external_output_bar": "V", "tube_hoop": "microstrain"},
                                    strain_per_volt={"external_output_bar": 2e-4})


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"friction-uq {__version__}"


@pytest.mark.parametrize("cmd", SUBCOMMANDS)
def test_help_on_every_subcommand(cmd, capsys):
    with pytest.raises(SystemExit) as e:
        main([cmd, "--help"])
    assert e.value.code == 0
    assert f"usage: friction-uq {cmd}" in capsys.readouterr().out


def test_parser_knows_every_subcommand():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert sorted(sub.choices) == sorted(SUBCOMMANDS)


def test_inspect_prints_the_summary(record, capsys):
    assert main(["inspect", str(record)]) == 0
    out = capsys.readouterr().out
    for text in ("S-01", "campaign S", "5 MHz", "input_bar", "tube_hoop", "V (0.0002 strain/V)", "microstrain",
                 "arrival us", "noise ue", "Z N s/m", "11449.1", "Lame 2.10 ue/MPa"):
        assert text in out, text


def test_design_writes_a_figure(record, tmp_path, capsys):
    out = tmp_path / "fig4.pdf"
    assert main(["design", str(record), "-o", str(out)]) == 0
    assert out.read_bytes()[:4] == b"%PDF"


def test_bad_window_is_a_usage_error(record, capsys):
    with pytest.raises(SystemExit) as e:
        main(["analyze", str(record), "--window", "abc"])
    assert e.value.code == 2
    assert "T0:T1" in capsys.readouterr().err
    for text in ("1e1000000:2e1000000", "1e999999999us:2e999999999us", "1e400us:2e400us"):  # overflowed: traceback
        with pytest.raises(SystemExit) as e:
            main(["analyze", str(record), "--window", text])
        assert e.value.code == 2
        assert "argument --window: window" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        main(["analyze", str(record), "--window", "600us:400us"])
    assert e.value.code == 2
    assert "argument --window: window '600us:400us': T1 must be after T0" in capsys.readouterr().err


@pytest.mark.parametrize("nu", ["1e-300", "0", "0.5", "nan", "-0.1"])
def test_an_implausible_nu_is_a_usage_error(record, capsys, nu):
    """eq. 17's f grows as 1/nu: nu = 1e-300 gave f = 3e298; the sample's Poisson ratio has a plausible range."""
    with pytest.raises(SystemExit) as e:
        main(["analyze", str(record), "--nu", nu])
    assert e.value.code == 2
    assert "argument --nu: nu is" in capsys.readouterr().err


def test_window_takes_seconds_or_a_unit(record, capsys):
    """--window 400us:600us, 0.4ms:0.6ms and 4e-4:6e-4 are the same window; bare numbers too large for seconds
    are refused with the microsecond spelling."""
    outs = []
    for w in ("400us:600us", "400:600us", "0.4ms:0.6ms", "4e-4:6e-4"):
        assert main(["analyze", str(record), "--window", w, "--json"]) == 0
        outs.append(json.loads(capsys.readouterr().out)["window"])
    assert all(o == outs[0] for o in outs)
    with pytest.raises(SystemExit) as e:
        main(["analyze", str(record), "--window", "400:600"])
    assert e.value.code == 2 and "write 400us:600us" in capsys.readouterr().err


def test_console_script_runs():
    r = subprocess.run([sys.executable, "-m", "friction_uq.cli", "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and __version__ in r.stdout


def test_simulate_writes_a_record_that_analyze_reads(tmp_path, capsys):
    cfg = tmp_path / "t.toml"
    cfg.write_text('[record]\ntest_id = "T-1"\ncampaign = "T"\nseed = 5\n[friction]\nlaw = "coulomb"\nf = 0.1\n')
    out = tmp_path / "t.h5"
    assert main(["simulate", str(cfg), "-o", str(out)]) == 0
    assert main(["analyze", str(out), "--nu", "0.4", "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    # default simulator physics: Coulomb f = 0.1, nu = 0.4, no gap, rigid tube -> eq. 17 recovers f
    assert doc["f"] == pytest.approx(0.1, rel=0.05)


def test_simulate_refuses_a_config_with_a_typo(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('[friction]\nlaw = "colomb"\n')
    out = tmp_path / "never.h5"
    assert main(["simulate", str(cfg), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.toml" in err[0] and "colomb" in err[0] and "coulomb" in err[0]
    assert not out.exists()


def test_simulate_does_not_write_over_its_own_configuration(tmp_path, capsys):
    """A configuration named .h5 given as its own output was overwritten by the record."""
    cfg = tmp_path / "t.h5"
    text = '[record]\ntest_id = "T-1"\ncampaign = "T"\nseed = 5\n'
    cfg.write_text(text)
    assert main(["simulate", str(cfg), "-o", str(cfg)]) == 2
    assert "is the configuration being read" in capsys.readouterr().err
    assert cfg.read_text() == text


def test_the_simulation_seed_is_checked_as_every_seed():
    from friction_uq.errors import SeedError
    from friction_uq.simulate import SimulationConfig, simulate

    for bad in (-1, 1.5, True, 2**64, "5"):
        with pytest.raises(SeedError, match="seed: must be an integer in"):
            simulate(SimulationConfig(), seed=bad)
