"""The number of samples a binary scope file declares, read from its header before any sample is decoded.

lecroyparser and RigolWFM read a whole file and decode every sample before a caller can ask how
many there are. The record holds at most :data:`~friction_uq.plausible.MAX_SAMPLES` samples a
channel (docs/limits.md), so the count is read here from the header alone and a file that declares
more is refused before the reader is called:

* LeCroy ``.trc``: the WAVEDESC descriptor (template LECROY_2_3, at the offsets lecroyparser
  reads): WAVE_ARRAY_COUNT, and WAVE_ARRAY_1, the bytes of samples the parser decodes.
* Tektronix ``.isf``: the header's NR_PT, and the curve block after the header, all of which
  RigolWFM decodes whatever NR_PT says.
* Tektronix ``.wfm`` (WFM#001 to WFM#003): the header's curve object (data start and postcharge
  start offsets) or, when that is empty, implicit dimension 1's size, the record length; the header
  is parsed by RigolWFM's own format description, its curve buffer left unread.

Other formats RigolWFM reads are checked once it has parsed them (:mod:`.binary`).
"""

from __future__ import annotations

import importlib
import io
import os
import struct
from pathlib import Path

from ..errors import ScopeFileError
from ..plausible import MAX_SAMPLES

#: Bytes of the WAVEDESC descriptor lecroyparser reads (its last field, WAVE_SOURCE, ends at byte 346).
WAVEDESC_BYTES = 346
#: lecroyparser looks for the "WAVEDESC" marker in a file's first 50 bytes (after a "#9nnnnnnnnn" block header).
WAVEDESC_WITHIN = 50
#: The descriptor's lengths (int32, in the file's byte order) at their offsets from the marker.
_WAVEDESC_LENGTHS = {"WAVE_DESCRIPTOR": 36, "USER_TEXT": 40, "TRIGTIME_ARRAY": 48, "WAVE_ARRAY_1": 60,
                     "WAVE_ARRAY_COUNT": 116}
#: Bytes read for a Tektronix header: an ISF text header or a WFM header (838 bytes) fits well within.
_HEAD_BYTES = 64 * 2**10
#: Tektronix WFM versions RigolWFM reads, and the format description each is parsed with.
_TEK_VERSIONS = {"WFM#001": "001", "WFM#002": "002", "WFM#003": "002"}


def over_limit(path: Path, what: str, n: int, verb: str = "declares", limit: int | None = None) -> ScopeFileError:
    """One sentence refusing ``n`` samples, more than a record may hold, naming where the count was read."""
    return ScopeFileError(f"{path}: {what} {verb} {n} samples, more than the {limit or MAX_SAMPLES} a record may "
                          "hold (docs/limits.md); export a shorter or decimated record")


def _ends(path: Path, n: int, last: int = 0) -> tuple[bytes, bytes, int]:
    """The first ``n`` bytes of the file, its ``last`` bytes, and its size in bytes."""
    try:
        with path.open("rb") as f:
            head, size = f.read(n), os.fstat(f.fileno()).st_size
            f.seek(max(0, size - last))
            return head, f.read(last) if last else b"", size
    except OSError as exc:
        raise ScopeFileError(f"{path}: cannot be read ({exc.strerror or exc})") from None


def _wavedesc(path: Path) -> tuple[int, int, dict[str, int], int]:
    """(where the descriptor starts, bytes a sample, its lengths by name, the file's size), each checked."""
    head, _, size = _ends(path, WAVEDESC_WITHIN + WAVEDESC_BYTES)
    pos = head[:WAVEDESC_WITHIN].find(b"WAVEDESC")
    if pos < 0:
        raise ScopeFileError(f"{path}: no WAVEDESC descriptor in its first {WAVEDESC_WITHIN} bytes; not a LeCroy "
                             "trace")
    desc = head[pos:pos + WAVEDESC_BYTES]
    if len(desc) < WAVEDESC_BYTES:
        raise ScopeFileError(f"{path}: the WAVEDESC descriptor is cut short ({len(desc)} of {WAVEDESC_BYTES} bytes)")
    order = int.from_bytes(desc[34:36], "little")  # COMM_ORDER, read as lecroyparser reads it
    if order not in (0, 1):
        raise ScopeFileError(f"{path}: the descriptor's COMM_ORDER is {order}, not 0 (big-endian) or 1 "
                             "(little-endian)")
    endian = "<" if order else ">"
    (comm_type,) = struct.unpack_from(endian + "H", desc, 32)
    if comm_type not in (0, 1):
        raise ScopeFileError(f"{path}: the descriptor's COMM_TYPE is {comm_type}, not 0 (8-bit samples) or 1 "
                             "(16-bit samples)")
    lengths = {k: struct.unpack_from(endian + "i", desc, at)[0] for k, at in _WAVEDESC_LENGTHS.items()}
    return pos, 1 + comm_type, lengths, size


def lecroy_declared(path: Path) -> None:
    """Refuse a LeCroy trace whose descriptor declares no samples, too many, or more than the file holds.

    Only the first few hundred bytes are read; lecroyparser is called afterwards.
    """
    pos, width, n, size = _wavedesc(path)
    count, nbytes = n["WAVE_ARRAY_COUNT"], n["WAVE_ARRAY_1"]
    if count <= 0:
        raise ScopeFileError(f"{path}: the descriptor's WAVE_ARRAY_COUNT is {count}: the trace holds no samples")
    if count > MAX_SAMPLES:
        raise over_limit(path, "the descriptor's WAVE_ARRAY_COUNT", count)
    for name, value in n.items():
        if value < 0:
            raise ScopeFileError(f"{path}: the descriptor's {name} is {value}, a negative length")
    if nbytes // width > MAX_SAMPLES:
        raise over_limit(path, f"the descriptor's WAVE_ARRAY_1 ({nbytes} bytes of {8 * width}-bit samples)",
                         nbytes // width)
    if nbytes < width:
        raise ScopeFileError(f"{path}: the descriptor's WAVE_ARRAY_1 is {nbytes} bytes: the trace holds no samples")
    start = pos + n["WAVE_DESCRIPTOR"] + n["USER_TEXT"] + n["TRIGTIME_ARRAY"]  # where lecroyparser reads them
    if start + max(nbytes, count * width) > size:
        raise ScopeFileError(f"{path}: the file's {size} bytes cannot hold the {count} samples of {8 * width} bits "
                             f"(WAVE_ARRAY_1 {nbytes} bytes) the descriptor declares from byte {start}; the file "
                             "is cut short")


def _int(text: str | None, default: int) -> int:
    """A header's number as RigolWFM reads it (``"1.0E+6"`` is 1000000), ``default`` when it is not one."""
    try:
        return int(float(text)) if text is not None else default
    except (ValueError, OverflowError):
        return default


def _isf_declared(path: Path) -> None:
    """Refuse a Tektronix ISF file whose NR_PT or curve block holds more samples than a record may."""
    import RigolWFM.isf as isf  # type: ignore[import-not-found]

    head, tail, size = _ends(path, _HEAD_BYTES, 16)
    end = head.find(b"#")  # the header ends at the curve block: '#', a digit n, n digits, the samples
    digits = head[end + 1] - 48 if 0 <= end < len(head) - 1 else -1
    if not 0 <= digits <= 9:
        return  # RigolWFM says what is wrong with the file
    parse = getattr(isf, "_parse_header", None)  # RigolWFM's own reading of the header's fields
    fields = parse(head[:end].decode("ascii", "replace")) if parse is not None else {}
    nr_pt = _int(fields.get("nr_pt"), 0)
    if nr_pt > MAX_SAMPLES:
        raise over_limit(path, "the header's NR_PT", nr_pt)
    width = 1 if _int(fields.get("byt_nr"), 2) == 1 else 2
    ends = len(tail) - len(tail.rstrip(b"\r\n"))  # line ends after the samples, which RigolWFM drops
    nbytes = size - (end + 2 + digits) - ends
    if nbytes // width > MAX_SAMPLES:
        raise over_limit(path, f"the curve block after the header ({nbytes} bytes of {8 * width}-bit samples)",
                         nbytes // width, "holds")


def _tek_header(head: bytes) -> object | None:
    """A Tektronix WFM header parsed by RigolWFM's description of its version, None when it does not parse."""
    from kaitaistruct import KaitaiStream  # type: ignore[import-not-found]

    order = {b"\x0f\x0f": "le", b"\xf0\xf0": "be"}.get(head[:2])
    version = _TEK_VERSIONS.get(head[3:10].split(b"\0")[0].decode("ascii", "ignore").strip())
    if order is None or version is None:
        return None
    try:  # RigolWFM's generated description of this version (a RigolWFM without it: the check after parsing)
        module = importlib.import_module(f"RigolWFM.tektronix_wfm_{version}_{order}_wfm")
        return getattr(module, f"TektronixWfm{version}{order.title()}Wfm")(KaitaiStream(io.BytesIO(head)))
    except Exception:  # a header cut short or damaged, or a RigolWFM laid out otherwise
        return None


def _tek_declared(path: Path) -> None:
    """Refuse a Tektronix WFM file whose header declares more samples than a record may hold."""
    head, _, _ = _ends(path, _HEAD_BYTES)
    raw = None if b"LLWFM" in head[:8] else _tek_header(head)
    if raw is None:
        return  # the older LLWFM layout, or a header RigolWFM will say is damaged
    try:
        curve = raw.wfm_header.curve  # type: ignore[attr-defined]
        valid = int(curve.num_valid_samples)
        length = int(raw.wfm_header.imp_dim1.dim_size)  # type: ignore[attr-defined]
    except Exception:  # no bytes a point: RigolWFM says so
        return
    if valid > MAX_SAMPLES:
        bpp = raw.static_file_info.num_bytes_per_point  # type: ignore[attr-defined]
        raise over_limit(path, f"the header's curve object (data start offset {curve.data_start_offset}, postcharge "
                               f"start offset {curve.postcharge_start_offset}, {bpp} bytes a point)", valid)
    if valid <= 0 and length > MAX_SAMPLES:  # RigolWFM then reads the record length
        raise over_limit(path, "the header's record length (implicit dimension 1 size)", length)


def rigolwfm_declared(path: Path) -> None:
    """Check the counts a file's header declares, for the formats whose header is read here (see above).

    The format is told by RigolWFM's own detection (a file's first 8 kB); a file it cannot place is
    left to RigolWFM to refuse.
    """
    import RigolWFM.wfm as wfm  # type: ignore[import-not-found]

    try:
        model = str(wfm.detect_model(str(path))).upper()
    except Exception:
        return
    check = {"ISF": _isf_declared, "TEK": _tek_declared}.get(model)
    if check is not None:
        check(path)
