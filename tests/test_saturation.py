"""A run of equal samples at a channel's peak: a rail the reader refuses, or a plateau on one code it reads and the
analysis warns of (friction_uq.record.saturation)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.analysis import prepare
from friction_uq.errors import RecordError
from friction_uq.record import CLIP_RUN, read_record
from friction_uq.record.saturation import flat_run, longest_run, noise_sd, run_needed

A03 = Path(__file__).parents[1] / "data" / "A" / "A-03.h5"


def quantised(x: np.ndarray, fill: float, bits: int = 8) -> np.ndarray:
    """``x`` read by a bipolar digitiser of 2**bits codes whose range is max|x| / fill (fill > 1: it clips)."""
    step = 2.0 * np.abs(x).max() / fill / 2**bits
    return np.clip(np.round(x / step), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * step


def a03_with(tmp_path: Path, name: str, transform) -> Path:
    path = tmp_path / "record.h5"
    shutil.copyfile(A03, path)
    with h5py.File(path, "r+") as fh:
        ds = fh["signals"][name]
        attrs = dict(ds.attrs)
        data = transform(ds[()].astype(float)).astype(np.float32)
        del fh["signals"][name]
        fh["signals"].create_dataset(name, data=data)
        fh["signals"][name].attrs.update(attrs)
    return path


def test_run_needed_limits() -> None:
    assert run_needed(0.0, 1.0, 1000) == math.inf  # no noise: nothing tells a rail from a code
    assert run_needed(1.0, 0.0, 1000) == CLIP_RUN  # unquantised: any run of equal samples is a rail
    assert run_needed(100.0, 1.0, 10_000) == CLIP_RUN  # a noise of many codes: the floor
    runs = [run_needed(s, 1.0, 5000) for s in (2.0, 1.0, 0.5, 0.3)]
    assert runs == sorted(runs) and runs[-1] > 50  # the quieter the noise, the longer the run it leaves


@pytest.mark.parametrize("sigma", [0.5, 0.8, 1.5])
def test_white_noise_on_a_plateau_rarely_reaches_the_needed_run(sigma: float) -> None:
    """The longest run of one code in n samples of white noise reaches run_needed on at most a few of 400 plateaus
    (its bound: RUN_ALPHA of them, 0.4); the level is put where a run is likeliest, the code's centre."""
    n, reached = 4000, 0
    rng = np.random.default_rng(7)
    need = run_needed(sigma, 1.0, n)
    for _ in range(400):
        codes = np.round(rng.normal(0.0, sigma, n))
        reached += max(longest_run(codes == v) for v in (-1.0, 0.0, 1.0)) >= need
    assert reached <= 2


@settings(max_examples=50, deadline=None)
@given(st.floats(0.6, 5.0), st.integers(0, 2**32 - 1))
def test_noise_sd_undoes_the_rounding(sigma: float, seed: int) -> None:
    """Sheppard's correction: the sd of noise rounded to unit codes, less 1/12, is the noise's within 15 %."""
    x = np.round(np.random.default_rng(seed).normal(0.3, sigma, 20_000))
    assert noise_sd(x, 1.0) == pytest.approx(sigma, rel=0.15)


def test_noise_on_two_codes_is_not_resolved() -> None:
    assert noise_sd(np.array([0.0, 1.0] * 50), 1.0) == 0.0


def test_8bit_plateau_is_read_and_warned_of(tmp_path: Path) -> None:
    """A-03's internal bar read at 8 bits, its peak at 70 % of the range: the peak sits on one code for runs its
    noise (below a code) makes; read, with a note that says the run cannot be told from a rail."""
    path = a03_with(tmp_path, "internal_output_bar", lambda x: quantised(x, 0.7))
    run = flat_run(h5py.File(path)["signals"]["internal_output_bar"][()])
    assert run is not None and run.run >= CLIP_RUN and not run.saturated
    prep = prepare(read_record(path))
    assert len(prep.flat_runs) == 1 and prep.flat_runs[0].startswith("/signals/internal_output_bar sits on one value")


def test_clean_records_have_no_flat_run() -> None:
    assert prepare(read_record(A03)).flat_runs == ()


def test_8bit_channel_with_resolved_noise_clipped_is_refused(tmp_path: Path) -> None:
    """The external bar's noise spans many 8-bit codes: a range ending at 60 % of its peak is a rail."""
    path = a03_with(tmp_path, "external_output_bar", lambda x: quantised(x, 1.6))
    with pytest.raises(RecordError, match=r"/signals/external_output_bar: is clipped: \d+ consecutive samples"):
        read_record(path)


def test_8bit_channel_below_its_noise_clipped_is_warned_of(tmp_path: Path) -> None:
    """The internal bar's noise is below one 8-bit code: its range ending at 80 % of the peak cannot be told from a
    plateau by the run alone; read, with the note (and the force balance's, 84 %)."""
    path = a03_with(tmp_path, "internal_output_bar", lambda x: quantised(x, 1.25))
    prep = prepare(read_record(path))
    assert any("internal_output_bar sits on one value" in n for n in prep.flat_runs)
