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
from friction_uq.record.saturation import digitiser_step, flat_run, noise_sd, run_needed
from friction_uq.stats.robust import quantisation_step

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
    assert run_needed(1.0, 1000) == math.inf  # a noise that never leaves its code: nothing tells a rail from it
    assert run_needed(0.0, 1000) == CLIP_RUN  # unquantised: any run of equal samples is a rail
    assert run_needed(0.01, 10_000) == CLIP_RUN  # a noise of many codes: the floor
    runs = [run_needed(p, 5000) for p in (0.2, 0.4, 0.7, 0.9)]
    assert runs == sorted(runs) and runs[-1] > 50  # the likelier a stay, the longer the run it leaves


def quantised_noise(n: int, sigma: float, rho: float, seed: int, level: float = 0.0) -> np.ndarray:
    """AR(1) noise of sd ``sigma`` and lag-1 ``rho`` about ``level``, rounded to unit codes."""
    rng = np.random.default_rng(seed)
    e = rng.normal(0.0, sigma * math.sqrt(1.0 - rho**2), n)
    x = np.empty(n)
    x[0] = rng.normal(0.0, sigma)
    for i in range(1, n):
        x[i] = rho * x[i - 1] + e[i]
    return np.round(level + x)


@pytest.mark.parametrize(("sigma", "rho"), [(0.5, 0.0), (0.8, 0.0), (1.5, 0.0), (1.5, 0.99), (2.0, 0.99),
                                            (3.0, 0.995)])
def test_a_quantised_plateau_that_never_saturated_is_not_called_saturated(sigma: float, rho: float) -> None:
    """A record whose pre-trigger and plateau carry the same noise (white or AR(1) up to 0.995), rounded to codes,
    the plateau's level at a code's centre (where runs are likeliest), never clipped: its longest run at the peak
    is saturated on at most 2 of 100 records (the bound: RUN_ALPHA of them). White noise's sd alone made
    coloured noise's runs rails (3 to 8 in 100 refused)."""
    called = 0
    for seed in range(100):
        noise = quantised_noise(4000, sigma, rho, seed)
        x = np.concatenate([noise[:400], 40.0 + noise[400:]])  # the pre-trigger, then a plateau 40 codes up
        run = flat_run(x)
        called += run is not None and run.saturated
    assert called <= 2


def test_a_rail_on_a_quiet_channel_resolved_by_its_pre_trigger_is_refused() -> None:
    """Noise of a quarter code about a code's centre: the pre-trigger holds three codes (a few samples off the
    middle one), so the noise is resolved though the rounding correction leaves no sd; a 2000-sample run at a
    rail is no plateau's (it was only warned of)."""
    noise = quantised_noise(6000, 0.25, 0.0, 3)
    x = noise.copy()
    x[400:2400] = np.minimum(60.0 + noise[400:2400], 50.0)  # the pulse, its top cut by the rail, then the baseline
    run = flat_run(x)
    assert run is not None and run.run > 1900 and run.saturated


def test_a_spike_or_a_front_in_the_pre_trigger_does_not_make_a_plateau_a_rail() -> None:
    """The 8-bit A-03 internal bar (a plateau on one code, warned of): a spike in its pre-trigger, or a pre-trigger
    shorter than the 2 % head, once made its noise several codes and the run a rail."""
    x = h5py.File(A03)["signals"]["internal_output_bar"][()].astype(float)
    q = quantised(x, 0.7)
    spiked = q.copy()
    spiked[50:52] += 40 * digitiser_step(q)
    for channel in (spiked, q[260:]):  # the pulse 140 samples in, the head 2 % of 6240 = 124 samples
        run = flat_run(channel)
        assert run is not None and not run.saturated


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


def test_a_rail_behind_an_unfilled_pre_trigger_is_still_refused(tmp_path: Path) -> None:
    """The external bar at 8 bits, its range ending at 60 % of its peak (refused), and its first 100 samples 0 (an
    unfilled pre-trigger): the pre-trigger the run is judged by starts after them (it was all zeros: no run judged,
    the record read)."""
    def clipped_and_padded(x: np.ndarray) -> np.ndarray:
        q = quantised(x, 1.6)
        q[:100] = 0.0
        return q

    path = a03_with(tmp_path, "external_output_bar", clipped_and_padded)
    with pytest.raises(RecordError, match=r"/signals/external_output_bar: is clipped"):
        read_record(path)


def test_a_pre_trigger_on_one_code_is_read(tmp_path: Path) -> None:
    """A-03's internal bar read at 8 bits with its peak at 8 % of the range: its pre-trigger sits on one code, a noise
    sd of 0 that the likelihood refused ("noise sd_io must be a positive number, got 0.0"). The noise is now at least
    the rounding's, step / sqrt(12), and the record is analysed; a 2-sample spike of 40 codes on that pre-trigger
    changes nothing."""
    path = a03_with(tmp_path, "internal_output_bar", lambda x: quantised(x, 0.08))
    rec = read_record(path)
    strain = rec.strain("internal_output_bar")
    noise = prepare(rec).forces.channels["internal_output_bar"].noise
    assert np.ptp(strain[noise.start:noise.stop]) == 0.0  # one code
    assert noise.sd == pytest.approx(quantisation_step(strain) / math.sqrt(12.0), rel=1e-9)
    raw_step = digitiser_step(h5py.File(path)["signals"]["internal_output_bar"][()].astype(float))
    (tmp_path / "spiked").mkdir()
    spiked = a03_with(tmp_path / "spiked", "internal_output_bar",
                      lambda v: quantised(v, 0.08) + np.where(np.isin(np.arange(v.size), [50, 51]), 40 * raw_step, 0.0))
    assert prepare(read_record(spiked)).forces.channels["internal_output_bar"].noise == noise
