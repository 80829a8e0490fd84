"""Laboratory faults put into a bundled record, and what the package says of each.

A measured record differs from a simulated one in ways no simulator makes: a coarse digitiser, a
trigger's pick-up, a short pre-trigger, a scope that stopped early, a dead bridge, a light gate read
wrong, a zero-padded export. Each fault below is put into ``data/A/A-03.h5`` (a copy, in a temporary
folder) and the record taken through ``read_record``, the gauge check of ``inspect`` and the stationary
analysis (``analyze``: eq. 17 at the nominal nu, the window, the warnings that need no sampling); with
``--run``, through ``friction_uq.run`` as well (its headline f and warnings, about 15 s a record).

    python benchmarks/lab_faults.py [--run] [--only NAME,...]

One line per fault: what was done, what the package says (refused with its sentence, or the notes and
f), and the verdict a lab wants: *refused* (the record cannot be analysed as it is, and the sentence
says why), *read* (analysed; the notes say what was seen). The table in ``docs/laboratory-faults.md``
is this script's output.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
from scipy.signal import lfilter

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "data" / "A" / "A-03.h5"

Channels = dict[str, np.ndarray]


def quantised(x: np.ndarray, fill: float, bits: int = 8) -> np.ndarray:
    """``x`` read by a bipolar digitiser of 2**bits codes whose range is max|x| / fill (fill > 1: it clips)."""
    step = 2.0 * np.abs(x).max() / fill / 2**bits
    return np.clip(np.round(x / step), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * step


def with_channel(name: str, change: Callable[[np.ndarray], np.ndarray]) -> Callable[[Channels, dict], None]:
    def edit(ch: Channels, attrs: dict) -> None:
        ch[name] = change(ch[name].copy())
    return edit


def spike_before(ch: Channels, attrs: dict) -> None:
    x = ch["input_bar"].copy()
    i = int((-attrs["t0"] - 20e-6) * attrs["sample_rate"])
    x[i:i + 2] -= 0.8 * np.abs(x).max()  # two samples, the pulse's sign (compression reads negative volts)
    ch["input_bar"] = x


def cut(pre_us: float, length_us: float | None = None) -> Callable[[Channels, dict], None]:
    """A trigger ``pre_us`` before the incident wave, ``length_us`` recorded."""
    def edit(ch: Channels, attrs: dict) -> None:
        fs, t0 = attrs["sample_rate"], attrs["t0"]
        start = int(round((-t0 - pre_us * 1e-6) * fs))
        stop = None if length_us is None else start + int(length_us * 1e-6 * fs)
        for k in ch:
            ch[k] = ch[k][start:stop]
        attrs["t0"] = t0 + start / fs
    return edit


def striker(v: float) -> Callable[[Channels, dict], None]:
    def edit(ch: Channels, attrs: dict) -> None:
        attrs["striker_velocity"] = v
    return edit


def zero_padded(n: int) -> Callable[[np.ndarray], np.ndarray]:
    def change(x: np.ndarray) -> np.ndarray:
        x[:n] = 0.0
        return x
    return change


def creep(fraction: float, tau: float) -> Callable[[Channels, dict], None]:
    """The external bar's zero creeping from the trigger by ``fraction`` of its peak, 1 - exp(-t / tau)."""
    def edit(ch: Channels, attrs: dict) -> None:
        x = ch["external_output_bar"]
        t = np.arange(x.size) / attrs["sample_rate"]
        peak = float(np.min(x) - np.median(x[:200]))  # compression reads negative volts
        ch["external_output_bar"] = x + fraction * peak * (1.0 - np.exp(-t / tau))
    return edit


def clipped_with_noise(ch: Channels, attrs: dict) -> None:
    """The external bar's amplifier saturating at 60 % of its peak, the digitiser's noise after it."""
    x = ch["external_output_bar"]
    base, sd = float(np.median(x[:200])), float(np.std(x[:200]))
    smooth = np.convolve(x, np.ones(9) / 9, mode="same")
    rail = base + 0.6 * (float(np.min(x)) - base)
    ch["external_output_bar"] = np.maximum(smooth, rail) + np.random.default_rng(5).normal(0.0, sd, x.size)


def coloured_noise(rho: float, level: float, seed: int) -> Callable[[Channels, dict], None]:
    """AR(1) noise of lag-1 ``rho`` and sd ``level`` times each channel's peak added to every channel (as
    ``tests/test_force_noise.py`` makes it)."""
    def edit(ch: Channels, attrs: dict) -> None:
        rng = np.random.default_rng(seed)
        for k in sorted(ch):
            x = ch[k]
            peak = float(np.max(np.abs(x - np.median(x[:200]))))
            noise = lfilter([np.sqrt(1.0 - rho * rho)], [1.0, -rho], rng.normal(size=x.size + 5000))[5000:]
            ch[k] = x + level * peak * noise
    return edit


def one_code_spike(ch: Channels, attrs: dict) -> None:
    """The internal bar read at 8 bits with its peak at 8 % of the range (its pre-trigger on one code), and a 2-sample
    spike of 40 codes 50 samples in."""
    x = quantised(ch["internal_output_bar"], 0.08)
    step = 2.0 * np.abs(ch["internal_output_bar"]).max() / 0.08 / 2**8
    x[50:52] += 40 * step * np.sign(np.min(x) or -1.0)
    ch["internal_output_bar"] = x


def step_before(ch: Channels, attrs: dict) -> None:
    """A baseline step of 10 % of the external bar's peak 20 us before its wave (about sample 1830)."""
    x = ch["external_output_bar"]
    i = int(round((-attrs["t0"] + 346e-6 - 20e-6) * attrs["sample_rate"]))
    ch["external_output_bar"] = np.concatenate([x[:i], x[i:] + 0.1 * (float(np.min(x)) - float(np.median(x[:200])))])


#: name -> (what is done, the edit of the channels and attributes)
FAULTS: dict[str, tuple[str, Callable[[Channels, dict], None]]] = {
    "clean": ("nothing (the bundled record)", lambda ch, a: None),
    "8bit_internal_70": ("internal bar read at 8 bits, its peak at 70 % of the range",
                         with_channel("internal_output_bar", lambda x: quantised(x, 0.7))),
    "8bit_input_50": ("input bar read at 8 bits, its peak at 50 % of the range",
                      with_channel("input_bar", lambda x: quantised(x, 0.5))),
    "8bit_internal_clipped": ("internal bar at 8 bits, the range ending at 80 % of its peak (noise below a code)",
                              with_channel("internal_output_bar", lambda x: quantised(x, 1.25))),
    "8bit_external_clipped": ("external bar at 8 bits, the range ending at 60 % of its peak (noise over codes)",
                              with_channel("external_output_bar", lambda x: quantised(x, 1.6))),
    "spike_before_front": ("a 2-sample spike of 80 % of the pulse on the input bar, 20 us before its front",
                           spike_before),
    "pretrigger_25us": ("triggered 25 us before the incident wave (2 % of the record is 26 us)", cut(25.0)),
    "pretrigger_12us": ("triggered 12 us before the incident wave", cut(12.0)),
    "stopped_early": ("triggered 40 us before, 1000 us recorded: the reflected wave's last 37 us missing",
                      cut(40.0, 1000.0)),
    "dead_hoop": ("the hoop bridge dead: its channel one constant", with_channel("tube_hoop", lambda x: 0 * x + x[0])),
    "striker_6_for_9.9": ("the light gate read 6 m/s for a 9.9 m/s shot", striker(6.0)),
    "zero_padded_external": ("the external bar's first 100 samples exactly 0 (an unfilled pre-trigger)",
                             with_channel("external_output_bar", zero_padded(100))),
    "one_code": ("internal bar at 8 bits, peak at 8 % of the range (its pre-trigger on one code)",
                 with_channel("internal_output_bar", lambda x: quantised(x, 0.08))),
    "one_code_spike": ("internal bar at 8 bits, peak at 8 % of the range (pre-trigger on one code), a 2-sample spike "
                       "of 40 codes on it", one_code_spike),
    "coloured_noise": ("lag-1 0.99 noise of 3 % of each channel's peak on every channel (seed 9)",
                       coloured_noise(0.99, 0.03, 9)),
    # known gaps (docs/laboratory-faults.md): f moves, and nothing but the record's usual warning says so
    "hoop_gain_0.85": ("the hoop gauge reading 15 % low (a gauge factor or a lead's resistance)",
                       with_channel("tube_hoop", lambda x: 0.85 * x)),
    "external_zero_creep": ("the external bar's zero creeping by 15 % of its peak from the trigger (tau 300 us)",
                            creep(0.15, 300e-6)),
    "external_clipped_noisy": ("the external bar's amplifier saturating at 60 % of its peak, noise after it",
                               clipped_with_noise),
    "external_step": ("a baseline step of 10 % of the external bar's peak 20 us before its wave", step_before),
}


def write_faulty(dst: Path, edit: Callable[[Channels, dict], None]) -> None:
    shutil.copyfile(SOURCE, dst)
    with h5py.File(dst, "r+") as fh:
        sig = fh["signals"]
        ch = {k: sig[k][()].astype(float) for k in sig}
        attrs = {"sample_rate": float(sig.attrs["sample_rate"]), "t0": float(sig.attrs["t0"]),
                 "striker_velocity": float(fh.attrs["striker_velocity"])}
        edit(ch, attrs)
        for k, data in ch.items():
            keep = dict(sig[k].attrs)
            del sig[k]
            sig.create_dataset(k, data=data.astype(np.float32))
            sig[k].attrs.update(keep)
        sig.attrs["t0"] = attrs["t0"]
        fh.attrs["striker_velocity"] = attrs["striker_velocity"]


def said(path: Path, *, run: bool, out: Path) -> tuple[str, str]:
    """(verdict, what the package says) of one record."""
    from friction_uq.analysis import identify, prepare
    from friction_uq.errors import FrictionUQError
    from friction_uq.gauge_check import record_gauge_check
    from friction_uq.record import read_record

    try:
        rec = read_record(path)
        faults, notes = record_gauge_check(rec)
        if faults:
            return "refused", f"inspect: {faults[0].sentence}"
        prep = prepare(rec)
        lab = identify(prep, nu=0.4)  # the nominal nu, as analyze
    except FrictionUQError as exc:
        return "refused", str(exc).removeprefix(f"{path}: ")
    words = [n.sentence for n in notes if n.kind != "ok"] or [n.sentence for n in notes]
    text = f"f (eq. 17) {lab.f:.4f}; " + " | ".join(words)
    if run:
        from friction_uq import run as run_record

        res = run_record(path, out_dir=out, pdf=False)
        f = res.f
        text = (f"headline f {f['q50']:.4f} [{f['q05']:.4f}, {f['q95']:.4f}], {len(res.warnings)} warning(s): "
                + " | ".join(w[:100] for w in res.warnings) + "; " + text)
    return "read", text


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", action="store_true", help="also friction_uq.run each record (about 15 s a record)")
    ap.add_argument("--only", default="", help="comma-separated fault names")
    args = ap.parse_args(argv)
    names = [n for n in FAULTS if not args.only or n in args.only.split(",")]
    print(f"{'fault':<24} {'verdict':<8} seconds  what the package says")
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            what, edit = FAULTS[name]
            path = Path(tmp) / f"{name}.h5"
            write_faulty(path, edit)
            t = time.perf_counter()
            verdict, text = said(path, run=args.run, out=Path(tmp) / "out")
            print(f"{name:<24} {verdict:<8} {time.perf_counter() - t:7.1f}  {what}: {text}")
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
