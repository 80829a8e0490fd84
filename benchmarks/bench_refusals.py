"""Time and peak memory of refusing over-limit inputs (docs/limits.md): each must take under 5 s and 500 MB.

    python benchmarks/bench_refusals.py

Crafts each input in a temporary folder (a record declaring 10^8 and 10^12 samples in a few kB, a
simulation at 1 GHz for 0.1 s, a TOML key of 50,000 dotted parts, /dev/zero as a configuration and
as a result, a campaign of two records whose output names collide), runs the command in a fresh
interpreter (so the time includes importing the libraries, as a user sees it) and prints one table
row per input: exit status, wall time, the process's peak resident memory and the first words of
its one sentence.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "data" / "configs" / "A-01.toml"


def _declares(path: Path, n: int) -> Path:
    with h5py.File(path, "r+") as fh:
        for name in list(fh["signals"]):
            attrs = dict(fh["signals"][name].attrs)
            del fh["signals"][name]
            ds = fh["signals"].create_dataset(name, shape=(n,), dtype="f4", chunks=(2**16,), compression="gzip")
            ds.attrs.update(attrs)
    return path


def _ids(path: Path, campaign: str, test_id: str) -> Path:
    with h5py.File(path, "r+") as fh:
        fh.attrs["campaign"], fh.attrs["test_id"] = campaign, test_id
    return path


def inputs(d: Path) -> dict[str, list[str]]:
    good = write_closed_form_record(d / "good.h5", ClosedFormTest(), seed=1, test_id="A-01", campaign="A")
    copies = {}
    for name in ("bomb", "huge", "a", "b"):
        copies[name] = d / f"{name}.h5"
        shutil.copyfile(good, copies[name])
    _declares(copies["bomb"], 10**8)
    _declares(copies["huge"], 10**12)
    _ids(copies["a"], "A_B", "C")
    _ids(copies["b"], "A", "B_C")
    ghz = d / "ghz.toml"
    ghz.write_text(CONFIG.read_text().replace("sample_rate = 5e6", "sample_rate = 1e9")
                   .replace("duration = 1.3e-3", "duration = 0.1"))
    dotted = d / "dotted.toml"
    dotted.write_text("a" + ".a" * 50_000 + " = 1\n")
    return {
        "record declaring 1e8 samples (gzip)": ["analyze", str(copies["bomb"])],
        "record declaring 1e12 samples": ["run", str(copies["huge"]), "--out", str(d / "o")],
        "simulation 1 GHz x 0.1 s": ["simulate", str(ghz), "-o", str(d / "x.h5")],
        "TOML key of 50,000 parts": ["simulate", str(dotted), "-o", str(d / "x.h5")],
        "/dev/zero as configuration": ["simulate", "/dev/zero", "-o", str(d / "x.h5")],
        "/dev/zero to compare": ["compare", "/dev/zero"],
        "campaign, colliding names": ["campaign", str(copies["a"]), str(copies["b"]), "--out", str(d / "c")],
    }


def measure(argv: list[str]) -> tuple[int, float, float, str]:
    with tempfile.TemporaryFile("w+") as err:
        t = time.perf_counter()
        p = subprocess.Popen([sys.executable, "-m", "friction_uq.cli", *argv], stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.perf_counter() - t
        err.seek(0)
        text = err.read().strip()
    return os.waitstatus_to_exitcode(status), seconds, usage.ru_maxrss / 1024.0, text


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        cases = inputs(Path(tmp))
        print(f"{'input':<38} {'exit':>4} {'s':>6} {'MB':>6}  sentence")
        for name, argv in cases.items():
            code, seconds, mb, text = measure(argv)
            flag = "" if code == 2 and seconds < 5 and mb < 500 and len(text.splitlines()) == 1 else "  <-- over target"
            print(f"{name:<38} {code:>4} {seconds:>6.2f} {mb:>6.0f}  {text.replace(tmp, '$TMP')[:70]}{flag}")


if __name__ == "__main__":
    main()
