"""Binary scope files that declare more samples than a record may hold are refused from their headers.

lecroyparser and RigolWFM decode every sample of a file before a caller sees how many there are, so
the count is read from the header first (LeCroy's WAVEDESC descriptor, a Tektronix ISF header and
curve block, a Tektronix WFM header) and the reader is never called for a file over the limit. The
files are small: only their headers claim a long record.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from friction_uq.acquisition import binary, declared
from friction_uq.acquisition.binary import describe_binary, read_binary
from friction_uq.cli import main
from friction_uq.errors import ScopeFileError
from friction_uq.plausible import MAX_SAMPLES

OVER = MAX_SAMPLES + 1
LIMIT = f"more than the {MAX_SAMPLES} a record may hold (docs/limits.md); export a shorter or decimated record"


def _no_parse(*args, **kwargs):
    raise AssertionError("the samples were decoded before the header's count was checked")


def _refused(path: Path, capsys) -> str:
    """The one line ``import FILE --show`` writes when it refuses the file (exit 2, no traceback)."""
    assert main(["import", str(path), "--show"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# ---- LeCroy .trc: the WAVEDESC descriptor ---------------------------------------------------------


def _trc(path: Path, raw: np.ndarray, *, count: int | None = None, nbytes: int | None = None, order: int = 1,
         comm_type: int = 1, prefix: bytes = b"", dt: float = 2e-7, t0: float = -1e-5, gain: float = 1e-3) -> Path:
    """A LeCroy trace (WAVEDESC template LECROY_2_3) of the samples ``raw``; ``count`` and ``nbytes`` overwrite
    the descriptor's WAVE_ARRAY_COUNT and WAVE_ARRAY_1, ``order`` is COMM_ORDER (1 little-endian)."""
    e = "<" if order else ">"
    raw = raw.astype(e + ("i2" if comm_type else "i1"))
    desc = bytearray(346)
    desc[0:8] = b"WAVEDESC"
    desc[16:26] = b"LECROY_2_3"
    struct.pack_into(e + "H", desc, 32, comm_type)
    struct.pack_into("<H", desc, 34, order)  # (0 reads the same in either byte order)
    struct.pack_into(e + "i", desc, 36, 346)
    struct.pack_into(e + "i", desc, 60, raw.nbytes if nbytes is None else nbytes)
    struct.pack_into(e + "i", desc, 116, raw.size if count is None else count)
    struct.pack_into(e + "f", desc, 156, gain)
    struct.pack_into(e + "H", desc, 172, 16)
    struct.pack_into(e + "f", desc, 176, dt)
    struct.pack_into(e + "d", desc, 180, t0)
    path.write_bytes(prefix + bytes(desc) + raw.tobytes())
    return path


@pytest.fixture
def lecroyparser(monkeypatch):
    """lecroyparser, made to fail if it is asked to read a file."""
    module = pytest.importorskip("lecroyparser")
    monkeypatch.setattr(module, "ScopeData", _no_parse)
    return module


def test_a_small_lecroy_trace_still_reads(tmp_path):
    pytest.importorskip("lecroyparser")
    raw = (1000 * np.sin(np.arange(500) / 20)).astype(int)
    (tr,) = read_binary(_trc(tmp_path / "C1shot.trc", raw, prefix=b"#9000000000"), [1]).values()
    assert np.allclose(tr.values, 1e-3 * raw, atol=1e-9) and tr.t0 == pytest.approx(-1e-5)
    assert tr.dt == pytest.approx(2e-7, rel=1e-6)


@pytest.mark.parametrize("order, comm_type, prefix", [(1, 1, b""), (0, 1, b""), (1, 0, b""), (1, 1, b"#9000000000")])
def test_lecroy_wave_array_count_over_the_limit_is_refused_before_parsing(tmp_path, capsys, lecroyparser, order,
                                                                           comm_type, prefix):
    path = _trc(tmp_path / "C1shot.trc", np.zeros(10), count=OVER, order=order, comm_type=comm_type, prefix=prefix)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, [1])
    assert str(e.value) == f"{path}: the descriptor's WAVE_ARRAY_COUNT declares {OVER} samples, {LIMIT}"
    assert f"C1shot.trc: the descriptor's WAVE_ARRAY_COUNT declares {OVER} samples" in _refused(path, capsys)


def test_lecroy_wave_array_1_over_the_limit_is_refused_before_parsing(tmp_path, lecroyparser):
    path = _trc(tmp_path / "C1shot.trc", np.zeros(10), nbytes=2 * OVER)  # WAVE_ARRAY_COUNT says 10
    with pytest.raises(ScopeFileError, match="WAVE_ARRAY_1") as e:
        read_binary(path, [1])
    assert str(e.value) == (f"{path}: the descriptor's WAVE_ARRAY_1 ({2 * OVER} bytes of 16-bit samples) declares "
                            f"{OVER} samples, {LIMIT}")


@pytest.mark.parametrize("edit, words", [
    ({"count": 0}, "the descriptor's WAVE_ARRAY_COUNT is 0: the trace holds no samples"),
    ({"count": -5}, "the descriptor's WAVE_ARRAY_COUNT is -5: the trace holds no samples"),
    ({"nbytes": -2}, "the descriptor's WAVE_ARRAY_1 is -2, a negative length"),
    ({"nbytes": 0}, "the descriptor's WAVE_ARRAY_1 is 0 bytes: the trace holds no samples"),
    ({"count": 1000}, "the file's 366 bytes cannot hold the 1000 samples of 16 bits (WAVE_ARRAY_1 20 bytes) the "
                      "descriptor declares from byte 346; the file is cut short"),
    ({"nbytes": 4000}, "the file's 366 bytes cannot hold the 10 samples of 16 bits (WAVE_ARRAY_1 4000 bytes)"),
    ({"order": 2}, "the descriptor's COMM_ORDER is 2, not 0 (big-endian) or 1 (little-endian)"),
    ({"comm_type": 3}, "the descriptor's COMM_TYPE is 3, not 0 (8-bit samples) or 1 (16-bit samples)"),
])
def test_a_lecroy_descriptor_that_cannot_be_read_is_named(tmp_path, lecroyparser, edit, words):
    path = _trc(tmp_path / "C1shot.trc", np.zeros(10), **edit)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, [1])
    assert str(e.value).startswith(f"{path}: {words}"), str(e.value)


def test_a_lecroy_file_without_or_with_a_cut_descriptor_is_named(tmp_path, lecroyparser):
    path = tmp_path / "C1shot.trc"
    path.write_bytes(b"\0" * 60 + b"WAVEDESC" + b"\0" * 400)
    with pytest.raises(ScopeFileError, match="no WAVEDESC descriptor in its first 50 bytes; not a LeCroy trace"):
        read_binary(path, [1])
    path.write_bytes(b"WAVEDESC" + b"\0" * 100)
    with pytest.raises(ScopeFileError, match=r"the WAVEDESC descriptor is cut short \(108 of 346 bytes\)"):
        read_binary(path, [1])


def test_a_lecroy_trace_of_exactly_the_limit_passes_the_descriptor_check(tmp_path):
    declared.lecroy_declared(_trc(tmp_path / "C1shot.trc", np.zeros(MAX_SAMPLES, dtype=np.int8), comm_type=0))


# ---- Tektronix .isf: NR_PT and the curve block ----------------------------------------------------


def _isf(path: Path, raw: np.ndarray, *, nr_pt: int | None = None, end: bytes = b"\n") -> Path:
    """A Tektronix ISF waveform (text header, 16-bit big-endian curve); ``nr_pt`` overwrites NR_PT."""
    nbytes = str(2 * raw.size)
    head = (f':WFMPRE:BYT_NR 2;BIT_NR 16;ENCDG BIN;BN_FMT RI;BYT_OR MSB;WFID "Ch1, DC coupling, 2.0E-2 V/div";'
            f'NR_PT {raw.size if nr_pt is None else nr_pt};PT_FMT Y;XUNIT "s";XINCR 2.0E-7;XZERO -1.0E-5;PT_OFF 0;'
            f'YUNIT "V";YMULT 1.0E-3;YOFF 0.0E+0;YZERO 0.0E+0;:CURVE #{len(nbytes)}{nbytes}')
    path.write_bytes(head.encode() + raw.astype(">i2").tobytes() + end)
    return path


@pytest.fixture
def rigolwfm(monkeypatch):
    """RigolWFM's reader, made to fail if it is asked to read a file."""
    pytest.importorskip("RigolWFM")
    import RigolWFM.wfm as wfm

    monkeypatch.setattr(wfm.Wfm, "from_file", _no_parse)
    return wfm


def test_a_small_isf_still_reads(tmp_path):
    pytest.importorskip("RigolWFM")
    raw = (1000 * np.sin(np.arange(500) / 20)).astype(int)
    tr = read_binary(_isf(tmp_path / "TEK0001.ISF", raw), [1])[1]
    assert np.allclose(tr.values, 1e-3 * raw, atol=1e-6) and tr.t0 == pytest.approx(-1e-5)


def test_isf_nr_pt_over_the_limit_is_refused_before_parsing(tmp_path, capsys, rigolwfm):
    path = _isf(tmp_path / "TEK0001.ISF", np.zeros(10), nr_pt=OVER)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, [1])
    assert str(e.value) == f"{path}: the header's NR_PT declares {OVER} samples, {LIMIT}"
    assert f"TEK0001.ISF: the header's NR_PT declares {OVER} samples" in _refused(path, capsys)


def test_an_isf_curve_block_over_the_limit_is_refused_whatever_nr_pt_says(tmp_path, rigolwfm):
    path = _isf(tmp_path / "TEK0001.ISF", np.zeros(OVER, dtype=np.int16), nr_pt=1000)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, ["CH1"])
    assert str(e.value) == (f"{path}: the curve block after the header ({2 * OVER} bytes of 16-bit samples) holds "
                            f"{OVER} samples, {LIMIT}")


def test_an_isf_of_exactly_the_limit_passes_the_header_check(tmp_path, rigolwfm):
    declared.rigolwfm_declared(_isf(tmp_path / "TEK0001.ISF", np.zeros(MAX_SAMPLES, dtype=np.int16), end=b"\r\n"))


# ---- Tektronix .wfm (WFM#002): the header's curve object and record length -----------------------


def _tek(path: Path, raw: np.ndarray, *, valid: int | None = None, length: int | None = None) -> Path:
    """A Tektronix WFM#002 little-endian waveform of the samples ``raw`` (int16, 1 mV a count, 200 ns apart,
    from -10 us); ``valid`` overwrites the curve's valid samples (its postcharge start), ``length`` the record
    length (implicit dimension 1 size)."""
    raw = raw.astype("<i2")
    h = bytearray(838)
    struct.pack_into("<H", h, 0, 0x0F0F)
    h[2:10] = b":WFM#002"
    struct.pack_into("<Bi", h, 15, 2, 838)  # bytes a point, where the curve buffer starts
    struct.pack_into("<iI", h, 78, 0, 1)  # a single waveform, one update
    struct.pack_into("<i", h, 122, 2)  # a vector of samples
    struct.pack_into("<I", h, 142, 1)  # one curve
    struct.pack_into("<dd", h, 168, 1e-3, 0.0)  # exp_dim1: volts a count, offset
    struct.pack_into("<ddI", h, 480, 2e-7, -1e-5, raw.size if length is None else length)  # imp_dim1
    n = raw.size if valid is None else valid
    struct.pack_into("<IIII", h, 806, 0, 2 * n, 2 * n, 2 * raw.size)  # data start, postcharge start/stop, end
    path.write_bytes(bytes(h) + raw.tobytes())
    return path


def test_the_tek_test_file_says_what_it_means_to(tmp_path):
    pytest.importorskip("RigolWFM")
    from kaitaistruct import KaitaiStream
    from RigolWFM.tektronix_wfm_002_le_wfm import TektronixWfm002LeWfm

    with open(_tek(tmp_path / "t.wfm", np.zeros(7), valid=5, length=9), "rb") as f:
        w = TektronixWfm002LeWfm(KaitaiStream(f))
        h = w.wfm_header
        assert (w.static_file_info.num_bytes_per_point, w.static_file_info.byte_offset_to_curve_buffer) == (2, 838)
        assert (h.curve.num_valid_samples, h.imp_dim1.dim_size, h.imp_dim1.dim_scale, h.exp_dim1.dim_scale) == (
            5, 9, 2e-7, 1e-3)
        assert (h.set_type, h.curve_ref_count, h.data_type, h.exp_dim1.format) == (0, 1, 2, 0)


def test_a_small_tektronix_wfm_still_reads(tmp_path):
    pytest.importorskip("RigolWFM")
    raw = (1000 * np.sin(np.arange(500) / 20)).astype(int)
    tr = read_binary(_tek(tmp_path / "tek0001.wfm", raw), [1])[1]
    assert np.allclose(tr.values, 1e-3 * raw, atol=1e-6) and tr.t0 == pytest.approx(-1e-5)
    assert tr.dt == pytest.approx(2e-7, rel=1e-9)


def test_tek_valid_samples_over_the_limit_are_refused_before_parsing(tmp_path, capsys, rigolwfm):
    path = _tek(tmp_path / "tek0001.wfm", np.zeros(10), valid=OVER)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, [1])
    assert str(e.value) == (f"{path}: the header's curve object (data start offset 0, postcharge start offset "
                            f"{2 * OVER}, 2 bytes a point) declares {OVER} samples, {LIMIT}")
    assert "tek0001.wfm: the header's curve object (data start offset 0" in _refused(path, capsys)


def test_tek_record_length_over_the_limit_is_refused_when_the_curve_is_empty(tmp_path, rigolwfm):
    path = _tek(tmp_path / "tek0001.wfm", np.zeros(10), valid=0, length=OVER)
    with pytest.raises(ScopeFileError) as e:
        describe_binary(path)
    assert str(e.value) == (f"{path}: the header's record length (implicit dimension 1 size) declares {OVER} "
                            f"samples, {LIMIT}")


def test_a_tek_record_length_beyond_valid_samples_is_not_refused(tmp_path, rigolwfm):
    declared.rigolwfm_declared(_tek(tmp_path / "tek0001.wfm", np.zeros(10), length=OVER))  # RigolWFM reads 10


# ---- the other RigolWFM formats: checked as soon as RigolWFM has parsed them ---------------------


def test_a_channel_over_the_limit_is_refused_right_after_parsing(tmp_path, monkeypatch):
    pytest.importorskip("RigolWFM")
    path = _isf(tmp_path / "TEK0001.ISF", np.zeros(500))  # within the limit its header is checked against
    monkeypatch.setattr(binary, "MAX_SAMPLES", 100)
    with pytest.raises(ScopeFileError) as e:
        read_binary(path, ["CH1"])
    assert str(e.value) == (f"{path}: channel 1 (CH 1), as RigolWFM decoded it, holds 500 samples, more "
                            "than the 100 a record may hold (docs/limits.md); export a shorter or decimated record")
