"""The record contract (docs/record-format.md) at the reading boundary: issue 2, item 3.

Every malformed variant is generated here from a fresh copy of the good record (h5py edits of
attributes, datasets and groups; byte-level truncation or overwriting), never checked in. Each must
be refused by :func:`read_record` with one sentence ``"<file>: <path inside>: <problem>"``; a subset
also goes through the ``friction-uq`` command (exit status 2, one line on stderr, no traceback).
The second half checks what the contract allows: optional parts, units, sign, storage variants.
"""

from __future__ import annotations

import io
import re
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest

from friction_uq.errors import RecordError
from friction_uq.record import Plug, Record, paper_apparatus, read_record, read_truth, write_record
from friction_uq.synthetic import ClosedFormTest, closed_form_strains

Mutation = Callable[[Path], Path]
"""Edits the copy of the good record at the given path; returns the path to read."""

CHANNELS = ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop")


# ----------------------------------------------------------------------------------------------
# Mutations
# ----------------------------------------------------------------------------------------------


def h5edit(edit: Callable[[h5py.File], None]) -> Mutation:
    def mutate(path: Path) -> Path:
        with h5py.File(path, "r+") as fh:
            edit(fh)
        return path

    return mutate


def set_attr(obj: str, name: str, value: Any) -> Mutation:
    def edit(fh: h5py.File) -> None:
        fh[obj].attrs[name] = value

    return h5edit(edit)


def del_attr(obj: str, name: str) -> Mutation:
    def edit(fh: h5py.File) -> None:
        del fh[obj].attrs[name]

    return h5edit(edit)


def delete(obj: str) -> Mutation:
    def edit(fh: h5py.File) -> None:
        del fh[obj]

    return h5edit(edit)


def replace_by(obj: str, make: Callable[[h5py.Group, str], Any]) -> Mutation:
    """Delete ``obj`` and let ``make(parent, name)`` put something else in its place."""

    def edit(fh: h5py.File) -> None:
        parent, _, name = obj.rpartition("/")
        del fh[obj]
        make(fh[parent or "/"], name)

    return h5edit(edit)


def _rewrite(fh: h5py.File, name: str, data: Any) -> None:
    """Replace /signals/<name> by ``data``, keeping its attributes."""
    attrs = dict(fh["signals"][name].attrs)
    del fh["signals"][name]
    ds = fh["signals"].create_dataset(name, data=data)
    for k, v in attrs.items():
        ds.attrs[k] = v


def channel(name: str, transform: Callable[[np.ndarray], Any]) -> Mutation:
    def edit(fh: h5py.File) -> None:
        _rewrite(fh, name, transform(fh["signals"][name][()]))

    return h5edit(edit)


def all_channels(transform: Callable[[np.ndarray], Any]) -> Mutation:
    def edit(fh: h5py.File) -> None:
        for name in list(fh["signals"]):
            _rewrite(fh, name, transform(fh["signals"][name][()]))

    return h5edit(edit)


def set_at(index: int, value: float) -> Callable[[np.ndarray], np.ndarray]:
    def transform(x: np.ndarray) -> np.ndarray:
        x = x.copy()
        x[index] = value
        return x

    return transform


def saturate_low(fraction: float) -> Callable[[np.ndarray], np.ndarray]:
    """A digitiser whose range ends at ``fraction`` of the channel's most negative value."""
    return lambda x: np.maximum(x, fraction * x.min())


def saturate_high(fraction: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda x: np.minimum(x, fraction * x.max())


def attrs_of(obj: str, **attrs: Any) -> Mutation:
    def edit(fh: h5py.File) -> None:
        for k, v in attrs.items():
            fh[obj].attrs[k] = v

    return h5edit(edit)


def add_group(obj: str, **attrs: Any) -> Mutation:
    def edit(fh: h5py.File) -> None:
        g = fh.create_group(obj)
        for k, v in attrs.items():
            g.attrs[k] = v

    return h5edit(edit)


def write_bytes(data: bytes) -> Mutation:
    def mutate(path: Path) -> Path:
        path.write_bytes(data)
        return path

    return mutate


def _npy_bytes() -> bytes:
    buf = io.BytesIO()
    np.save(buf, np.zeros(8))
    return buf.getvalue()


def truncate(keep: Callable[[int], int]) -> Mutation:
    def mutate(path: Path) -> Path:
        size = path.stat().st_size
        with open(path, "r+b") as fh:
            fh.truncate(keep(size))
        return path

    return mutate


def scramble_after_signature(path: Path) -> Path:
    data = path.read_bytes()
    path.write_bytes(data[:8] + bytes(len(data) - 8))
    return path


def damaged_chunk(name: str) -> Mutation:
    """/signals/<name> stored gzip-compressed in chunks, one chunk's bytes then overwritten (a disk or a copy
    that damaged the file's middle): HDF5 opens the file and fails on that dataset's read."""

    def mutate(path: Path) -> Path:
        with h5py.File(path, "r+") as fh:
            data, attrs = fh["signals"][name][()], dict(fh["signals"][name].attrs)
            del fh["signals"][name]
            ds = fh["signals"].create_dataset(name, data=data, compression="gzip", chunks=(max(1, data.size // 4),))
            for k, v in attrs.items():
                ds.attrs[k] = v
            offset = ds.id.get_chunk_info(1).byte_offset
        raw = bytearray(path.read_bytes())
        raw[offset + 10:offset + 60] = bytes(b ^ 0xFF for b in raw[offset + 10:offset + 60])
        path.write_bytes(bytes(raw))
        return path

    return mutate


def empty_hdf5(path: Path) -> Path:
    with h5py.File(path, "w"):
        pass
    return path


def absent(path: Path) -> Path:
    return path.with_name("absent.h5")


def a_directory(path: Path) -> Path:
    d = path.with_name("a_directory.h5")
    d.mkdir()
    return d


# ----------------------------------------------------------------------------------------------
# The table of malformed variants
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Case:
    id: str
    mutate: Mutation
    where: str
    problem: str
    """Regular expression searched in the problem part of the message."""
    cli: bool = False
    """Also run through ``friction-uq inspect``."""


S, A = "/signals", "/apparatus"
IB, IOB, EOB, HOOP = (f"{S}/{c}" for c in CHANNELS)

CASES = [
    # ---- the file itself ----
    Case("not-hdf5-text", write_bytes(b"time,input_bar\n0.0,1e-6\n"), "/", "is not an HDF5 file", cli=True),
    Case("not-hdf5-empty", write_bytes(b""), "/", "is not an HDF5 file"),
    Case("not-hdf5-npy", write_bytes(_npy_bytes()), "/", "is not an HDF5 file"),
    Case("truncated-half", truncate(lambda n: n // 2), "/", "damaged or truncated HDF5 file", cli=True),
    Case("truncated-last-byte", truncate(lambda n: n - 1), "/", "damaged or truncated HDF5 file"),
    Case("truncated-1k", truncate(lambda n: 1024), "/", "damaged or truncated HDF5 file"),
    Case("truncated-signature-only", truncate(lambda n: 8), "/", "damaged or truncated HDF5 file"),
    Case("zeros-after-signature", scramble_after_signature, "/", "damaged or truncated HDF5 file"),
    # a damaged chunk in a dataset: that dataset named, not the file's root
    Case("damaged-chunk", damaged_chunk("internal_output_bar"), "/signals/internal_output_bar",
         "cannot be read: its stored data are damaged", cli=True),
    Case("missing-file", absent, "/", "file not found", cli=True),
    Case("directory", a_directory, "/", "is a directory", cli=True),
    Case("hdf5-but-not-a-record", empty_hdf5, "/", "required attribute 'format' is missing"),
    # ---- root attributes ----
    Case("format-wrong", set_attr("/", "format", "friction-uq/tset"), "/@format",
         r"is 'friction-uq/tset', expected 'friction-uq/test'", cli=True),
    Case("format-missing", del_attr("/", "format"), "/", "required attribute 'format' is missing"),
    Case("format-number", set_attr("/", "format", 1), "/@format", "must be a string"),
    Case("format-version-newer", set_attr("/", "format_version", 2), "/@format_version",
         "is 2, newer than the 1 this friction-uq reads; upgrade"),
    Case("format-version-zero", set_attr("/", "format_version", 0), "/@format_version", "is 0, expected 1"),
    Case("format-version-string", set_attr("/", "format_version", "1"), "/@format_version",
         "must be an integer, got '1'"),
    Case("format-version-fraction", set_attr("/", "format_version", 1.5), "/@format_version",
         "must be an integer, got 1.5"),
    Case("format-version-missing", del_attr("/", "format_version"), "/",
         "required attribute 'format_version' is missing"),
    Case("test-id-missing", del_attr("/", "test_id"), "/", "required attribute 'test_id' is missing"),
    Case("test-id-blank", set_attr("/", "test_id", "  "), "/@test_id", "is empty"),
    Case("test-id-number", set_attr("/", "test_id", 7), "/@test_id", "must be a string, got int 7"),
    Case("campaign-missing", del_attr("/", "campaign"), "/", "required attribute 'campaign' is missing"),
    Case("campaign-empty", set_attr("/", "campaign", ""), "/@campaign", "is empty"),
    Case("striker-velocity-negative", set_attr("/", "striker_velocity", -10.0), "/@striker_velocity",
         r"must be > 0 m/s, got -10\.0"),
    Case("striker-velocity-zero", set_attr("/", "striker_velocity", 0.0), "/@striker_velocity", "must be > 0"),
    Case("striker-velocity-text", set_attr("/", "striker_velocity", "10 m/s"), "/@striker_velocity",
         "must be a number, got '10 m/s'"),
    Case("date-not-iso-8601", set_attr("/", "date", "21/11/2016"), "/@date", "not an ISO 8601 date"),
    # ---- groups ----
    Case("signals-missing", delete(S), S, "required group is missing", cli=True),
    Case("apparatus-missing", delete(A), A, "required group is missing"),
    Case("signals-is-a-dataset", replace_by(S, lambda g, n: g.create_dataset(n, data=np.ones(3))), S,
         "must be a group"),
    Case("tube-missing", delete(f"{A}/tube"), f"{A}/tube", "required group is missing"),
    Case("sample-missing", delete(f"{A}/sample"), f"{A}/sample", "required group is missing"),
    Case("sample-is-a-dataset", replace_by(f"{A}/sample", lambda g, n: g.create_dataset(n, data=[0.01])),
         f"{A}/sample", "must be a group"),
    Case("provenance-is-a-dataset", h5edit(lambda fh: (fh.__delitem__("provenance") if "provenance" in fh else None,
                                                      fh.create_dataset("provenance", data=[1.0]))), "/provenance",
         "must be a group"),
    Case("plug-is-a-dataset", h5edit(lambda fh: fh[A].create_dataset("plug", data=[0.01])), f"{A}/plug",
         "must be a group"),
    # ---- /signals attributes ----
    Case("sample-rate-missing", del_attr(S, "sample_rate"), S, "required attribute 'sample_rate' is missing"),
    Case("sample-rate-zero", set_attr(S, "sample_rate", 0.0), f"{S}@sample_rate", r"must be > 0 Hz, got 0\.0",
         cli=True),
    Case("sample-rate-negative", set_attr(S, "sample_rate", -5e6), f"{S}@sample_rate", "must be > 0 Hz"),
    Case("sample-rate-nan", set_attr(S, "sample_rate", np.nan), f"{S}@sample_rate", "must be finite, got nan"),
    Case("sample-rate-text", set_attr(S, "sample_rate", "5 MHz"), f"{S}@sample_rate",
         "must be a number, got '5 MHz'"),
    Case("sample-rate-array", set_attr(S, "sample_rate", np.array([5e6, 5e6])), f"{S}@sample_rate",
         r"must be a scalar, got an array of shape \(2,\)"),
    Case("t0-inf", set_attr(S, "t0", np.inf), f"{S}@t0", "must be finite, got inf"),
    # ---- channels: presence and shape ----
    Case("input-bar-missing", delete(IB), IB, "required channel is missing", cli=True),
    Case("internal-output-bar-missing", delete(IOB), IOB, "required channel is missing"),
    Case("external-output-bar-missing", delete(EOB), EOB, "required channel is missing"),
    Case("channel-is-a-group", replace_by(IOB, lambda g, n: g.create_group(n)), IOB, "must be a dataset"),
    Case("channel-dangling-soft-link", replace_by(IB, lambda g, n: g.__setitem__(n, h5py.SoftLink("/nowhere"))),
         IB, "is a broken link"),
    Case("channel-external-link-to-missing-file",
         replace_by(EOB, lambda g, n: g.__setitem__(n, h5py.ExternalLink("scope_raw.h5", "/ch3"))),
         EOB, "is an external link"),
    Case("channel-2d", channel(IB, lambda x: x.reshape(-1, 2)), IB, r"must be 1-D, got shape \(3250, 2\)"),
    Case("channel-column", channel(EOB, lambda x: x[:, None]), EOB, r"must be 1-D, got shape \(6500, 1\)"),
    Case("channel-scalar", channel(HOOP, lambda x: x[0]), HOOP, r"must be 1-D, got shape \(\)"),
    Case("channel-int16-adc-counts", channel(IB, lambda x: np.round(x * 1e6).astype(np.int16)), IB,
         "must be float32 or float64, got int16", cli=True),
    Case("channel-text", channel(IOB, lambda x: np.array([b"%.6e" % v for v in x])), IOB,
         "must be float32 or float64, got"),
    Case("channel-float16", channel(EOB, lambda x: x.astype(np.float16)), EOB,
         "must be float32 or float64, got float16"),
    Case("channel-complex", channel(IB, lambda x: x.astype(np.complex128)), IB,
         "must be float32 or float64, got complex128"),
    Case("unequal-length", channel(IOB, lambda x: x[:-1]), IOB,
         "has 6499 samples but /signals/input_bar has 6500; channels must have equal length", cli=True),
    Case("unequal-length-hoop", channel(HOOP, lambda x: np.concatenate([x, x[:10]])), HOOP,
         "has 6510 samples but /signals/input_bar has 6500"),
    Case("too-few-samples", all_channels(lambda x: x[:32]), IB, "has 32 samples, at least 64 are needed"),
    Case("no-samples", all_channels(lambda x: x[:0]), IB, "has 0 samples, at least 64 are needed", cli=True),
    # ---- channels: samples ----
    Case("nan-sample", channel(EOB, set_at(1234, np.nan)), EOB,
         r"has 1 non-finite samples \(NaN first at index 1234\)", cli=True),
    Case("inf-sample", channel(HOOP, set_at(4000, np.inf)), HOOP, r"\(inf first at index 4000\)"),
    Case("minus-inf-sample", channel(IB, set_at(0, -np.inf)), IB, r"\(inf first at index 0\)"),
    Case("clipped-compression", channel(IB, saturate_low(0.8)), IB,
         r"is clipped: \d+ consecutive samples sit at the minimum value", cli=True),
    Case("clipped-tension", channel(IB, saturate_high(0.8)), IB,
         r"is clipped: \d+ consecutive samples sit at the maximum value"),
    Case("clipped-hoop", channel(HOOP, saturate_high(0.5)), HOOP,
         r"is clipped: .*\(amplifier or digitiser saturated\)"),
    Case("flat-channel", channel(IOB, lambda x: np.full_like(x, 1e-5)), IOB,
         r"is flat \(every sample equals 1e-05\): the gauge recorded no signal"),
    Case("dead-hoop-gauge", channel(HOOP, np.zeros_like), HOOP, "is flat"),
    # ---- channels: units ----
    Case("units-missing", del_attr(IB, "units"), IB, "required attribute 'units' is missing"),
    Case("units-unknown", set_attr(IOB, "units", "mV"), f"{IOB}@units",
         "is 'mV', allowed: strain, microstrain, V", cli=True),
    Case("units-wrong-case", set_attr(IB, "units", "Strain"), f"{IB}@units", "is 'Strain', allowed"),
    Case("units-number", set_attr(IB, "units", 1.0), f"{IB}@units", "must be a string"),
    Case("volts-without-strain-per-volt", set_attr(EOB, "units", "V"), EOB,
         "units are 'V' but attribute 'strain_per_volt' is missing", cli=True),
    Case("strain-per-volt-zero", attrs_of(EOB, units="V", strain_per_volt=0.0), f"{EOB}@strain_per_volt",
         "must not be zero"),
    Case("strain-per-volt-text", attrs_of(EOB, units="V", strain_per_volt="2e-4 /V"), f"{EOB}@strain_per_volt",
         "must be a number"),
    Case("strain-per-volt-nan", attrs_of(EOB, units="V", strain_per_volt=np.nan), f"{EOB}@strain_per_volt",
         "must be finite"),
    # ---- record length against the apparatus ----
    Case("too-short-for-reflected-wave", all_channels(lambda x: x[:3000]), S,
         r"lasts 600 us, too short to hold the reflected wave.*= 997 us", cli=True),
    Case("too-short-at-higher-sample-rate", set_attr(S, "sample_rate", 1e7), S, "too short to hold the reflected wave"),
    Case("too-short-for-far-gauge", set_attr(f"{A}/input_bar", "gauge_distance", 2.4), S,
         "too short to hold the reflected wave"),
    # ---- apparatus: values ----
    Case("striker-length-zero", set_attr(f"{A}/striker", "length", 0.0), f"{A}/striker@length",
         r"must be > 0, got 0\.0"),
    Case("input-bar-diameter-negative", set_attr(f"{A}/input_bar", "diameter", -0.02), f"{A}/input_bar@diameter",
         "must be > 0, got -0.02"),
    Case("internal-output-bar-modulus-missing", del_attr(f"{A}/internal_output_bar", "young_modulus"),
         f"{A}/internal_output_bar", "required attribute 'young_modulus' is missing"),
    Case("external-output-bar-outer-diameter-missing", del_attr(f"{A}/external_output_bar", "outer_diameter"),
         f"{A}/external_output_bar", "required attribute 'outer_diameter' is missing"),
    Case("wave-speed-nan", set_attr(f"{A}/striker", "wave_speed", np.nan), f"{A}/striker@wave_speed",
         "must be finite"),
    Case("sample-density-text", set_attr(f"{A}/sample", "density", "1850 kg/m3"), f"{A}/sample@density",
         "must be a number"),
    Case("tube-gauge-width-zero", set_attr(f"{A}/tube", "gauge_width", 0.0), f"{A}/tube@gauge_width",
         "must be > 0"),
    Case("tube-gauge-offset-missing", del_attr(f"{A}/tube", "gauge_offset"), f"{A}/tube",
         "required attribute 'gauge_offset' is missing"),
    Case("sample-material-missing", del_attr(f"{A}/sample", "material"), f"{A}/sample",
         "required attribute 'material' is missing"),
    Case("sample-material-number", set_attr(f"{A}/sample", "material", 1.0), f"{A}/sample@material",
         "must be a string"),
    # ---- apparatus: geometry and consistency ----
    Case("external-bar-inner-above-outer", set_attr(f"{A}/external_output_bar", "inner_diameter", 0.05),
         f"{A}/external_output_bar@inner_diameter", "not smaller than outer_diameter 0.04 m", cli=True),
    Case("external-bar-inner-equals-outer", set_attr(f"{A}/external_output_bar", "inner_diameter", 0.04),
         f"{A}/external_output_bar@inner_diameter", "not smaller than outer_diameter"),
    Case("tube-inner-above-outer", set_attr(f"{A}/tube", "inner_diameter", 0.03), f"{A}/tube@inner_diameter",
         "is 0.03 m, not smaller than outer_diameter 0.024 m"),
    Case("input-gauge-beyond-bar", set_attr(f"{A}/input_bar", "gauge_distance", 2.6),
         f"{A}/input_bar@gauge_distance", "is 2.6 m, beyond the bar's length 2.5 m", cli=True),
    Case("internal-gauge-beyond-bar", set_attr(f"{A}/internal_output_bar", "gauge_distance", 1.5),
         f"{A}/internal_output_bar@gauge_distance", "beyond the bar's length 1.46 m"),
    Case("external-gauge-at-far-end", set_attr(f"{A}/external_output_bar", "gauge_distance", 1.5),
         f"{A}/external_output_bar@gauge_distance", "beyond the bar's length"),
    Case("gauge-distance-zero", set_attr(f"{A}/input_bar", "gauge_distance", 0.0), f"{A}/input_bar@gauge_distance",
         "must be > 0"),
    Case("tube-poisson-half", set_attr(f"{A}/tube", "poisson_ratio", 0.5), f"{A}/tube@poisson_ratio",
         r"must lie in \(-1, 0\.5\), got 0\.5"),
    Case("tube-poisson-above-half", set_attr(f"{A}/tube", "poisson_ratio", 0.7), f"{A}/tube@poisson_ratio",
         "must lie in"),
    Case("bar-poisson-above-half", set_attr(f"{A}/input_bar", "poisson_ratio", 0.5), f"{A}/input_bar@poisson_ratio",
         r"must lie in \(-1, 0\.5\)"),
    Case("sample-wider-than-bore", set_attr(f"{A}/sample", "diameter", 0.012), f"{A}/sample@diameter",
         "is 0.012 m, larger than the tube's inner_diameter 0.01 m", cli=True),
    Case("sample-longer-than-tube", set_attr(f"{A}/sample", "length", 0.05), f"{A}/sample@length",
         "not shorter than the tube's length 0.04 m"),
    Case("internal-bar-wider-than-bore", set_attr(f"{A}/internal_output_bar", "diameter", 0.011),
         f"{A}/internal_output_bar@diameter", "too large to slide in the tube"),
    Case("bars-not-coaxial", set_attr(f"{A}/external_output_bar", "inner_diameter", 0.009),
         f"{A}/external_output_bar@inner_diameter", "not larger than the internal output bar's diameter"),
    Case("hoop-gauge-off-the-tube", set_attr(f"{A}/tube", "gauge_offset", -0.03), f"{A}/tube@gauge_offset",
         "outside the tube"),
    Case("plug-length-negative", add_group(f"{A}/plug", length=-0.01, young_modulus=200e9, density=7800.0),
         f"{A}/plug@length", "must be > 0"),
    Case("plug-incomplete", add_group(f"{A}/plug", length=0.01), f"{A}/plug",
         "required attribute 'young_modulus' is missing"),
]


def test_table_is_large_and_ids_are_unique() -> None:
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids))
    assert len(CASES) >= 35
    cli_ids = {c.id for c in CASES if c.cli}
    assert len(cli_ids) >= 8 and {"not-hdf5-text", "truncated-half"} <= cli_ids


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id) for c in CASES])
def test_malformed_record_is_refused(case: Case, record_copy: Callable[..., Path]) -> None:
    path = case.mutate(record_copy())
    prefix = f"{path}: {case.where}: "
    with pytest.raises(RecordError, match=rf"^{re.escape(prefix)}.*(?:{case.problem})") as info:
        read_record(path)
    err = info.value
    assert (err.file, err.where) == (str(path), case.where)
    assert re.search(case.problem, err.problem), err.problem
    message = str(err)
    assert message == prefix + err.problem
    assert path.name in message and case.where in message
    assert "\n" not in message


CLI_CASES = [pytest.param(c, id=c.id) for c in CASES if c.cli]


@pytest.mark.parametrize("case", CLI_CASES)
def test_cli_refuses_with_one_line_and_status_2(
    case: Case, record_copy: Callable[..., Path], capfd: pytest.CaptureFixture[str]
) -> None:
    from friction_uq.cli import main

    path = case.mutate(record_copy())
    status = main(["inspect", str(path)])
    out, err = capfd.readouterr()  # file-descriptor level: HDF5's own diagnostics would show here
    assert status == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("friction-uq: error: ")
    assert f"{path}: {case.where}: " in lines[0]
    assert "Traceback" not in err


def _console_command() -> list[str] | None:
    script = Path(sys.executable).with_name("friction-uq")
    if script.exists():
        return [str(script)]
    found = shutil.which("friction-uq")
    return [found] if found else None


def test_installed_console_script_refuses_without_traceback(tmp_path: Path) -> None:
    command = _console_command()
    if command is None:
        pytest.skip("the friction-uq console script is not installed")
    bad = tmp_path / "BAD.h5"
    bad.write_text("this is a lab notebook, not a record\n")
    proc = subprocess.run([*command, "inspect", str(bad)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"friction-uq: error: {bad}: /: is not an HDF5 file")
    assert "Traceback" not in proc.stderr


# ----------------------------------------------------------------------------------------------
# What the contract allows
# ----------------------------------------------------------------------------------------------


def _same_strains(a: Record, b: Record, *, rtol: float = 0.0, atol: float = 0.0) -> None:
    assert set(a.channels) == set(b.channels)
    for name in a.channels:
        np.testing.assert_allclose(a.strain(name), b.strain(name), rtol=rtol, atol=atol, err_msg=name)


def test_good_record_reads(good_record: Path) -> None:
    rec = read_record(good_record)
    assert (rec.test_id, rec.campaign) == ("A-01", "A")
    assert set(rec.channels) == set(CHANNELS) and rec.has_hoop
    assert rec.n_samples == 6500 and rec.sample_rate == 5e6
    for ch in rec.channels.values():
        assert not ch.strain.flags.writeable


def test_record_without_hoop_channel_reads(good_record: Path, record_copy: Callable[..., Path]) -> None:
    rec = read_record(delete(HOOP)(record_copy()))
    assert not rec.has_hoop
    assert set(rec.channels) == set(CHANNELS[:3])
    good = read_record(good_record)
    for name in CHANNELS[:3]:
        np.testing.assert_array_equal(rec.strain(name), good.strain(name))


def test_units_convert_by_the_contracts_factors(good_record: Path, record_copy: Callable[..., Path]) -> None:
    """Rewrite the good record's channels by hand in microstrain and volts: same strain out."""
    spv = 2.5e-4

    def edit(fh: h5py.File) -> None:
        _rewrite(fh, "input_bar", fh[IB][()] * 1e6)
        fh[IB].attrs["units"] = "microstrain"
        _rewrite(fh, "external_output_bar", fh[EOB][()] / spv)
        fh[EOB].attrs["units"] = "V"
        fh[EOB].attrs["strain_per_volt"] = spv
        _rewrite(fh, "tube_hoop", fh[HOOP][()] * 1e6)
        fh[HOOP].attrs["units"] = "microstrain"

    rec = read_record(h5edit(edit)(record_copy()))
    assert rec.channels["external_output_bar"].strain_per_volt == spv
    _same_strains(rec, read_record(good_record), rtol=1e-12, atol=1e-20)


@pytest.mark.parametrize(("units", "strain_per_volt"), [("strain", None), ("microstrain", None), ("V", 2.0e-4)])
def test_written_units_round_trip(units: str, strain_per_volt: float | None, tmp_path: Path) -> None:
    app = paper_apparatus()
    t, strains, _ = closed_form_strains(ClosedFormTest(), app)
    rng = np.random.default_rng(11)
    strains = {k: v + rng.normal(0.0, 3e-6, v.size) for k, v in strains.items()}
    path = write_record(
        tmp_path / f"{units}.h5", test_id="U-01", campaign="U", sample_rate=5e6, t0=float(t[0]), strains=strains,
        apparatus=app, units={k: units for k in strains},
        strain_per_volt={k: strain_per_volt for k in strains} if strain_per_volt else None,
    )
    rec = read_record(path)
    with h5py.File(path, "r") as fh:
        assert {fh[f"{S}/{k}"].attrs["units"] for k in strains} == {units}
    for k, eps in strains.items():
        np.testing.assert_allclose(rec.strain(k), eps, rtol=1e-12, atol=1e-20, err_msg=k)


def test_sign_is_flipped_once_compression_reads_positive(tmp_path: Path) -> None:
    """Contract: positive = elongation in the file. Package: compression positive after read_record."""
    app, test = paper_apparatus(), ClosedFormTest()
    t, strains, _ = closed_form_strains(test, app)
    rng = np.random.default_rng(3)
    strains = {k: v + rng.normal(0.0, 2e-6, v.size) for k, v in strains.items()}
    path = write_record(tmp_path / "sign.h5", test_id="G-01", campaign="G", sample_rate=5e6, t0=float(t[0]),
                        strains=strains, apparatus=app)
    # eq. 14: incident strain V_s / (2 c) on the input bar, compressive; at the gauge from t = 0 on
    eps_incident = test.striker_velocity / (2.0 * app.input_bar.wave_speed)
    plateau = (t > test.rise_time) & (t < app.pulse_duration - test.rise_time)
    with h5py.File(path, "r") as fh:
        raw = {k: fh[f"{S}/{k}"][()] for k in CHANNELS}
    assert np.median(raw["input_bar"][plateau]) == pytest.approx(-eps_incident, rel=0.01)
    assert raw["tube_hoop"].max() > 50 * 2e-6  # the tube swells: the hoop gauge elongates
    rec = read_record(path)
    assert np.median(rec.strain("input_bar")[plateau]) == pytest.approx(eps_incident, rel=0.01)
    assert rec.strain("tube_hoop").min() < -50 * 2e-6
    for k in CHANNELS:  # one flip, not two, not none
        np.testing.assert_array_equal(rec.strain(k), -raw[k])


def test_good_record_stores_compression_negative(good_record: Path) -> None:
    test = ClosedFormTest()
    rec = read_record(good_record)
    plateau = (rec.time > test.rise_time) & (rec.time < rec.apparatus.pulse_duration - test.rise_time)
    with h5py.File(good_record, "r") as fh:
        raw = fh[IB][()]
    assert np.median(raw[plateau]) < -5e-4
    assert np.median(rec.strain("input_bar")[plateau]) > 5e-4


def test_removing_truth_changes_nothing(good_record: Path, record_copy: Callable[..., Path]) -> None:
    path = delete("/truth")(record_copy())
    assert read_truth(good_record) and read_truth(path) == {}
    a, b = read_record(good_record), read_record(path)
    for f in fields(Record):
        if f.name in ("path", "sha256", "channels"):
            continue
        assert getattr(a, f.name) == getattr(b, f.name), f.name
    _same_strains(a, b)


@pytest.mark.parametrize(
    ("dtype", "chunked", "rtol"),
    [(np.float32, False, 1e-6), (">f8", False, 0.0), (">f4", False, 1e-6), (np.float64, True, 0.0)],
    ids=["float32", "float64-big-endian", "float32-big-endian", "float64-gzip-chunked"],
)
def test_storage_variants_read_to_the_same_strain(
    dtype: Any, chunked: bool, rtol: float, good_record: Path, record_copy: Callable[..., Path]
) -> None:
    def edit(fh: h5py.File) -> None:
        for name in CHANNELS:
            data, attrs = fh[f"{S}/{name}"][()], dict(fh[f"{S}/{name}"].attrs)
            del fh[f"{S}/{name}"]
            kw = {"chunks": (1024,), "compression": "gzip"} if chunked else {}
            ds = fh[S].create_dataset(name, data=data.astype(dtype), **kw)
            ds.attrs.update(attrs)

    rec = read_record(h5edit(edit)(record_copy()))
    for ch in rec.channels.values():
        assert ch.strain.dtype == np.float64
    _same_strains(rec, read_record(good_record), rtol=rtol, atol=1e-12 if rtol else 0.0)


def test_optional_attributes_may_be_absent(record_copy: Callable[..., Path]) -> None:
    def edit(fh: h5py.File) -> None:
        for name in ("description", "striker_velocity"):
            del fh.attrs[name]
        del fh[S].attrs["t0"]
        del fh["/provenance"]

    rec = read_record(h5edit(edit)(record_copy()))
    assert rec.t0 == 0.0 and rec.time[0] == 0.0
    assert rec.description is None and rec.striker_velocity is None and rec.date is None
    assert dict(rec.provenance) == {}


@pytest.mark.parametrize("date", ["2016-03-01", "2016-03-01T10:42:00", "2016-03-01T10:42:00+01:00"])
def test_iso_8601_dates_read(date: str, record_copy: Callable[..., Path]) -> None:
    assert read_record(set_attr("/", "date", date)(record_copy())).date == date


def test_fixed_length_byte_strings_read(record_copy: Callable[..., Path]) -> None:
    """Writers in C or MATLAB store fixed-length ASCII strings, not h5py's variable-length UTF-8."""

    def edit(fh: h5py.File) -> None:
        for name in ("format", "test_id", "campaign"):
            fh.attrs[name] = np.bytes_(fh.attrs[name].encode())
        for name in CHANNELS:
            fh[f"{S}/{name}"].attrs["units"] = np.bytes_(b"strain")
        fh[f"{A}/sample"].attrs["material"] = np.bytes_(b"I1")

    rec = read_record(h5edit(edit)(record_copy()))
    assert (rec.test_id, rec.campaign, rec.apparatus.sample.material) == ("A-01", "A", "I1")


def test_plug_is_optional_and_read_when_present(record_copy: Callable[..., Path]) -> None:
    rec = read_record(add_group(f"{A}/plug", length=0.01, young_modulus=200e9, density=7800.0)(record_copy()))
    assert rec.apparatus.plug == Plug(length=0.01, young_modulus=200e9, density=7800.0)


def test_unknown_additions_are_ignored(good_record: Path, record_copy: Callable[..., Path]) -> None:
    """The project may add optional fields: a reader ignores what it does not know."""

    def edit(fh: h5py.File) -> None:
        fh.attrs["operator"] = "J. Doe"
        notes = fh.create_group("notes")
        notes.attrs["text"] = "second shot of the day"
        notes.create_dataset("thermocouple", data=np.linspace(20.0, 21.0, 10)).attrs["units"] = "degC"
        fh[f"{A}/striker"].attrs["serial"] = "ST-3"
        prov = fh["provenance"]
        prov.attrs["gains"] = np.array([1.0, 2.0, 0.5])
        prov.attrs["scope"] = np.bytes_(b"LeCroy \xb5s")  # not UTF-8
        prov.attrs["channels"] = np.array([b"ch1", b"ch2"])

    rec = read_record(h5edit(edit)(record_copy()))
    _same_strains(rec, read_record(good_record))
    assert rec.provenance["gains"] == [1.0, 2.0, 0.5]
    assert rec.provenance["channels"] == ["ch1", "ch2"]
    assert rec.provenance["scope"].startswith("LeCroy ")


def test_a_channel_in_too_many_chunks_is_refused_before_it_is_read(record_copy, monkeypatch) -> None:
    """A chunk a sample made a million-sample record take 4 GB to read; the chunk count is checked from the
    dataset's layout first (here against a limit lowered to 100, so that a short record shows it)."""
    from friction_uq.record import _checks

    monkeypatch.setattr(_checks, "MAX_CHUNKS", 100)
    path = record_copy()
    with h5py.File(path, "r+") as fh:
        attrs, data = dict(fh["signals/tube_hoop"].attrs), fh["signals/tube_hoop"][()]
        del fh["signals/tube_hoop"]
        ds = fh["signals"].create_dataset("tube_hoop", data=data, chunks=(10,))
        ds.attrs.update(attrs)
    n = -(-data.size // 10)
    with pytest.raises(RecordError, match=rf"^{re.escape(str(path))}: /signals/tube_hoop: is stored in {n} chunks "
                                          r"of 10 samples, more than the 100 a channel may have"):
        read_record(path)
    monkeypatch.setattr(_checks, "MAX_CHUNKS", n)
    read_record(path)


def test_a_channel_through_a_filter_not_installed_is_named(record_copy) -> None:
    """HDF5 reports a dataset whose filter is missing as a damaged file; the reader names the channel and the
    filter before reading it."""
    path = record_copy()
    with h5py.File(path, "r+") as fh:
        attrs, data = dict(fh["signals/tube_hoop"].attrs), fh["signals/tube_hoop"][()]
        del fh["signals/tube_hoop"]
        ds = fh["signals"].create_dataset("tube_hoop", shape=data.shape, dtype=data.dtype, chunks=data.shape,
                                          compression=32001, allow_unknown_filter=True)
        ds.id.write_direct_chunk((0,), data.tobytes())
        ds.attrs.update(attrs)
    with pytest.raises(RecordError, match=rf"^{re.escape(str(path))}: /signals/tube_hoop: is compressed with HDF5 "
                                          r"filter 32001 .* which this installation cannot read"):
        read_record(path)


def test_a_provenance_attribute_hdf5_cannot_read_is_named(record_copy) -> None:
    """A null-dataspace attribute: HDF5 cannot size it, and the error named the file's root as damaged."""
    path = record_copy()
    with h5py.File(path, "r+") as fh:
        fh.require_group("provenance").attrs["x"] = h5py.Empty("f8")
    with pytest.raises(RecordError, match=rf"^{re.escape(str(path))}: /provenance@x: cannot be read"):
        read_record(path)


def test_a_dead_hoop_bridge_is_refused_with_the_way_round_it(record_copy: Callable[..., Path]) -> None:
    """A hoop channel reading one constant (a dead bridge): refused, saying --no-hoop analyses without it; read with
    hoop=False (what --no-hoop does), the record has no hoop gauge and its other channels are as they were."""
    path = channel(HOOP, lambda x: np.full_like(x, 1.5))(record_copy())
    with pytest.raises(RecordError, match=r"/signals/tube_hoop: is flat .*without it with --no-hoop"):
        read_record(path)
    rec = read_record(path, hoop=False)
    assert not rec.has_hoop
    assert np.array_equal(rec.strain("input_bar"), read_record(record_copy("good.h5")).strain("input_bar"))


def test_a_missing_required_channel_is_not_excused_by_no_hoop(record_copy: Callable[..., Path]) -> None:
    path = h5edit(lambda fh: fh["signals"][IB].attrs.__setitem__("units", "furlongs"))(record_copy())
    with pytest.raises(RecordError, match=r"/signals/input_bar@units: is 'furlongs'") as info:
        read_record(path, hoop=False)
    assert "--no-hoop" not in str(info.value)


def test_no_hoop_sets_up_a_run_on_a_dead_hoop_bridge(record_copy: Callable[..., Path], tmp_path: Path) -> None:
    from friction_uq.record_run.steps import set_up

    path = channel(HOOP, lambda x: np.full_like(x, 1.5))(record_copy())
    s = set_up(path, None, tmp_path / "out", window=None, dispersion=False, hoop=False)
    assert not s.use_hoop and s.prepared.data.hoop is None
