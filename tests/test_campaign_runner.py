"""Campaign runner: records and seeds, Dask on 1 or 2 workers, failures that do not stop the others,
progress, and the refusals of bad campaign input (one sentence, exit 2)."""

from __future__ import annotations

import dataclasses
import io
import sys

import cloudpickle
import numpy as np
import pytest

from friction_uq.campaigns import RecordResult, RecordTask, find_records, make_tasks, read_header, run_tasks
from friction_uq.campaigns.runner import Progress, check_headers
from friction_uq.cli import main
from friction_uq.errors import FrictionUQError
from friction_uq.record import paper_apparatus
from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

# the cheap jobs below run on spawned worker processes, which cannot import this test module
cloudpickle.register_pickle_by_value(sys.modules[__name__])


def seeded_job(task: RecordTask) -> RecordResult:
    """Stands in for the analysis: a draw from the task's seed (what makes a run's bits)."""
    if task.path.endswith("boom.h5"):
        raise RuntimeError("worker crashed")
    x = float(np.random.default_rng(task.seed).normal())
    return RecordResult(path=task.path, status="done", summary={"f": {"mean": x}})


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("records")
    for k, v in enumerate([7.0, 9.0, 11.0, 13.0]):
        write_closed_form_record(d / f"S-0{k + 1}.h5", ClosedFormTest(striker_velocity=v), seed=100 + k,
                                 test_id=f"S-0{k + 1}")
    return d


def test_seeds_do_not_depend_on_order_or_on_the_other_records(folder, tmp_path):
    paths = find_records([folder])
    headers = [read_header(p) for p in paths]
    a = {t.path: t.seed for t in make_tasks(headers, out_dir=tmp_path, seed=7)}
    b = {t.path: t.seed for t in make_tasks(headers[::-1][:3], out_dir=tmp_path, seed=7)}
    assert all(b[p] == a[p] for p in b)
    assert len(set(a.values())) == len(a)
    c = {t.path: t.seed for t in make_tasks(headers, out_dir=tmp_path, seed=8)}
    assert all(c[p] != a[p] for p in a)


@pytest.mark.slow  # a campaign twice: in the default suite it kept that suite over 10 minutes (13 s in a CI run)
def test_results_are_the_same_on_one_and_two_workers_in_any_order(folder, tmp_path):
    headers = [read_header(p) for p in find_records([folder])]
    tasks = make_tasks(headers, out_dir=tmp_path, seed=3)
    one = run_tasks(tasks, workers=1, progress=False, job=seeded_job)
    two = run_tasks(tasks[::-1], workers=2, progress=False, job=seeded_job)[::-1]
    assert [r.path for r in one] == [t.path for t in tasks]
    assert [r.summary for r in one] == [r.summary for r in two]


def test_a_crashing_task_is_one_failed_record_and_the_others_go_on(folder, tmp_path):
    headers = [read_header(p) for p in find_records([folder])]
    tasks = make_tasks(headers, out_dir=tmp_path, seed=3)
    tasks.insert(1, dataclasses.replace(tasks[0], path=str(tmp_path / "boom.h5")))
    res = run_tasks(tasks, workers=2, progress=False, job=seeded_job)
    assert [r.status for r in res] == ["done", "failed", "done", "done", "done"]
    assert "boom.h5: the task failed on its worker (RuntimeError: worker crashed)" in res[1].message


def test_progress_counts_done_failed_and_left():
    out = io.StringIO()
    bar = Progress(3, stream=out)
    bar.update(RecordResult(path="a.h5", status="done", campaign="A", test_id="A-01"))
    bar.update(RecordResult(path="b.h5", status="failed"))
    bar.update(RecordResult(path="c.h5", status="skipped", campaign="A", test_id="A-03"))
    lines = out.getvalue().splitlines()
    assert lines[0] == "campaign: 1 done (0 up to date), 0 failed, 2 left - A A-01: done"
    assert lines[1] == "campaign: 1 done (0 up to date), 1 failed, 1 left - b.h5: failed"
    assert lines[2] == "campaign: 2 done (1 up to date), 1 failed, 0 left - A A-03: skipped"


def test_an_empty_list_is_refused(tmp_path, capsys):
    with pytest.raises(FrictionUQError, match="no records given"):
        find_records([])
    assert main(["campaign", "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no records given" in err and "Traceback" not in err


def test_a_folder_with_no_records_is_refused(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("x")
    assert main(["campaign", str(tmp_path / "empty"), "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "empty: a folder with no records in it" in err
    assert not (tmp_path / "c").exists()


def test_mixed_sample_materials_are_refused(folder, tmp_path, capsys):
    app = paper_apparatus()
    other = dataclasses.replace(app, sample=dataclasses.replace(app.sample, material="PMMA"))
    write_closed_form_record(tmp_path / "P-01.h5", ClosedFormTest(), seed=1, apparatus=other, test_id="P-01",
                             campaign="P")
    headers = [read_header(p) for p in find_records([folder, tmp_path / "P-01.h5"])]
    with pytest.raises(FrictionUQError, match=r"records of different sample materials are mixed \(I1 in S-01.h5"):
        check_headers(headers)
    assert main(["campaign", str(folder), str(tmp_path / "P-01.h5"), "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "PMMA in P-01.h5" in err


def test_the_same_record_twice_is_refused(folder, tmp_path):
    import shutil

    shutil.copyfile(folder / "S-01.h5", tmp_path / "copy.h5")
    headers = [read_header(p) for p in find_records([folder, tmp_path / "copy.h5"])]
    with pytest.raises(FrictionUQError, match="copy.h5 and .*S-01.h5 are the same record"):
        check_headers(headers)


def test_a_scheduler_that_does_not_answer_is_refused(folder, tmp_path, capsys):
    assert main(["campaign", str(folder), "--out", str(tmp_path / "c"), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--scheduler tcp://127.0.0.1:9: no Dask scheduler answers at this address within 5 s" in err


def test_workers_below_one_is_refused(folder, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["campaign", str(folder), "--out", str(tmp_path / "c"), "--workers", "0"])
    assert exc.value.code == 2
    assert "workers must be at least 1, got 0" in capsys.readouterr().err


def test_test_ids_in_another_script_keep_their_letters_and_do_not_collide(tmp_path):
    """A lab's ids "Essai-é1" and "Essai-è1" write files of their own names (they had both become "Essai-_1" and the
    campaign refused them as one name); a decomposed accent is the composed one; what a file name cannot hold is '_'."""
    from friction_uq.record_run import safe_stem

    assert safe_stem("A", "Essai-é1") == "A_Essai-é1" != safe_stem("A", "Essai-è1")
    assert safe_stem("A", "Essai-e\u03011") == "A_Essai-é1"  # the same id typed with a combining accent
    assert safe_stem("B", "x/y:z*? 1") == "B_x_y_z___1" and safe_stem(".", "t") == "_t"
    app = paper_apparatus()
    for tid in ("Essai-é1", "Essai-è1"):
        write_closed_form_record(tmp_path / f"{tid}.h5", ClosedFormTest(), seed=len(tid) + ord(tid[-2]),
                                 apparatus=app, test_id=tid, campaign="A")
    check_headers([read_header(p) for p in find_records([tmp_path])])  # two names: nothing refused
