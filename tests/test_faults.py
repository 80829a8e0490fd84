"""Fault injection: every failure of `friction-uq` is one sentence, exit 2, nothing half-written.

Operating-system errors are raised inside the writers (ENOSPC, EROFS, EACCES, EISDIR), a real full
disk is a 2 MB tmpfs where the machine allows mounting one, and bad seeds, output names and input
files are given to each subcommand. After a failure the output folder holds no temporary file,
no lock and no output of a half-finished run.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
from pathlib import Path

import numpy as np
import pytest

from friction_uq import _atomic
from friction_uq.cli import main
from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

STEM = "fault_F-01"


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    d = tmp_path_factory.mktemp("faults")
    return write_closed_form_record(d / "fault.h5", ClosedFormTest(f=0.05, nu=0.4), seed=31,
                                    test_id="F-01", campaign="fault")


def _one_sentence(capsys) -> str:
    err = [line for line in capsys.readouterr().err.splitlines() if not line.startswith(("sampling:", "friction-uq: note"))]
    err = [line for line in err if not line.startswith("friction-uq: ") or line.startswith("friction-uq: error:")]
    assert len(err) == 1, err
    assert err[0].startswith("friction-uq: error:") and "Traceback" not in err[0]
    return err[0]


def _nothing_half_written(out: Path) -> None:
    if not out.exists():
        return
    names = sorted(p.name for p in out.iterdir())
    assert not [n for n in names if ".tmp" in n or n.endswith(".lock")], names
    assert not [n for n in names if n.startswith(STEM)], names  # no output of a failed run


def _raise(code: int):
    def f(*args, **kwargs):
        raise OSError(code, os.strerror(code), str(args[0]) if args and isinstance(args[0], (str, os.PathLike)) else None)
    return f


def _quiet_run(record, out, *extra) -> int:
    return main(["run", str(record), "--out", str(out), "--quiet", "--no-pdf", "--seed", "3", *extra])


# ---------------------------------------------------------------- system errors inside the writers


@pytest.mark.slow  # a whole run per fault: in the default suite it kept that suite over 10 minutes (16 s each in a CI run)
@pytest.mark.parametrize("code, words", [(errno.ENOSPC, "No space left on device"),
                                         (errno.EROFS, "Read-only file system")])
def test_output_writer_fault_keeps_the_previous_outputs(record, tmp_path, capsys, monkeypatch, code, words):
    out = tmp_path / "out"
    out.mkdir()
    old = {out / f"{STEM}.json": b"old json", out / f"{STEM}.nc": b"old nc"}
    for p, data in old.items():
        p.write_bytes(data)
    monkeypatch.setattr(_atomic.os, "fsync", _raise(code))  # the data hits the disk at fsync
    assert _quiet_run(record, out) == 2
    msg = _one_sentence(capsys)
    assert words in msg and STEM in msg
    for p, data in old.items():  # the earlier set is untouched, no new file beside it
        assert p.read_bytes() == data
    names = sorted(p.name for p in out.iterdir())
    assert not [n for n in names if ".tmp" in n or n.endswith(".lock")], names
    assert set(names) <= {f"{STEM}.json", f"{STEM}.nc", f".{STEM}.checkpoint.npz"}
    # the checkpoint that is left is whole: the next run resumes from it and finishes
    monkeypatch.undo()
    assert _quiet_run(record, out) == 0
    assert sorted(p.name for p in out.iterdir()) == [f"{STEM}.json", f"{STEM}.nc"]


def test_checkpoint_writer_fault_is_one_sentence(record, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    real = tempfile.mkstemp

    def mkstemp(*args, **kwargs):
        if ".checkpoint.npz" in kwargs.get("prefix", ""):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(*args, **kwargs)

    monkeypatch.setattr(_atomic.tempfile, "mkstemp", mkstemp)
    assert _quiet_run(record, out) == 2
    msg = _one_sentence(capsys)
    assert "checkpoint.npz: cannot write (No space left on device)" in msg
    _nothing_half_written(out)


def test_permission_denied_on_the_folder_is_refused_before_sampling(record, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    real = os.open

    def deny(path, *args, **kwargs):
        if str(path).endswith(".lock"):
            raise OSError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(_atomic.os, "open", deny)
    assert _quiet_run(record, out) == 2
    assert "cannot write (Permission denied); choose a folder you may write to" in _one_sentence(capsys)
    _nothing_half_written(out)


def test_an_output_name_taken_by_a_directory_is_refused(record, tmp_path, capsys):
    out = tmp_path / "out"
    (out / f"{STEM}.json").mkdir(parents=True)
    assert _quiet_run(record, out) == 2
    assert "a directory has that name" in _one_sentence(capsys)


def test_a_second_run_into_the_same_folder_is_refused(record, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    with _atomic.output_lock(out, STEM):
        assert _quiet_run(record, out) == 2
        msg = _one_sentence(capsys)
    assert "another friction-uq run is writing fault_F-01 into this folder" in msg
    assert not (out / f".{STEM}.lock").exists()  # released by its holder


# ---------------------------------------------------------------- stale state


def test_orphans_and_a_corrupt_checkpoint_are_cleared(record, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    orphans = [out / f".{STEM}.json.k3j2l1.tmp.json", out / f".{STEM}.nc.x9y8z7.tmp.nc",
               out / f"..{STEM}.checkpoint.npz.aa11bb.tmp.npz"]
    for p in orphans:
        p.write_bytes(b"half")
    other = out / ".other_X-1.json.k3j2l1.tmp.json"  # another record's: not ours to remove
    other.write_bytes(b"x")
    (out / f".{STEM}.checkpoint.npz").write_bytes(b"PK\x03\x04 cut short")
    (out / f"{STEM}.pdf").write_bytes(b"%PDF of an earlier run")
    assert _quiet_run(record, out) == 0
    err = capsys.readouterr().err
    assert "checkpoint.npz cannot be read" in err and "sampling starts afresh" in err
    names = sorted(p.name for p in out.iterdir())
    assert names == [other.name, f"{STEM}.json", f"{STEM}.nc"]  # the earlier run's PDF is gone too
    doc = json.loads((out / f"{STEM}.json").read_text())
    import hashlib

    assert doc["outputs"]["netcdf"]["sha256"] == hashlib.sha256((out / f"{STEM}.nc").read_bytes()).hexdigest()
    assert doc["outputs"]["pdf"] is None


# ---------------------------------------------------------------- a real full disk


def _mount_tmpfs(where: Path, size: str) -> bool:
    if not sys.platform.startswith("linux") or shutil.which("mount") is None or os.geteuid() != 0:
        return False
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)], capture_output=True)
    return r.returncode == 0


@pytest.mark.slow  # a whole run onto a 2 MB tmpfs: in the default suite it kept that suite over 10 minutes (25 s in a CI run)
def test_a_real_full_disk_is_one_sentence_and_leaves_nothing(record, tmp_path):
    mnt = tmp_path / f"tmpfs-{uuid.uuid4().hex[:6]}"
    mnt.mkdir()
    if not _mount_tmpfs(mnt, "2m"):
        pytest.skip("cannot mount a tmpfs here (needs root on Linux): the full disk is covered by injected ENOSPC")
    try:
        # a separate process: a crash (segfault) would show as a negative return code
        cmd = [sys.executable, "-m", "friction_uq.cli", "run", str(record), "--out", str(mnt / "out"), "--quiet",
               "--seed", "3"]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        err = r.stderr.strip().splitlines()
        assert r.returncode == 2, r.stderr[-2000:]
        assert len(err) == 1 and "No space left on device" in err[0] and "Traceback" not in r.stderr
        # where the disk filled decides what is left: when the first checkpoint does not fit (so with the twenty-sixth
        # session's fresh install; with the one before, it did), the folder the run made is removed; else the
        # checkpoints written before are left, and nothing half-written
        left = mnt / "out"
        if not left.exists():  # the first checkpoint did not fit: the run leaves no trace at all
            assert "checkpoint" in err[0] and list(mnt.iterdir()) == [], (err, list(mnt.iterdir()))
        names = sorted(p.name for p in left.iterdir()) if left.exists() else []
        assert not [n for n in names if ".tmp" in n or n.endswith(".lock") or n.startswith(STEM)], names
        # whatever checkpoint is left is whole: moved where there is room, the run resumes (or starts) and ends
        roomy = tmp_path / "roomy"
        if left.exists():
            shutil.copytree(left, roomy)
        cmd[cmd.index("--out") + 1] = str(roomy)
        r2 = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert r2.returncode == 0, r2.stderr[-2000:]
        assert "cannot be read" not in r2.stderr
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


# ---------------------------------------------------------------- bad seeds, names, files


@pytest.mark.parametrize("argv, words", [
    (["run", "{rec}", "--seed", "-1"], "seed must be an integer in [0, 2**64), got -1"),
    (["run", "{rec}", "--seed", str(2**64)], "seed must be an integer in [0, 2**64)"),
    (["run", "{rec}", "--seed", "1.5"], "seed '1.5' is not a decimal integer"),
    (["run", "{rec}", "--seed", "0x10"], "seed '0x10' is not a decimal integer"),
    (["simulate", "{cfg}", "-o", "{tmp}/x.h5", "--seed", "-1"], "seed must be an integer in [0, 2**64), got -1"),
    (["simulate", "{cfg}", "-o", "{tmp}"], "is a directory; give a record file name ending in .h5"),
    (["simulate", "{cfg}", "-o", "{tmp}/x.txt"], "unknown record format '.txt'"),
    (["design", "{rec}", "-o", "{tmp}/fig.xyz"], "unknown figure format '.xyz'"),
    (["design", "{rec}", "-o", "{tmp}"], "is a directory"),
    (["compare", "{rec}"], "is an HDF5 file (a test record?), not a result file"),
    (["compare", "{u16}"], "is not UTF-8 text"),
    (["simulate", "{u16}", "-o", "{tmp}/x.h5"], "is not UTF-8 text"),
    (["simulate", "{deep}", "-o", "{tmp}/x.h5"], "nested too deeply"),
    (["run", "{rec}", "--priors", "{u16}"], "is not UTF-8 text"),
    (["run", "{rec}", "--priors", "{binary}"], "is not UTF-8 text"),
    (["run", "{rec}", "--priors", "{deep}"], "nested too deeply"),
    (["run", "{rec}", "--priors", "{tmp}"], "is a folder, not a prior file"),
    (["run", "{rec}", "--priors", "{rec}"], "is an HDF5 file (a test record?), not a prior file"),
    (["simulate", "{rec}", "-o", "{tmp}/x.h5"], "is an HDF5 file (a test record?), not a simulation configuration"),
    (["inspect", "{u16}"], "is not an HDF5 file"),
    (["run", "{rec}", "--out", ""], "argument --out: an empty path"),
    (["campaign", "{rec}", "--out", ""], "argument --out: an empty path"),
    (["analyze", ""], "argument file: an empty path"),
    (["priors", "I1", "--nu", "0.4", "--out", ""], "argument --out: an empty path"),
    (["import", "--setup", "", "-o", "{tmp}/x.h5"], "argument --setup: an empty path"),
    (["analyze", "{tmp}"], "is a directory"),
])
def test_bad_input_is_one_sentence_before_any_work(record, tmp_path, capsys, argv, words):
    files = {
        "rec": str(record), "tmp": str(tmp_path),
        "cfg": str(Path(__file__).resolve().parents[1] / "data" / "configs" / "A-01.toml"),
        "u16": tmp_path / "u16.toml", "deep": tmp_path / "deep.toml", "binary": tmp_path / "bin.toml",
    }
    files["u16"].write_bytes("material = 'I1'\n".encode("utf-16"))
    files["deep"].write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    files["binary"].write_bytes(np.random.default_rng(1).integers(0, 256, 300, dtype=np.uint8).tobytes())
    args = [a.format(**{k: str(v) for k, v in files.items()}) for a in argv]
    before = sorted(p.name for p in tmp_path.iterdir())
    try:
        code = main(args)
    except SystemExit as e:  # argparse usage errors
        code = e.code
    assert code == 2
    assert words in _one_sentence(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written
