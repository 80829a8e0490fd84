"""The layout of a delimited oscilloscope export, found from its lines rather than assumed.

The delimiter and decimal mark come from the file's last lines (which are data), the first data row
is the first of several consecutive all-numeric rows of that shape; a line that breaks the layout
the others share is named by its number. :mod:`.delimited` reads the table with them.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ScopeFileError

#: (delimiter, decimal mark) candidates in order of preference; None splits on whitespace.
DIALECTS = (("\t", "."), ("\t", ","), (";", "."), (";", ","), (",", "."), (None, "."), (None, ","))
DIALECT_NAMES = {"\t": "tab", ";": "semicolon", ",": "comma", None: "whitespace"}
HEAD_LINES = 400
TAIL_LINES = 20
CONFIRM_ROWS = 3


def fields(line: str, delim: str | None) -> list[str]:
    parts = line.split(delim) if delim is not None else line.split()
    parts = [p.strip().strip('"').strip() for p in parts]
    while parts and parts[-1] == "":
        parts.pop()
    return parts


def is_number(cell: str, decimal: str) -> bool:
    if decimal == ",":
        cell = cell.replace(",", ".")
    try:
        float(cell)
    except ValueError:
        return False
    return True


def numeric_row(line: str, delim: str | None, decimal: str) -> int:
    """Number of fields if every field of ``line`` is a number, else 0."""
    f = fields(line, delim)
    return len(f) if f and all(is_number(c, decimal) for c in f) else 0


def tail_lines(text: str, head: list[str]) -> list[tuple[int, str]]:
    """The last :data:`TAIL_LINES` lines that are not blank, each with its offset in ``text`` (a short file's
    from its head): the lines the layout is read from."""
    chunk = text[-(1 << 15):]
    base, out, at = len(text) - len(chunk), [], 0
    for k, line in enumerate(chunk.split("\n")):
        if k and line.strip():  # the chunk's first line may be cut
            out.append((base + at, line))
        at += len(line) + 1
    if not out:  # a short file: its tail is its head
        at = 0
        for line in head:
            if line.strip():
                out.append((at, line))
            at += len(line) + 1
    return out[-TAIL_LINES:]


def find_dialect(path: Path, tail: list[tuple[int, str]], text: str) -> tuple[str | None, str, int]:
    """(delimiter, decimal mark, fields per row) under which every line of ``tail`` (offset, line) is a row of
    numbers; else one sentence naming the line that breaks the layout the others share, or saying there is none."""
    lines = [ln for _, ln in tail]
    best: tuple[str | None, str, int] | None = None
    for delim, dec in DIALECTS:
        counts = {numeric_row(line, delim, dec) for line in lines}
        if len(counts) == 1 and (n := counts.pop()) > 0 and (best is None or n > best[2]):
            best = (delim, dec, n)
    if best is None:
        odd = odd_line(tail, text)
        if odd is not None and "a footer" in odd[0]:
            raise ScopeFileError(f"{path}: {odd[0]} (the rows before it are {odd[1]} numbers each)")
        if odd is not None:
            raise ScopeFileError(f"{path}: {odd[0]}, where the rows around it are {odd[1]} numbers each (a truncated "
                                 "or damaged row near the end of the export)")
        raise ScopeFileError(f"{path}: its last lines are not rows of numbers in any of the usual layouts (comma, "
                             "semicolon, tab or space separated; decimal point or comma): is it an oscilloscope "
                             "export?")
    return best


def odd_line(tail: list[tuple[int, str]], text: str) -> tuple[str, int] | None:
    """The first line of ``tail`` (offset, line) that breaks the layout more than half of them share (of such
    layouts, the one with the most numbers per row): a row of numbers with another count of them, or a line
    between rows of the layout that is not a row of numbers ('line N has k fields'), and the rows' count of
    numbers; a line after the last row that is not a row of numbers (a footer); None when there is no such layout or
    no such line (a header above the rows)."""
    lines = [ln for _, ln in tail]
    shared: tuple[int, int, str | None, str] | None = None  # (rows, fields, delimiter, decimal mark)
    for delim, dec in DIALECTS:
        counts = [numeric_row(line, delim, dec) for line in lines]
        top = max(set(counts) - {0}, key=lambda n: (counts.count(n), n), default=0)
        if top and 2 * counts.count(top) > len(lines) and (shared is None or (counts.count(top), top) > shared[:2]):
            shared = (counts.count(top), top, delim, dec)
    if shared is None:
        return None
    _, ncols, delim, dec = shared
    fits = [numeric_row(line, delim, dec) == ncols for line in lines]
    for k, (pos, line) in enumerate(tail):
        if fits[k]:
            continue
        if numeric_row(line, delim, dec):
            n = len(fields(line, delim))
            what = f"has {n} field{'s' if n != 1 else ''}"
        elif any(fits[:k]) and any(fits[k + 1:]):
            what = f"is not a row of numbers ({line.strip()[:40]!r})"
        elif any(fits[:k]):  # after the last row: a footer, which the export's rows must not have
            what = (f"follows the last row of numbers and is not one ({line.strip()[:40]!r}): a footer; delete it and "
                    "the lines after it")
            return f"line {text.count(chr(10), 0, pos) + 1} {what}", ncols
        else:
            continue
        return f"line {text.count(chr(10), 0, pos) + 1} {what}", ncols
    return None


def data_start(path: Path, head: list[str], delim: str | None, dec: str, ncols: int) -> int:
    ok = [numeric_row(line, delim, dec) == ncols for line in head]
    for i in range(len(head)):
        if ok[i] and all(ok[i:i + CONFIRM_ROWS]):
            return i
    raise ScopeFileError(f"{path}: no run of {CONFIRM_ROWS} rows of {ncols} numbers in its first {len(head)} lines: "
                         "more metadata lines than an oscilloscope writes, or a column that is not numeric")
