"""The per-record job: its versioned result read back with one function, the up-to-date rule, and a
real two-record campaign on a separately started Dask scheduler and worker (the path to a cluster)."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from friction_uq.campaigns import RecordResult, read_result
from friction_uq.campaigns.job import SCHEMA_VERSION, _up_to_date, write_result
from friction_uq.cli import main
from friction_uq.errors import FrictionUQError
from friction_uq.synthetic import ClosedFormTest, write_closed_form_record


def _result(**kw) -> RecordResult:
    base = dict(path="x/A-01.h5", status="done", campaign="A", test_id="A-01", material="I1", record_sha256="ab" * 32,
                prior_file="priors/I1.toml", prior_sha256="cd" * 32, settings={"seed": 5, "dispersion": False,
                                                                              "hoop": True, "pdf": False},
                outputs={"json": "A_A-01.json"}, summary={"f": {"mean": 0.05, "sd": 0.003, "q05": 0.045,
                                                                "q50": 0.05, "q95": 0.055}},
                causes=["plug friction"])
    return RecordResult(**(base | kw))


def test_a_result_reads_back_as_written(tmp_path):
    r = _result()
    assert read_result(write_result(r, tmp_path / "A_A-01.result.json")) == r


@pytest.mark.parametrize(("edit", "message"), [
    ({"schema": "other"}, "not a campaign record result \\(key 'schema'"),
    ({"schema_version": SCHEMA_VERSION + 1}, f"key 'schema_version' is {SCHEMA_VERSION + 1}, this friction-uq reads"),
    ({"colour": "red"}, f"unknown key\\(s\\) colour in a schema version {SCHEMA_VERSION} result"),
    ({"schema_version": 1}, "key 'schema_version' is 1, this friction-uq reads version 4"),  # no window_halves
    ({"schema_version": 2}, "key 'schema_version' is 2, this friction-uq reads version 4"),  # no warnings
    ({"schema_version": 3}, "key 'schema_version' is 3, this friction-uq reads version 4"),  # no warning_kinds
    ({"status": "maybe"}, "key 'status' is 'maybe', allowed values: done, skipped, failed"),
    ({"window_halves": {"sd": 1}}, "key 'window_halves': key 'log_kappa_change' must be a finite number"),
])
def test_a_result_of_another_schema_is_refused(tmp_path, edit, message):
    path = write_result(_result(), tmp_path / "r.json")
    doc = json.loads(path.read_text()) | edit
    path.write_text(json.dumps(doc))
    with pytest.raises(FrictionUQError, match=f"r.json: {message}"):
        read_result(path)


def test_up_to_date_needs_same_record_settings_prior_version_and_outputs(tmp_path):
    import hashlib

    (tmp_path / "A_A-01.nc").write_bytes(b"draws")  # the run JSON names the .nc's checksum
    from friction_uq.record_run.outputs import RUN_SCHEMA_VERSION

    run_json = {"schema_version": RUN_SCHEMA_VERSION, "record_sha256": "ab" * 32, "campaign": "A", "test_id": "A-01",
                "outputs": {"netcdf": {"file": "A_A-01.nc", "sha256": hashlib.sha256(b"draws").hexdigest()},
                            "pdf": None}}
    (tmp_path / "A_A-01.json").write_text(json.dumps(run_json | {"schema_version": RUN_SCHEMA_VERSION - 1}))
    old = _result(outputs={"json": "A_A-01.json", "netcdf": "A_A-01.nc"})
    stem = "A_A-01"
    assert not _up_to_date(old, _result(status="failed"), tmp_path, stem)  # an older run's JSON: other meanings
    (tmp_path / "A_A-01.json").write_text(json.dumps(run_json))
    assert _up_to_date(old, _result(status="failed"), tmp_path, stem) == run_json  # its run's document
    for change in ({"record_sha256": "ff" * 32}, {"prior_sha256": "ee" * 32}, {"friction_uq_version": "0.0.1"},
                   {"settings": old.settings | {"seed": 6}}, {"settings": old.settings | {"dispersion": True}}):
        assert _up_to_date(old, dataclasses.replace(old, **change), tmp_path, stem) is None, change
    assert _up_to_date(dataclasses.replace(old, status="failed"), old, tmp_path, stem) is None
    with_pdf = dataclasses.replace(old, settings=old.settings | {"pdf": True})
    assert _up_to_date(with_pdf, old, tmp_path, stem) is not None  # a run with the report serves one without
    assert _up_to_date(old, with_pdf, tmp_path, stem) is None
    # a stored result edited to another test's id or to another record's outputs is not this record's: redone
    assert _up_to_date(dataclasses.replace(old, test_id="Z-99"), old, tmp_path, stem) is None
    (tmp_path / "A_A-02.json").write_text(json.dumps(run_json | {"test_id": "A-02"}))
    (tmp_path / "A_A-02.nc").write_bytes(b"draws")
    other = dataclasses.replace(old, outputs={"json": "A_A-02.json", "netcdf": "A_A-02.nc"})
    assert _up_to_date(other, old, tmp_path, stem) is None
    (tmp_path / "A_A-01.json").write_text(json.dumps(run_json | {"record_sha256": "ff" * 32}))  # another record's run
    assert _up_to_date(old, old, tmp_path, stem) is None
    (tmp_path / "A_A-01.json").write_text(json.dumps(run_json))
    (tmp_path / "A_A-01.nc").write_bytes(b"drawz")  # changed since its run: redone
    assert _up_to_date(old, old, tmp_path, stem) is None
    (tmp_path / "A_A-01.json").unlink()
    assert _up_to_date(old, old, tmp_path, stem) is None


@pytest.fixture(scope="module")
def dask_address(tmp_path_factory):
    """``dask scheduler`` and one ``dask worker`` (one thread) on 127.0.0.1, as a lab would start them."""
    d = tmp_path_factory.mktemp("dask")
    sfile = d / "scheduler.json"
    dask_cli = str(Path(sys.executable).parent / "dask")
    env = os.environ | {"NUMBA_NUM_THREADS": "1"}
    logs = {name: open(d / f"{name}.log", "w") for name in ("scheduler", "worker")}
    procs = [subprocess.Popen([dask_cli, "scheduler", "--host", "127.0.0.1", "--port", "0", "--dashboard-address",
                               ":0", "--scheduler-file", str(sfile)], stdout=logs["scheduler"],
                              stderr=subprocess.STDOUT, env=env)]
    try:
        t0 = time.monotonic()
        while not sfile.exists() and time.monotonic() - t0 < 60:
            time.sleep(0.2)
        address = json.loads(sfile.read_text())["address"]
        procs.append(subprocess.Popen([dask_cli, "worker", address, "--nthreads", "1", "--nworkers", "1",
                                       "--no-dashboard"], stdout=logs["worker"], stderr=subprocess.STDOUT, env=env))
        yield address, d / "worker.log"
    finally:
        for p in reversed(procs):
            p.terminate()
            p.wait(timeout=30)
        for f in logs.values():
            f.close()


@pytest.fixture(scope="module")
def scheduler_campaign(dask_address, tmp_path_factory):
    address, worker_log = dask_address
    d = tmp_path_factory.mktemp("campaign")
    for k, v in enumerate([8.0, 12.0]):
        write_closed_form_record(d / f"S-0{k + 1}.h5", ClosedFormTest(striker_velocity=v), seed=200 + k,
                                 test_id=f"S-0{k + 1}")
    (d / "S-09.h5").write_text("not an HDF5 file")
    out = tmp_path_factory.mktemp("out")
    code = main(["campaign", str(d), "--out", str(out), "--scheduler", address, "--no-pdf", "--quiet"])
    return code, d, out, address, worker_log


@pytest.mark.slow  # a campaign on a scheduler of its own, shared by the three tests below: in the default suite it kept that suite over 10 minutes (72 s to set up in a CI run)
def test_a_campaign_runs_on_a_separate_scheduler_and_a_bad_record_does_not_stop_it(scheduler_campaign):
    code, d, out, _, worker_log = scheduler_campaign
    assert code == 1  # one record refused
    doc = json.loads((out / "campaign.json").read_text())
    status = {Path(r["path"]).name: r["status"] for r in doc["records"]}
    assert status == {"S-01.h5": "done", "S-02.h5": "done", "S-09.h5": "failed"}
    bad = next(r for r in doc["records"] if r["status"] == "failed")
    assert bad["message"].startswith(str(d / "S-09.h5"))
    assert set(doc["pooled"]) == {"f", "kappa"} and doc["friction_law"]["best"] is None
    assert doc["wall_seconds"]["records"] > 0 and doc["wall_seconds"]["analysis"] > 0
    for name in ("S_S-01", "S_S-02"):
        r = read_result(out / "records" / f"{name}.result.json")
        assert r.status == "done" and r.causes is None and 0.03 < r.summary["f"]["q50"] < 0.07
        assert (out / "records" / r.outputs["netcdf"]).exists()
    assert (out / "campaign.nc").exists() and (out / "campaign.pdf").read_bytes()[:4] == b"%PDF"
    assert not list((out / "records").glob("*.pdf"))  # --no-pdf: no per-record reports
    log = worker_log.read_text()
    assert "posterior (90 % credible intervals)" not in log and "wrote " not in log  # the job prints nothing


@pytest.mark.slow  # the scheduler's campaign above: in the default suite it kept that suite over 10 minutes (8 s in a CI run)
def test_a_rerun_skips_what_is_up_to_date(scheduler_campaign, capsys):
    _, d, out, address, _ = scheduler_campaign
    capsys.readouterr()
    assert main(["campaign", str(d), "--out", str(out), "--scheduler", address, "--no-pdf"]) == 1
    doc = json.loads((out / "campaign.json").read_text())
    assert doc["counts"] == {"done": 0, "skipped": 2, "failed": 1}
    err = capsys.readouterr().err
    assert "campaign: 2 done (2 up to date), 1 failed, 0 left" in err


@pytest.mark.slow  # the scheduler's campaign above: in the default suite it kept that suite over 10 minutes (29 s in a CI run)
def test_a_stored_result_edited_is_read_from_its_run_or_redone(scheduler_campaign, capsys):
    """A stored result's summary is its run JSON's, not its own copy's: emptied or made text, the skip reads the
    run back (these were an internal error and a half-written campaign); its test id changed, the record is
    analysed again."""
    _, d, out, address, _ = scheduler_campaign
    stored = out / "records" / "S_S-01.result.json"
    before = read_result(stored).summary
    doc = json.loads(stored.read_text())
    doc["summary"] = {"V": {"mean": "abc"}}
    stored.write_text(json.dumps(doc))
    assert main(["campaign", str(d), "--out", str(out), "--scheduler", address, "--no-pdf", "--quiet"]) == 1
    counts = json.loads((out / "campaign.json").read_text())["counts"]
    assert counts == {"done": 0, "skipped": 2, "failed": 1} and read_result(stored).summary == before
    doc = json.loads(stored.read_text())
    doc["test_id"] = "Z-99"
    stored.write_text(json.dumps(doc))
    assert main(["campaign", str(d), "--out", str(out), "--scheduler", address, "--no-pdf", "--quiet"]) == 1
    counts = json.loads((out / "campaign.json").read_text())["counts"]
    assert counts == {"done": 1, "skipped": 1, "failed": 1} and read_result(stored).test_id == "S-01"
