"""Generic signal code: noise, arrivals, transport. Closed forms and property tests."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from friction_uq.errors import ShortPreTrigger, SignalError
from friction_uq.signals import (ARRIVAL_SIGMAS, SPIKE_FILTER, SPIKE_SIGMAS, baseline_free, first_crossing, noise_estimate, padding,
                                 prepulse_noise, pulse_arrival, pulse_front, transport)
from friction_uq.stats.robust import despiked, quantisation_step, running_median
from friction_uq.noise import white_and_ar1_noise

FS = 5e6
DT = 1.0 / FS
C = 4555.0


def ramp_pulse(n: int, foot: float, *, rise: int = 100, plateau: int = 1500, amp: float = 1e-3) -> np.ndarray:
    """Trapezoid with a smooth (raised-cosine) front whose foot is at fractional index ``foot``.

    The 10 % and 50 % crossings of a raised cosine are not on a line through the foot, so
    the test compares arrivals before/after transport rather than against ``foot`` itself.
    """
    i = np.arange(n, dtype=float)
    u = np.clip((i - foot) / rise, 0, 1)
    up = 0.5 - 0.5 * np.cos(np.pi * u)
    d = np.clip((foot + rise + plateau + rise - i) / rise, 0, 1)
    down = 0.5 - 0.5 * np.cos(np.pi * d)
    return amp * np.minimum(up, down)


def linear_front(n: int, foot: float, *, rise: int = 50, amp: float = 1e-3) -> np.ndarray:
    i = np.arange(n, dtype=float)
    return amp * np.clip((i - foot) / rise, 0, 1)


def test_noise_estimate_recovers_ar1_parameters():
    rng = np.random.default_rng(7)
    x = 2e-5 + white_and_ar1_noise(200_000, sd=3e-6, rho=0.6, white_fraction=0.0, rng=rng)
    e = noise_estimate(x, stop=len(x))
    assert e.offset == pytest.approx(2e-5, abs=3 * 3e-6 / np.sqrt(200_000 * 0.25))
    assert e.sd == pytest.approx(3e-6, rel=0.02)
    assert e.rho == pytest.approx(0.6, abs=0.01)


def test_noise_estimate_needs_enough_samples():
    with pytest.raises(SignalError, match="at least 32 are needed"):
        noise_estimate(np.zeros(10), stop=10)


@pytest.mark.parametrize("foot", [700.0, 700.25, 700.5, 933.8])
def test_arrival_of_a_linear_front_is_exact(foot):
    x = linear_front(3000, foot)
    assert pulse_arrival(x, offset=0.0, sd=1e-9) == pytest.approx(foot, abs=1e-6)


@pytest.mark.parametrize("distance", [1.22, 0.33, 0.295])
def test_transported_pulse_arrives_where_travel_time_says(distance):
    """A pulse at a gauge, transported to the interface, arrives distance/c later within 0.1 sample."""
    n = 8192
    x = ramp_pulse(n, 600.3)
    a0 = pulse_arrival(x, offset=0.0, sd=1e-9)
    y = transport(x, sample_interval=DT, distance=distance, wave_speed=C)
    a1 = pulse_arrival(y, offset=0.0, sd=1e-9)
    expected = distance / C * FS
    assert a1 - a0 == pytest.approx(expected, abs=0.1)
    # and a linear front lands on its exact foot (foot moved by the travel time)
    z = transport(linear_front(n, 600.0, rise=200), sample_interval=DT, distance=distance, wave_speed=C)
    assert pulse_arrival(z, offset=0.0, sd=1e-9) == pytest.approx(600.0 + expected, abs=0.1)


def test_transport_back_and_forth_is_identity():
    x = ramp_pulse(4096, 1000.0)
    y = transport(transport(x, sample_interval=DT, distance=1.22, wave_speed=C),
                  sample_interval=DT, distance=-1.22, wave_speed=C)
    assert np.max(np.abs(y - x)) < 1e-9 * np.max(x) + 1e-6 * np.max(x)


def test_prepulse_noise_on_a_noisy_record():
    rng = np.random.default_rng(3)
    n = 6000
    x = ramp_pulse(n, 800.0) + 1e-5 + white_and_ar1_noise(n, sd=3e-6, rho=0.5, white_fraction=0.3, rng=rng)
    est, arr = prepulse_noise(x, polarity=+1)
    assert est.stop <= 800
    assert est.offset == pytest.approx(1e-5, abs=1.5e-6)
    assert est.sd == pytest.approx(3e-6, rel=0.15)
    assert arr == pytest.approx(pulse_arrival(ramp_pulse(n, 800.0), offset=0, sd=1e-9), abs=5.0)


def test_no_pulse_is_refused():
    rng = np.random.default_rng(4)
    with pytest.raises(SignalError, match="no pulse rises above the noise"):
        prepulse_noise(rng.normal(0, 1e-6, 4000))


# ---------------------------------------------------------------- property tests (hypothesis)

pulses = st.builds(
    lambda foot, amp, rise: ramp_pulse(4096, foot, rise=rise, plateau=800, amp=amp),
    st.floats(500.0, 1200.0), st.floats(1e-5, 5e-3), st.integers(20, 150),
)


@settings(max_examples=25, deadline=None)
@given(x=pulses, y=pulses, a=st.floats(-3, 3), b=st.floats(-3, 3), d=st.floats(-1.5, 1.5))
def test_transport_is_linear(x, y, a, b, d):
    kw = dict(sample_interval=DT, distance=d, wave_speed=C)
    lhs = transport(a * x + b * y, **kw)
    rhs = a * transport(x, **kw) + b * transport(y, **kw)
    assert np.allclose(lhs, rhs, atol=1e-12 * (abs(a) + abs(b) + 1))


@settings(max_examples=25, deadline=None)
@given(x=pulses, k=st.integers(-300, 300))
def test_integer_delay_is_a_shift(x, k):
    y = transport(x, sample_interval=DT, distance=k * DT * C, wave_speed=C)
    expected = np.zeros_like(x)
    if k >= 0:
        expected[k:] = x[: len(x) - k]
    else:
        expected[:k] = x[-k:]
    assert np.allclose(y, expected, atol=1e-9 * np.max(np.abs(x)))


@settings(max_examples=25, deadline=None)
@given(x=pulses, shift=st.floats(-200.0, 200.0))
def test_arrival_detection_is_shift_invariant(x, shift):
    a0 = pulse_arrival(x, offset=0.0, sd=1e-12)
    y = transport(x, sample_interval=DT, distance=shift * DT * C, wave_speed=C)
    assert pulse_arrival(y, offset=0.0, sd=1e-12) - a0 == pytest.approx(shift, abs=0.1)


@settings(max_examples=200, deadline=None)
@given(y=st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=40), level=st.floats(-1.0, 1.0),
       start=st.integers(0, 39))
def test_a_crossing_lies_where_the_signal_reaches_the_level(y, level, start):
    """The crossing is at or after ``start`` less one sample, never beyond the first sample at the level: a search
    that starts where the signal is already above the level once interpolated with the sample before it, also above,
    and put the crossing millions of samples away (an IndexError in the front's walk back, on a coloured record)."""
    y = np.asarray(y)
    start = min(start, y.size - 1)
    t = first_crossing(y, level, start=start)
    at = np.flatnonzero(y[start:] >= level)
    if at.size == 0:
        assert t is None
        return
    i = start + int(at[0])
    assert max(start - 1, 0) <= t <= i and (t == i or y[int(math.floor(t))] < level)


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rho=st.floats(0.9, 0.999), level=st.floats(0.02, 0.12))
def test_a_front_is_found_inside_the_record_whatever_the_noise(seed, rho, level):
    """A pulse under strongly coloured noise (noise of up to an eighth of the pulse): the foot and the 10 % and 50 %
    crossings lie inside the record, in order. A pulse 8.3 noise sd high under noise that wanders low over its whole
    plateau (lag-1 0.999) may not rise 8 sd above the noise anywhere once spikes are filtered (seed 591635, level
    0.119): refused then, and only then."""
    x = ramp_pulse(2048, 700.0, rise=60, plateau=600) + level * 1e-3 * white_and_ar1_noise(
        2048, sd=1.0, rho=rho, white_fraction=0.0, rng=np.random.default_rng(seed))
    if float(running_median(x, SPIKE_FILTER).max()) <= ARRIVAL_SIGMAS * level * 1e-3:
        with pytest.raises(SignalError, match="no pulse rises above the noise"):
            pulse_front(x, offset=0.0, sd=level * 1e-3, start=0, polarity=+1)
        return
    foot, t10, t50 = pulse_front(x, offset=0.0, sd=level * 1e-3, start=0, polarity=+1)
    assert -0.25 * x.size <= foot <= t10 <= t50 < x.size


@settings(max_examples=25, deadline=None)
@given(x=pulses, offset=st.floats(-1e-3, 1e-3), scale=st.floats(0.1, 10.0))
def test_noise_estimate_is_offset_and_scale_equivariant(x, offset, scale):
    rng = np.random.default_rng(11)
    z = x + rng.normal(0, 1e-6, len(x))
    e0 = noise_estimate(z, stop=400)
    e1 = noise_estimate(scale * z + offset, stop=400)
    assert e1.offset == pytest.approx(scale * e0.offset + offset, abs=1e-15 + 1e-12 * abs(offset))
    assert e1.sd == pytest.approx(scale * e0.sd, rel=1e-9)
    assert e1.rho == pytest.approx(e0.rho, abs=1e-9)


@settings(max_examples=15, deadline=None)
@given(
    units=st.sampled_from(["strain", "microstrain", "V"]),
    spv=st.floats(1e-5, 1e-3),
    amp=st.floats(1e-5, 3e-3),
)
def test_units_round_trip(units, spv, amp):
    """Strain written in any of the contract's units reads back as the same strain, compression positive."""
    import tempfile
    from pathlib import Path

    from friction_uq.record import paper_apparatus, read_record, write_record

    rng = np.random.default_rng(5)
    n = 6000
    eps = {name: amp * ramp_pulse(n, 500.0 + 40 * k, amp=1.0) + rng.normal(0, 1e-7, n)
           for k, name in enumerate(["input_bar", "internal_output_bar", "external_output_bar"])}
    with tempfile.TemporaryDirectory() as d:
        p = write_record(
            Path(d) / "u.h5", test_id="U-1", campaign="U", sample_rate=FS, strains=eps,
            apparatus=paper_apparatus(), units={k: units for k in eps},
            strain_per_volt={k: spv for k in eps} if units == "V" else None,
        )
        rec = read_record(p)
    for name, e in eps.items():
        assert np.allclose(rec.strain(name), e, rtol=1e-12, atol=1e-18)
        assert rec.channels[name].units == units


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(40.0, 300.0), st.floats(0.1, 3.0), st.sampled_from([-1, 1]),
       st.integers(1, 3))
def test_a_spike_before_the_pulse_moves_neither_its_arrival_nor_the_baseline(seed, before, height, sign, width):
    """A spike of pick-up (1-3 samples, from a tenth of the pulse, 20 noise sd, to 3 times it, either sign) before
    the front: the arrival and the baseline's offset and sd are those of the record without it (it took the spike
    for the pulse's front, and its sd into the noise). A bump below 8 robust sd is noise to the filter."""
    rng = np.random.default_rng(seed)
    n, foot = 4000, 900.0
    clean = ramp_pulse(n, foot) + white_and_ar1_noise(n, sd=5e-6, rho=0.5, white_fraction=0.3, rng=rng)
    spiked = clean.copy()
    at = int(foot - before)
    spiked[at:at + width] += sign * height * 1e-3
    e0, a0 = prepulse_noise(clean)
    e1, a1 = prepulse_noise(spiked)
    assert a1 == pytest.approx(a0, abs=0.05)  # the spike sample is the running median now, not the noise it hid
    assert e1.sd == pytest.approx(e0.sd, rel=0.05) and abs(e1.offset - e0.offset) < 0.2 * e0.sd


def _noise(kind: str, seed: int, rho: float) -> np.ndarray:
    rng = np.random.default_rng(seed)
    if kind == "ar1":
        return white_and_ar1_noise(5000, sd=3e-6, rho=rho, white_fraction=0.0, rng=rng)
    if kind == "mixed":
        return white_and_ar1_noise(5000, sd=3e-6, rho=rho, white_fraction=0.2, rng=rng)
    if kind == "band-limited":  # white noise through a 20-sample moving average
        return np.convolve(rng.normal(0.0, 3e-6, 5019), np.ones(20) / 20, mode="valid")
    step = 3e-6 / (0.3 + 0.7 * rho)  # quantised: the noise's sd 0.3 to 1 digitiser step
    return np.round(white_and_ar1_noise(5000, sd=3e-6, rho=0.5, white_fraction=0.3, rng=rng) / step) * step


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["ar1", "mixed", "band-limited", "quantised"]), st.integers(0, 2**32 - 1),
       st.floats(0.0, 0.995))
def test_gaussian_noise_is_not_despiked(kind, seed, rho):
    """The spike filter leaves Gaussian noise as it is, white, AR(1) up to a lag-1 of 0.995, band-limited or read by
    a digitiser coarser than it: same bits."""
    x = _noise(kind, seed, rho)
    assert np.array_equal(despiked(x, width=SPIKE_FILTER, sigmas=SPIKE_SIGMAS), x)


@pytest.mark.parametrize("kind", ["ar1", "band-limited", "quantised"])
def test_a_spike_is_despiked_whatever_the_noise(kind):
    x = _noise(kind, 4, 0.9)
    spiked = x.copy()
    spiked[2500] += 30 * x.std()
    out = despiked(spiked, width=SPIKE_FILTER, sigmas=SPIKE_SIGMAS)
    assert abs(out[2500] - x[2500]) < 3 * x.std() and np.array_equal(np.delete(out, 2500), np.delete(x, 2500))


@pytest.mark.parametrize("pre", [100, 140, 200])
def test_a_pre_trigger_shorter_than_the_head_leaves_the_baseline_as_it_is(pre):
    """A pre-trigger shorter than the provisional head (2 % of 20 000 samples: 400) but long enough for a baseline:
    the offset within 4 of its standard errors of the true 3e-5, the arrival where a long pre-trigger puts it (the
    head's median once took the pulse's front in: the offset was off by a fraction of the pulse)."""
    rng = np.random.default_rng(11)
    n, foot = 20_000, 2000.0
    x = 3e-5 + ramp_pulse(n, foot, plateau=8000) + white_and_ar1_noise(n, sd=5e-6, rho=0.5, white_fraction=0.3,
                                                                        rng=rng)
    _, a_long = prepulse_noise(x)
    cut = int(foot) - pre
    e, a = prepulse_noise(x[cut:])
    assert a + cut == pytest.approx(a_long, abs=0.5)
    assert abs(e.offset - 3e-5) < 4 * e.offset_sd


def test_a_pre_trigger_too_short_asks_for_a_longer_one():
    n, foot = 20_000, 20.0
    x = ramp_pulse(n, foot, plateau=8000) + white_and_ar1_noise(n, sd=5e-6, rho=0.5, white_fraction=0.3,
                                                                rng=np.random.default_rng(2))
    with pytest.raises(ShortPreTrigger, match="record a longer pre-trigger"):
        prepulse_noise(x)


@pytest.mark.parametrize("pad", [20, 100, 400])
def test_an_unfilled_pre_trigger_is_not_the_baseline(pad):
    """The first samples exactly 0 (a zero-padded export, an unfilled buffer), then the baseline's noise about an
    offset: the arrival and the noise are those of the baseline after them (the step at their end was taken for the
    pulse, the noise for nothing, and the record refused as a gain off by 20 %)."""
    rng = np.random.default_rng(5)
    n, foot = 6000, 1200.0
    x = 2e-5 + ramp_pulse(n, foot) + white_and_ar1_noise(n, sd=3e-6, rho=0.5, white_fraction=0.3, rng=rng)
    padded = x.copy()
    padded[:pad] = 0.0
    e0 = noise_estimate(x, start=pad, stop=prepulse_noise(x)[0].stop)
    e, a = prepulse_noise(padded)
    assert padding(padded) == pad and e.start == pad
    assert a == pytest.approx(prepulse_noise(x)[1], abs=0.05)  # the second pass's offset is the shorter segment's
    assert e.stop == e0.stop and e.offset == pytest.approx(e0.offset, rel=1e-12) and e.sd == pytest.approx(e0.sd,
                                                                                                       rel=1e-12)


def test_a_noise_free_baseline_is_no_padding():
    """A synthetic record's baseline is exactly constant up to its front: not an unfilled pre-trigger."""
    x = ramp_pulse(6000, 1200.0, rise=2000)  # a slow front: its first 32 samples barely move, and never back
    assert padding(x) == 0 and padding(np.zeros(100)) == 0


def test_a_baseline_on_one_code_is_no_padding():
    """A baseline quantised more coarsely than its noise sits on one code for a while, then toggles: its first run
    is no unfilled pre-trigger (cut as one on up to a quarter of such records, and refused when the pre-trigger was
    short), since the noise comes back to that code."""
    from friction_uq.stats.robust import padding

    for seed in range(200):
        rng = np.random.default_rng(seed)
        x = np.round(rng.normal(0.0, 0.3, 2000) + 0.2)
        assert padding(x) == 0, seed


@pytest.mark.parametrize("pre", [100, 150])
def test_a_short_pre_trigger_before_a_quantised_plateau_is_found(pre):
    """A pre-trigger shorter than half the 2 % head, a plateau quantised more coarsely than its noise (sd 0.2 code)
    filling the rest of it: the head's median is the plateau's and its MAD 0, so a front was 'found' on the
    plateau's noise beyond the head and the segment took the pulse in (23 in 100 records at 100 samples). The head
    is used only when its median is its first samples'."""
    bad = 0
    for seed in range(100):
        rng = np.random.default_rng(seed)
        t = np.arange(20_000)
        x = np.round(0.3 + 100.0 * np.clip((t - pre) / 20, 0, 1) * (t < pre + 5000) + rng.normal(0.0, 0.2, t.size))
        e, a = prepulse_noise(x, polarity=1)
        bad += e.stop > pre or abs(a - pre) > 2
    assert bad == 0


def test_the_baseline_free_signal_has_no_padding_no_spike_and_no_offset():
    """One signal for every reader of a channel's waves (the forces, the measured loading, the whole-record check, the
    two-bar record): zero over an unfilled pre-trigger, a pre-pulse spike left out, the offset taken off, and the
    samples from the segment's start otherwise the record's less the offset, to the bit."""
    rng = np.random.default_rng(9)
    n, foot, pad = 6000, 1200.0, 100
    x = 2e-5 + ramp_pulse(n, foot) + white_and_ar1_noise(n, sd=3e-6, rho=0.5, white_fraction=0.3, rng=rng)
    x[:pad] = 0.0
    x[1000] += 5e-4  # a spike 200 samples before the front
    e, _ = prepulse_noise(x)
    y = baseline_free(x, e)
    assert np.all(y[:pad] == 0.0)
    assert abs(y[1000]) < 5 * e.sd
    keep = np.ones(n, bool)
    keep[:pad] = keep[1000] = False
    assert np.array_equal(y[keep], (x - e.offset)[keep])


@pytest.mark.parametrize("coarse", [10.0, 30.0, 100.0])
def test_a_spike_on_a_baseline_on_one_code_is_left_out(coarse):
    """A baseline read by a digitiser whose step is ``coarse`` times its noise sits on one code; a 2-sample spike of
    40 steps on it was the only departure from the running median, so it set the scale and was kept: the noise sd
    became 1.24 steps and the arrival moved by up to 6 samples (on A-03's internal bar read so, the record was refused:
    "no pulse rises above the noise"). Now the scale is at most a step: the spiked record reads as the clean one."""
    rng = np.random.default_rng(4)
    n, foot = 6000, 2100.0
    sd = 1e-7
    step = coarse * sd
    x = np.round((0.3 * step + 2e-4 * ramp_pulse(n, foot) / ramp_pulse(n, foot).max()
                  + rng.normal(0.0, sd, n)) / step) * step
    spiked = x.copy()
    spiked[50:52] += 40 * step
    (e0, a0), (e1, a1) = prepulse_noise(x), prepulse_noise(spiked)
    # the sd's floor, step / sqrt(12), from the record's codes (the spike's among them: the last bits may differ)
    assert e1.offset == e0.offset and e1.sd == pytest.approx(e0.sd, rel=1e-12) and a1 == pytest.approx(a0, abs=1e-9)


def test_flickers_of_one_code_are_noise_not_spikes():
    """A baseline on one code but for two flickers to the next code and a 2-sample spike of 13 codes: the spike's
    samples are half of those that leave their running median, so without the one-step cap on the scale they set it
    and stay; with a cap below a step's 1 / 11.9 the flickers would go too. The spike goes, the flickers stay."""
    x = np.zeros(4000)
    x[[700, 2900]] = 1.0  # flickers
    x[1500:1502] = 13.0  # the spike
    out = despiked(x, step=1.0)
    assert np.all(out[1500:1502] == 0.0)
    assert out[700] == 1.0 and out[2900] == 1.0
    assert np.array_equal(despiked(x), x)  # without the step, nothing tells the spike from the noise


@pytest.mark.parametrize(("bits", "codes"), [(8, 0.3), (12, 1.0), (14, 2.0), (16, 3.0)])
@pytest.mark.parametrize("offset", [0.0, 0.37])
def test_the_quantisation_step_is_the_lattice_s(bits, codes, offset):
    """A wave read at 8-16 bits with noise of 0.3-3 codes, stored in float32 after a scale and an offset: the step is
    the code's, within float32's rounding (the median gap between distinct values, 9-120 codes on such records, once
    set a noise floor 3-30 times the noise); continuous data sit on no lattice."""
    rng = np.random.default_rng(bits)
    t = np.arange(20000)
    wave = np.convolve(np.where((t > 5000) & (t < 12000), 0.8, 0.0), np.ones(200) / 200, mode="same")
    step = 2.0 / 2**bits
    x = np.round((wave + rng.normal(0.0, codes * step, t.size)) / step) * step
    stored = ((x + offset) * 1.234e-4).astype(np.float32).astype(float)
    assert quantisation_step(stored) == pytest.approx(step * 1.234e-4, rel=2e-4)
    assert quantisation_step(wave + rng.normal(0.0, 1e-3, t.size)) == 0.0
    e = noise_estimate(stored, stop=4000)  # the noise as it is, rounding and all: no floor on resolved noise
    unit = step * 1.234e-4
    assert 0.8 * codes * unit < e.sd < 1.25 * math.sqrt(codes ** 2 + 1.0 / 12.0) * unit
