"""Oscilloscope exports as delimited text (CSV, TSV, semicolon or whitespace separated).

Scopes differ in everything but the table of numbers: Keysight, Tektronix, Rigol, PicoScope and
LabVIEW write a different number of metadata lines before the header row, some a units row after
it, some a trailing delimiter; in some locales the delimiter is ``;`` and the decimal mark ``,``.
So nothing is assumed: the delimiter and decimal mark are found from the file's last lines (which
are data), the first data row is the first of several consecutive all-numeric rows of that shape,
and the header row is the nearest line above the data that names the columns asked for. The body
is then parsed in one pass by :func:`numpy.loadtxt`; a cell it cannot read is found again line by
line, so the refusal names the line and the column.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ScopeFileError
from ..plausible import MAX_SAMPLES
from .file_units import suffix_unit, units_row
from .text_layout import (
    DIALECT_NAMES,
    HEAD_LINES,
    data_start,
    find_dialect,
    fields,
    is_number,
    tail_lines,
)

#: Largest text export read (bytes): 1 M samples x 8 columns of 16-character numbers is 140 MB.
MAX_TEXT_BYTES = 2_000_000_000


@dataclass(frozen=True)
class TextTable:
    """The columns asked for, with where they were found (for messages and provenance)."""

    path: Path
    columns: dict[str | int, np.ndarray]
    labels: dict[str | int, str]
    first_data_line: int
    header_line: int | None
    delimiter: str | None
    decimal: str
    #: the unit the file writes beside each column asked for (None: it says none this package knows), and where:
    #: "its units row (line N)" or "its name"
    units: dict[str | int, str | None] = field(default_factory=dict)
    units_from: dict[str | int, str] = field(default_factory=dict)

    @property
    def dialect(self) -> str:
        return f"{DIALECT_NAMES[self.delimiter]}-separated, decimal mark {self.decimal!r}"


def _header(path: Path, head: list[str], start: int, delim: str | None,
            wanted: list[str]) -> tuple[int | None, list[str]]:
    """(index, fields) of the nearest line above the data naming every wanted column (case-insensitively)."""
    for i in range(start - 1, max(-1, start - 60), -1):
        f = fields(head[i], delim)
        low = [c.lower() for c in f]
        if f and all(w in f or w.lower() in low for w in wanted):
            return i, f
    if wanted:  # name the first missing column against the line that names most of them
        lines = [(sum(w.lower() in [c.lower() for c in fields(head[i], delim)] for w in wanted), i)
                 for i in range(start - 1, max(-1, start - 60), -1) if head[i].strip()]
        if not lines:
            raise ScopeFileError(f"{path}: no header line above the data (line {start + 1}); name the columns by "
                                 "number (column = 2)")
        _, best = max(lines, key=lambda x: x[0])
        f = fields(head[best], delim)
        miss = next(w for w in wanted if w.lower() not in [c.lower() for c in f])
        raise ScopeFileError(f"{path}: column {miss!r} not found; the header line {best + 1} has: {', '.join(f)}")
    for i in range(start - 1, max(-1, start - 60), -1):  # for messages only: the nearest non-numeric line
        if head[i].strip():
            return i, fields(head[i], delim)
    return None, []


def _units_row_above(head: list[str], start: int, delim: str | None, ncols: int,
                     names: list[str]) -> tuple[int | None, list[str | None]]:
    """(index, each column's unit) of a units row right above the data (:func:`.file_units.units_row`; lines of
    delimiters alone are passed over), else (None, []). A line that names every column asked for is the header,
    whatever its words."""
    for i in range(start - 1, max(-1, start - 4), -1):
        cells = fields(head[i], delim)
        if not any(c.strip().strip('"') for c in cells):
            continue
        low = [c.strip().strip('"').lower() for c in cells]
        row = units_row(cells, ncols)
        if row is None or (names and all(w.lower() in low for w in names)):
            return None, []
        return i, row
    return None, []


def _units(urow: list[str | None], uline: int | None, header: list[str], named: bool, ncols: int,
           idx: list[int], dec: str) -> list[tuple[str | None, str]]:
    """Each asked column's (unit, where it was read): from the units row, else the bracketed end of its name in the
    header (``Time (s)``) when the header names the columns: columns asked by name, or one name per column and no
    number among them (not a metadata line such as ``Sample Rate (Hz),1000000``)."""
    names = named or (len(header) == ncols and not any(is_number(c.strip().strip('"'), dec) for c in header))
    out = []
    for i in idx:
        if i < len(urow) and urow[i] is not None:
            out.append((urow[i], f"its units row (line {uline + 1})"))
        else:
            out.append((suffix_unit(header[i]) if names and i < len(header) else None, "its name"))
    return out


def _index(path: Path, key: str | int, header: list[str], header_line: int | None, ncols: int) -> int:
    if isinstance(key, int):
        if key > ncols:
            raise ScopeFileError(f"{path}: column {key} asked for, the data rows have {ncols} columns")
        return key - 1
    low = [c.lower() for c in header]
    same = [j for j, c in enumerate(header) if c == key] or [j for j, c in enumerate(low) if c == key.lower()]
    if len(same) > 1:  # two columns of one name: which is the gauge's cannot be guessed
        raise ScopeFileError(f"{path}: column {key!r} is the name of columns {', '.join(str(j + 1) for j in same)} "
                             f"on the header line {header_line}; give the column by its number instead")
    i = same[0]
    if i >= ncols:
        raise ScopeFileError(f"{path}: column {key!r} (number {i + 1} on the header line {header_line}) has no "
                             f"numbers: the data rows have {ncols} columns")
    return i


def _locate_bad_cell(path: Path, lines: list[str], start: int, delim: str | None, dec: str,
                     idx: list[int], labels: list[str], ncols: int) -> ScopeFileError | None:
    for n, line in enumerate(lines[start:], start=start + 1):
        if not line.strip():
            continue
        f = fields(line, delim)
        if len(f) <= max(idx):
            return ScopeFileError(f"{path}: line {n} has {len(f)} fields where the data rows have {ncols} "
                                  "(a truncated or damaged row)")
        for i, label in zip(idx, labels):
            if not is_number(f[i], dec):
                return ScopeFileError(f"{path}: line {n}, column {label}: {f[i]!r} is not a number")
    return None


def _text(path: Path) -> str:
    try:
        size = path.stat().st_size
        if size > MAX_TEXT_BYTES:
            raise ScopeFileError(f"{path}: {size / 1e9:.1f} GB, larger than the {MAX_TEXT_BYTES / 1e9:.0f} GB a text "
                                 "export is read up to; export fewer samples or a binary format")
        raw = path.read_bytes()
    except OSError as exc:
        raise ScopeFileError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if raw.startswith(b"\x89HDF\r\n\x1a\n"):
        raise ScopeFileError(f"{path}: is an HDF5 file (a test record already?), not an oscilloscope export; "
                             "friction-uq inspect reads records")
    if b"\x00" in raw[:65536]:
        raise ScopeFileError(f"{path}: is a binary file, not a text export; give a TDMS file the extension .tdms, a "
                             "LeCroy trace .trc, a Tektronix or Rigol waveform .wfm/.isf/.bin")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")  # scope software in Windows code pages (a 'µs' in a units row)


def _rows_over(body: str, limit: int) -> bool:
    """More than ``limit`` lines that are not blank in ``body`` (counted without a list of them)."""
    for n, _ in enumerate(re.finditer(r"(?m)^[^\S\n]*\S", body), start=1):
        if n > limit:
            return True
    return False


def _row_of_another_length(body: str, delim: str | None, ncols: int) -> tuple[int, int] | None:
    """(index among ``body``'s lines, fields) of the first line that is not blank and has other than ``ncols``
    fields, else None: with a field too many or too few, numbers would land in the wrong columns (a row's
    columns are taken by their place). Read a megabyte at a time, the delimiters counted in C."""
    want, trail = ncols - 1, f' \t\r"{delim or ""}'
    drop = None if delim is None else bytes(range(256)).translate(None, (delim + "\n").encode())
    pos = first = 0
    while pos < len(body):
        end = body.find("\n", pos + (1 << 20))
        end = len(body) if end < 0 else end + 1
        lines = body[pos:end].split("\n")
        if delim is None:
            odd = [k for k, line in enumerate(lines) if len(line.split()) != ncols]
        else:  # each line's delimiters; a trailing delimiter (an empty last field) is looked at again
            sig = body[pos:end].encode().translate(None, drop).split(b"\n")
            odd = [k for k, d in enumerate(sig) if len(d) != want and lines[k].rstrip(trail).count(delim) != want]
        for k in odd:
            n = len(fields(lines[k], delim))
            if n != ncols and lines[k].strip():
                return first + k, n
        first += len(lines) - 1
        pos = end
    return None


def read_delimited(path: str | Path, wanted: list[str | int]) -> TextTable:
    """The columns ``wanted`` (header names or 1-based numbers) of a delimited text export, as float64.

    Raises
    ------
    ScopeFileError
        Naming the file and the line or column: no data, a missing column, a cell that is not a
        number, a row with fields too few or too many.
    """
    p = Path(path)
    text = _text(p)
    if "\n" not in text[: 1 << 16] and "\r" in text[: 1 << 16]:
        text = text.replace("\r", "\n")  # old Macintosh line ends
    head = text[: 1 << 18].split("\n")[:HEAD_LINES]
    tail = tail_lines(text, head)
    if not tail:
        raise ScopeFileError(f"{p}: is empty")
    delim, dec, ncols = find_dialect(p, tail, text)
    start = data_start(p, head, delim, dec, ncols)
    names = [w for w in wanted if isinstance(w, str)]
    uline, urow = _units_row_above(head, start, delim, ncols, names)
    hline, header = _header(p, head, start if uline is None else uline, delim, names)
    idx = [_index(p, w, header, None if hline is None else hline + 1, ncols) for w in wanted]
    labels = [repr(header[i]) if i < len(header) else f"{i + 1}" for i in idx]
    labels = [f"{lab} (number {i + 1})" for lab, i in zip(labels, idx)]
    # the body from the first data row, as one string (offset found without splitting the whole file)
    offset = 0
    for _ in range(start):
        offset = text.index("\n", offset) + 1
    body = text[offset:]
    if body.count("\n") + 1 > MAX_SAMPLES and _rows_over(body, MAX_SAMPLES):  # before parsing
        raise ScopeFileError(f"{p}: more than {MAX_SAMPLES} data rows from line {start + 1}, more samples than a "
                             "record may hold (docs/limits.md); export a shorter or decimated record")
    odd = _row_of_another_length(body, delim, ncols)
    if odd is not None:
        why = "a truncated or damaged row" if odd[1] < ncols else "a damaged row: its numbers would shift columns"
        raise ScopeFileError(f"{p}: line {start + 1 + odd[0]} has {odd[1]} fields where the data rows have {ncols} "
                             f"({why})")
    if dec == ",":
        body = body.replace(",", ".")
    uniq = sorted(set(idx))
    try:
        data = np.loadtxt(io.StringIO(body), delimiter=delim, usecols=uniq, dtype=np.float64, ndmin=2,
                          quotechar='"', comments=None)
    except ValueError as exc:
        err = _locate_bad_cell(p, text.split("\n"), start, delim, dec, idx, labels, ncols)
        raise (err or ScopeFileError(f"{p}: cannot be read as a table from line {start + 1}: {exc}")) from None
    cols = {w: np.ascontiguousarray(data[:, uniq.index(i)]) for w, i in zip(wanted, idx)}
    units = _units(urow, uline, header, bool(names), ncols, idx, dec)
    return TextTable(p, cols, dict(zip(wanted, labels)), start + 1, None if hline is None else hline + 1, delim, dec,
                     {w: u for w, (u, _) in zip(wanted, units)}, {w: at for w, (_, at) in zip(wanted, units)})


def describe_text(path: str | Path) -> list[str]:
    """What a text export holds, for writing SETUP.toml: its layout, the header's columns, a first row."""
    p = Path(path)
    text = _text(p)
    if "\n" not in text[: 1 << 16] and "\r" in text[: 1 << 16]:
        text = text.replace("\r", "\n")
    head = text[: 1 << 18].split("\n")[:HEAD_LINES]
    tail = tail_lines(text, head)
    if not tail:
        raise ScopeFileError(f"{p}: is empty")
    delim, dec, ncols = find_dialect(p, tail, text)
    start = data_start(p, head, delim, dec, ncols)
    above = [i for i in range(start - 1, max(-1, start - 60), -1) if head[i].strip()][:3]
    named = [i for i in above if len(f := fields(head[i], delim)) >= ncols and len(set(f)) == len(f)]
    hline = named[0] if named else None
    header = fields(head[hline], delim) if hline is not None else []
    table = read_delimited(p, list(range(1, ncols + 1)))
    n = len(table.columns[1])
    first = [table.columns[i][0] for i in range(1, ncols + 1)]
    out = [f"{p}: {table.dialect}; {start} line(s) before the data, data from line {start + 1}, {n} rows"]
    out += [f"  line {i + 1}: {', '.join(fields(head[i], delim))}" for i in reversed(above)]
    out.append(f"  column names from line {hline + 1}" if hline is not None
               else "  no header line: name columns by number")
    for i in range(ncols):
        name = header[i] if i < len(header) else ""
        col = table.columns[i + 1]
        step = np.diff(col[: min(n, 1000)])
        timelike = n > 2 and np.all(step > 0) and np.ptp(step) < 0.01 * step.mean()
        even = " (evenly increasing: a time column?)" if timelike else ""
        out.append(f"  column {i + 1:>2}  {name!r:<16} first {first[i]:<14.6g} min {col.min():<12.4g} "
                   f"max {col.max():<12.4g}{even}")
    return out
