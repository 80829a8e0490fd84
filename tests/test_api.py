"""The Python interface: lazy at import, the functions as the commands, a run's outputs read back."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import friction_uq as fu
from friction_uq.errors import FrictionUQError

ROOT = Path(__file__).resolve().parents[1]


def test_import_friction_uq_loads_no_scientific_stack():
    code = "import sys, friction_uq; print(sorted(m for m in ('numpy', 'scipy', 'h5py', 'arviz') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_the_interface_is_listed_and_documented():
    for name in ("run", "diagnose", "campaign", "read_result", "import_scope_files"):
        assert name in fu.__all__ and callable(getattr(fu, name)) and getattr(fu, name).__doc__


def test_run_and_campaign_stay_the_functions_once_their_subpackages_load():
    import inspect

    import friction_uq.campaigns  # noqa: F401  (binds the subpackage's name on the package)
    import friction_uq.record_run  # noqa: F401

    assert callable(fu.run) and callable(fu.campaign)
    assert "priors" in inspect.signature(fu.run).parameters
    assert "workers" in inspect.signature(fu.campaign).parameters
    with pytest.raises(FrictionUQError, match="file not found"):
        fu.run(ROOT / "nope.h5", out_dir=ROOT / "reports" / "never")


def test_read_result_reads_the_json_and_refuses_others(tmp_path):
    doc = {"schema": "friction-uq/run-result", "schema_version": 3, "test_id": "A-03", "warnings": ["w"],
           "f": {"mean": 0.05, "q05": 0.04, "q50": 0.05, "q95": 0.06, "model": "stationary"}}
    (tmp_path / "A_A-03.json").write_text(json.dumps(doc))
    res = fu.read_result(tmp_path / "A_A-03.nc")  # the stem, the .nc or the .json
    assert res.f["q50"] == 0.05 and res.warnings == ["w"] and res.test_id == "A-03"
    assert res.warning_kinds == []  # schema 3 wrote none
    with pytest.raises(FrictionUQError, match=r"A_A-03.json: its netCDF file .* is missing"):
        res.datatree()
    (tmp_path / "A_A-03.nc").write_bytes(b"not a netCDF file")
    with pytest.raises(FrictionUQError, match=r"A_A-03.nc: not a readable netCDF file"):
        fu.read_result(tmp_path / "A_A-03.json").datatree()
    (tmp_path / "x.json").write_text(json.dumps({"schema": "friction-uq/campaign"}))
    with pytest.raises(FrictionUQError, match=r"x.json: not a run result"):
        fu.read_result(tmp_path / "x.json")
    (tmp_path / "y.json").write_text('{"x": ' + "9" * 5000 + "}")  # an integer past Python's 4300 digits
    with pytest.raises(FrictionUQError, match=r"y.json: not a friction-uq result file \(not JSON"):
        fu.read_result(tmp_path / "y.json")
    (tmp_path / "z.json").write_bytes(b'{"x": "\xff"}')  # not UTF-8
    with pytest.raises(FrictionUQError, match=r"z.json: is not UTF-8 text \(byte 7\); save the result file as UTF-8"):
        fu.read_result(tmp_path / "z.json")
    (tmp_path / "d.json").mkdir()  # read as every text input is: a folder named as a result is said so
    with pytest.raises(FrictionUQError, match=r"d.json: is a folder, not a result file"):
        fu.read_result(tmp_path / "d.json")


@pytest.mark.slow
def test_example_imports_a_csv_runs_and_draws_a_figure(tmp_path):
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "import_and_run.py"), "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    assert (tmp_path / "A-03_f_nu.pdf").read_bytes()[:4] == b"%PDF"
    res = fu.read_result(tmp_path / "A_A-03.json")
    assert res.datatree()["posterior"]["f"].shape[0] >= 1
    assert "f = " in r.stdout and "eti90" in r.stdout


R = ROOT / "data" / "A" / "A-01.h5"


@pytest.mark.parametrize("call, words", [
    (lambda o: fu.run(5, out_dir=o), "path: must be a path (text or os.PathLike), got int 5"),
    (lambda o: fu.run(str(R).encode(), out_dir=o), "path: must be a path"),
    (lambda o: fu.run([R], out_dir=o), "path: must be a path"),
    (lambda o: fu.run(R, out_dir=5), "out_dir: must be a path"),
    (lambda o: fu.run(R, out_dir=""), "write '.' for the current folder"),
    (lambda o: fu.run(R, out_dir=o, priors=""), "priors: must be a path"),
    (lambda o: fu.run(R, out_dir=o, window="400us:600us"), "window: must be (t0, t1)"),
    (lambda o: fu.run(R, out_dir=o, window=(4e-4, 5e-4, 6e-4)), "window: must be (t0, t1)"),
    (lambda o: fu.run(R, out_dir=o, window=("4e-4", "6e-4")), "window: must be (t0, t1)"),
    (lambda o: fu.run(R, out_dir=o, window=(4e-4, float("nan"))), "window: must be (t0, t1)"),
    (lambda o: fu.run(R, out_dir=o, hoop="no"), "hoop: must be True or False, got str 'no'"),
    (lambda o: fu.diagnose(R, out_dir=o, pdf=None), "pdf: must be True or False"),
    (lambda o: fu.campaign(str(R), o, workers="2"), "workers: must be a whole number of at least 1, got str"),
    (lambda o: fu.campaign([R], o, workers=1.5), "workers: must be a whole number"),
    (lambda o: fu.campaign([R], o, scheduler=5), "scheduler: must be a Dask scheduler's address"),
    (lambda o: fu.campaign(5, o), "records: must be a path or a list of paths"),
    (lambda o: fu.campaign([R, None], o), "records[1]: must be a path"),
    (lambda o: fu.campaign([R], o, diagnose="no"), "diagnose: must be True or False"),
    (lambda o: fu.import_scope_files("x.csv", "SETUP.toml", o / "x.h5", check="no"), "check: must be True or False"),
    (lambda o: fu.read_result(5), "path: must be a path"),
    (lambda o: fu.read_result(""), "path: must be a path"),
])
def test_arguments_of_the_wrong_type_are_refused_in_one_sentence_before_any_work(tmp_path, call, words):
    """Not a TypeError from deep inside, and not read as something else: the string 'no' is true, and one path
    given to campaign was walked character by character (from '/', the whole file system)."""
    out = tmp_path / "out"
    with pytest.raises(FrictionUQError) as info:
        call(out)
    assert words in str(info.value) and "\n" not in str(info.value)
    assert not out.exists()


def test_read_result_refuses_a_json_without_what_it_exposes(tmp_path):
    (tmp_path / "a.json").write_text(json.dumps({"schema": "friction-uq/run-result"}))
    with pytest.raises(FrictionUQError, match=r"a.json: not a run result: key 'f'"):
        fu.read_result(tmp_path / "a.json")
    (tmp_path / "b.json").write_text(json.dumps({"schema": "friction-uq/run-result", "f": {}, "warnings": "abc"}))
    with pytest.raises(FrictionUQError, match=r"b.json: key 'warnings' must be a list of sentences"):
        fu.read_result(tmp_path / "b.json")
    with pytest.raises(TypeError, match=r"diagnose\(\) got unexpected keyword argument\(s\): bogus"):
        fu.diagnose(R, bogus=1)
