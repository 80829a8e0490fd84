"""The installed package (a wheel, not the checkout) runs the main job from any folder.

The wheel is built with pip, installed without dependencies into a fresh virtual environment that
borrows the test environment's third-party packages (a path file placed after the environment's own
site-packages, so the installed wheel, not the checkout, is what imports), and ``friction-uq run``
is started from an unrelated folder on a bundled record. The slow variant installs the wheel with
its dependencies from the package index into a fresh environment of every other Python >= 3.12
found (3.13 here).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "data" / "A" / "A-03.h5"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", str(ROOT),
                        "-w", str(out)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    (whl,) = out.glob("friction_uq-*.whl")
    return whl


def _venv(python: str, where: Path, env: dict[str, str] | None = None) -> Path:
    r = subprocess.run([python, "-m", "venv", str(where)], capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stderr[-2000:]
    return where / "bin"


def _site_packages(bindir: Path) -> Path:
    out = subprocess.run([str(bindir / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                         capture_output=True, text=True, check=True)
    return Path(out.stdout.strip())


def _run_from_elsewhere(bindir: Path, tmp: Path, *extra: str) -> dict:
    work = tmp / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    where = subprocess.run([str(bindir / "python"), "-c", "import friction_uq, sys; print(friction_uq.__file__)"],
                           capture_output=True, text=True, cwd=work, env=env)
    assert where.returncode == 0, where.stderr[-2000:]
    assert str(ROOT) not in where.stdout, f"imports the checkout: {where.stdout}"
    r = subprocess.run([str(bindir / "friction-uq"), "run", str(RECORD), "--out", "out", "--quiet", "--seed", "5",
                        *extra], capture_output=True, text=True, cwd=work, env=env, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    (js,) = (work / "out").glob("*.json")
    doc = json.loads(js.read_text())
    assert sorted(doc["f_under_nu_priors"]) == ["default", "nu-tight", "nu-wide"]  # the three nu priors compared
    assert "site-packages" in doc["prior_file"] and str(ROOT) not in doc["prior_file"]
    for s in doc["f_under_nu_priors"].values():
        assert s["q05"] < s["q50"] < s["q95"]
    return doc


def test_wheel_contains_the_prior_files(wheel):
    """The repository keeps one copy of the prior files, its top-level priors/; the wheel ships it in the package."""
    import zipfile

    z = zipfile.ZipFile(wheel)
    names = z.namelist()
    shipped = sorted((ROOT / "priors").glob("*.toml"))
    assert [f.name for f in shipped] == ["I1-nu-tight.toml", "I1-nu-wide.toml", "I1.toml"]
    for f in shipped:
        assert z.read(f"friction_uq/prior_files/{f.name}") == f.read_bytes()
    assert not [n for n in names if n.startswith("priors/")]
    assert not (ROOT / "friction_uq" / "prior_files").exists()  # no second copy in the checkout


def test_installed_wheel_runs_from_another_folder(wheel, tmp_path):
    bindir = _venv(sys.executable, tmp_path / "venv")
    r = subprocess.run([str(bindir / "python"), "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheel)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    # borrow this environment's third-party packages, after the new environment's own
    site = _site_packages(bindir)
    (site / "zz_borrowed_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    doc = _run_from_elsewhere(bindir, tmp_path, "--no-pdf")
    assert doc["outputs"]["pdf"] is None and doc["converged"]


def _other_pythons() -> list[str]:
    """Interpreters >= 3.12 other than this one's version: on PATH, or installed by pyenv."""
    cands = [shutil.which(n) for n in ("python3.13", "python3.12")]
    pyenv = shutil.which("pyenv")
    if pyenv:
        root = subprocess.run([pyenv, "root"], capture_output=True, text=True).stdout.strip()
        bare = subprocess.run([pyenv, "versions", "--bare"], capture_output=True, text=True).stdout.split()
        cands += [str(Path(root) / "versions" / v / "bin" / "python3") for v in bare if v.startswith(("3.12", "3.13"))]
    found: dict[str, str] = {}
    for exe in filter(None, cands):
        r = subprocess.run([exe, "-c", "import sys; print(*sys.version_info[:2])"], capture_output=True, text=True)
        if r.returncode != 0:
            continue
        version = tuple(map(int, r.stdout.split()))
        if version >= (3, 12) and version != sys.version_info[:2]:
            found.setdefault(".".join(map(str, version)), exe)
    return list(found.values())


@pytest.mark.slow
@pytest.mark.parametrize("python", _other_pythons() or [pytest.param(None, marks=pytest.mark.skip(
    reason="no other Python >= 3.12 on this machine"))])
def test_wheel_with_its_dependencies_on_another_python(wheel, tmp_path, python):
    bindir = _venv(python, tmp_path / "venv")
    r = subprocess.run([str(bindir / "python"), "-m", "pip", "install", "-q", str(wheel)],
                       capture_output=True, text=True, timeout=1800)
    if r.returncode != 0:
        pytest.fail(f"installing the wheel with its dependencies on {python} failed: {r.stderr[-2000:]}")
    doc = _run_from_elsewhere(bindir, tmp_path)
    assert doc["outputs"]["pdf"]["file"].endswith(".pdf")
