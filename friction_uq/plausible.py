"""Plausible ranges of every apparatus and signal quantity, and the size limits of every input (docs/limits.md).

A value outside its range is refused where it is read (a record, a simulation configuration, an
option), with one sentence naming the file, the field, the value and the range. The ranges are
wide: each spans what split Hopkinson bars built in a laboratory have (polymer bars to tungsten
carbide, millimetre samples to 20 cm, 100 kHz to 10 GHz digitisers); a value outside is a typo, a
unit slip (mm for m, V for strain) or a file that is not what it says. Limits on sizes are checked
before any work, from what a file declares (a dataset's shape, a file's size), not from what it
decompresses to.
"""

from __future__ import annotations

import math
import os
import re
import stat
import unicodedata
from pathlib import Path

from .errors import os_error_text

#: (low, high, unit, what spans it) per quantity; bounds are inclusive.
RANGES: dict[str, tuple[float, float, str, str]] = {
    "bar.young_modulus": (1e9, 1e12, "Pa", "polymer (PMMA 3 GPa) to tungsten carbide (700 GPa) bars"),
    "bar.wave_speed": (500.0, 15000.0, "m/s", "polymer to beryllium bars"),
    "bar.diameter": (1e-3, 0.2, "m", "1 mm micro-bars to 200 mm bars"),
    "bar.density": (300.0, 25000.0, "kg/m^3", "polymer to tungsten bars: E / c^2, the two declared together"),
    "bar.length": (0.01, 20.0, "m", "1 cm strikers to 20 m bars"),
    "bar.gauge_distance": (1e-3, 20.0, "m", "a gauge on the bar"),
    "tube.young_modulus": (1e9, 1e12, "Pa", "polymer to carbide confining tubes"),
    "tube.diameter": (1e-3, 0.5, "m", "confining tubes"),
    "tube.length": (1e-3, 1.0, "m", "confining tubes"),
    "tube.gauge_width": (1e-4, 0.05, "m", "strain gauge grids 0.1 to 50 mm"),
    "sample.diameter": (1e-4, 0.2, "m", "samples 0.1 mm to 20 cm across"),
    "sample.length": (1e-4, 0.2, "m", "samples 0.1 mm to 20 cm long"),
    "sample.young_modulus": (1e5, 1e12, "Pa", "rubbers (0.1 MPa) to ceramics"),
    "sample.density": (100.0, 25000.0, "kg/m^3", "foams to osmium"),
    "sample.poisson_ratio": (0.01, 0.4999, "", "a sample that swells sideways at all, short of incompressible; eq. 17's f "
                             "grows as 1/nu below"),
    "plug.length": (1e-4, 0.5, "m", "plugs"),
    "plug.young_modulus": (1e8, 1e12, "Pa", "polymer to carbide plugs"),
    "plug.density": (100.0, 25000.0, "kg/m^3", "foams to osmium"),
    "signals.sample_rate": (1e5, 1e10, "Hz", "digitisers of 100 kHz to 10 GHz"),
    "signals.t0": (-1.0, 1.0, "s", "a trigger within a second of the record's start"),
    "signals.strain_per_volt": (1e-9, 1.0, "strain/V", "gauge bridges and amplifiers"),
    "signals.strain": (0.0, 0.1, "", "a gauge on an elastic bar or tube (10 % strain has long yielded steel)"),
    "striker_velocity": (0.1, 200.0, "m/s", "gas guns of Hopkinson bars"),
}

#: Samples per channel of a record (10 ms at 100 MHz; a confined friction test lasts about 1 ms).
MAX_SAMPLES = 1_000_000
#: Chunks of one channel's dataset: a million samples stored a chunk each took 1 GB of HDF5's chunk index per
#: channel to read (62 500 chunks of 16: 210 MB); 10 000 chunks of 100 samples read in 0.07 s within a few MB.
MAX_CHUNKS = 10_000
#: Bytes of a record file (four channels of MAX_SAMPLES float64 samples take 32 MB).
MAX_RECORD_BYTES = 256 * 2**20
#: Bytes of one attribute of a record, as stored.
MAX_ATTRIBUTE_BYTES = 64 * 2**10
#: Longest test id or campaign name (characters): the two name every output file, whose name the file system
#: limits to 255 bytes.
MAX_ID_CHARS = 100
#: Bytes of a text input (simulation configuration, prior file, result JSON).
MAX_TEXT_BYTES = 1 * 2**20
#: Parts of one dotted key or table name of a TOML file (``a.b.c`` has 3), and levels of nesting.
MAX_TOML_DEPTH = 32
#: Samples a simulation writes per channel (sample_rate x duration), as for a record.
MAX_SIMULATED_SAMPLES = MAX_SAMPLES
#: Time steps of a simulation (duration / time step).
MAX_SIMULATION_STEPS = 5_000_000

_NAME = re.compile(r"[A-Za-z0-9_-]+")


def out_of_range(key: str, value: float) -> str | None:
    """None if ``value`` lies in the plausible range of ``key`` (:data:`RANGES`), else the problem in words."""
    low, high, unit, what = RANGES[key]
    if math.isfinite(value) and low <= value <= high:
        return None
    u = f" {unit}" if unit else ""
    return f"is {value!r}{u}, outside the plausible range [{low:g}, {high:g}]{u} ({what})"


def text_bytes(text: str) -> int:
    """Bytes ``text`` takes as UTF-8 (lone surrogates counted, not refused): what an attribute's limit counts."""
    return len(text.encode("utf-8", "surrogatepass"))


def not_regular(path: Path) -> str | None:
    """None if ``path`` is a regular file (or does not exist: its reader says so), else a few words: a pipe would
    block the reader, a device never end."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None
    if stat.S_ISREG(mode):
        return None
    return "is a folder" if stat.S_ISDIR(mode) else "is not a regular file (a device or a pipe)"


#: The first bytes of every HDF5 file (a test record given where a text file was asked for)
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


class NotText(ValueError):
    """Why a file is not the text input it was given as: the words that follow its name (and its field)."""


def text_of(path: Path, what: str, limit: int, *, encoding: str = "utf-8") -> str:
    """The text of an input file (a prior file, a set-up, a configuration, a result) read up to ``limit`` bytes and
    decoded with ``encoding``; else :class:`NotText` in a few words naming ``what`` it was given as: not a regular
    file, unreadable, too large (from at most ``limit`` + 1 bytes read), a record, not UTF-8, NUL characters."""
    if odd := not_regular(path):
        raise NotText(f"{odd}, not a {what}")
    try:
        with open(path, "rb") as fh:
            raw = fh.read(limit + 1)
    except OSError as exc:
        raise NotText(f"cannot be read ({os_error_text(exc)})") from None
    if len(raw) > limit:
        raise NotText(f"is larger than {limit} bytes, too large for a {what} (docs/limits.md)")
    if raw.startswith(HDF5_SIGNATURE):
        raise NotText(f"is an HDF5 file (a test record?), not a {what}")
    try:
        text = raw.decode(encoding)
    except UnicodeDecodeError as exc:
        raise NotText(f"is not UTF-8 text (byte {exc.start}); save the {what} as UTF-8") from None
    if "\x00" in text:
        raise NotText(f"contains NUL characters (a binary file?), not a {what}")
    return text


def unprintable(text: str) -> str | None:
    """None if ``text`` has no control, format or line-separator character, else a few words naming the first:
    such text would move the cursor, start a new line or reorder the text of a terminal that prints it."""
    for i, ch in enumerate(text):
        if unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp"):
            return f"holds the control character {ch!r} at position {i}"
    return None


def is_name(text: str) -> bool:
    """``text`` is a name: letters, digits, '-' and '_' only (no path, no space, no dot)."""
    return bool(_NAME.fullmatch(text))


def escaped(text: str) -> str:
    """``text`` with control, format and line-separator characters written as escapes (a terminal shows them)."""
    if unprintable(text) is None:
        return text
    return "".join(ch.encode("unicode_escape").decode("ascii")
                   if unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp") else ch for ch in text)


def apparatus_problem(app) -> tuple[str, str, str] | None:
    """The first quantity of an :class:`~friction_uq.apparatus.Apparatus` outside its plausible range, as
    (part, attribute, problem), or None. Attributes are the record contract's names."""
    checks: list[tuple[str, str, str, float]] = []
    for part in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
        bar = getattr(app, part)
        diameter = "outer_diameter" if part == "external_output_bar" else "diameter"
        checks += [(part, "young_modulus", "bar.young_modulus", bar.young_modulus),
                   (part, "wave_speed", "bar.wave_speed", bar.wave_speed),
                   (part, diameter, "bar.diameter", bar.outer_diameter),
                   (part, "length", "bar.length", bar.length)]
        if part == "external_output_bar":
            checks.append((part, "inner_diameter", "bar.diameter", bar.inner_diameter))
        if bar.gauge_distance is not None:
            checks.append((part, "gauge_distance", "bar.gauge_distance", bar.gauge_distance))
    t, s = app.tube, app.sample
    checks += [("tube", "young_modulus", "tube.young_modulus", t.young_modulus),
               ("tube", "inner_diameter", "tube.diameter", t.inner_diameter),
               ("tube", "outer_diameter", "tube.diameter", t.outer_diameter),
               ("tube", "length", "tube.length", t.length),
               ("tube", "gauge_width", "tube.gauge_width", t.gauge_width),
               ("sample", "diameter", "sample.diameter", s.diameter),
               ("sample", "length", "sample.length", s.length),
               ("sample", "young_modulus", "sample.young_modulus", s.young_modulus),
               ("sample", "density", "sample.density", s.density)]
    if app.plug is not None:
        checks += [("plug", k, f"plug.{k}", getattr(app.plug, k)) for k in ("length", "young_modulus", "density")]
    for part, attr, key, value in checks:
        problem = out_of_range(key, value)
        if problem:
            return part, attr, problem
    if t.gauge_width >= t.length:
        return "tube", "gauge_width", f"is {t.gauge_width!r} m, not narrower than the tube's length {t.length!r} m"
    for part in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
        bar = getattr(app, part)  # E and c each plausible, yet together a bar of no material (E = rho c^2)
        density = bar.young_modulus / bar.wave_speed**2
        if out_of_range("bar.density", density):
            low, high = RANGES["bar.density"][:2]
            return part, "young_modulus", (f"is {bar.young_modulus:.3g} Pa with wave_speed {bar.wave_speed:.4g} m/s: a "
                                           f"density E / c^2 of {density:.3g} kg/m^3, outside [{low:g}, {high:g}] "
                                           "kg/m^3 (polymer to tungsten bars): one of the two is off")
    return None


def toml_shape_problem(text: str) -> str | None:
    """None if a TOML text stays within :data:`MAX_TOML_DEPTH` (dotted-key parts, nesting of arrays and
    tables), else the problem in words. One pass over the text, before the parser (whose time and memory
    grow with the depth: 50,000 dotted parts take minutes)."""
    depth = dots = 0
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if c in "\"'":
            i = _string_end(text, i)
            continue
        if c == ".":
            dots += 1
            if dots >= MAX_TOML_DEPTH:
                return f"has a dotted key of more than {MAX_TOML_DEPTH} parts (line {text.count(chr(10), 0, i) + 1})"
        elif c in "[{":
            depth, dots = depth + 1, 0
            if depth > MAX_TOML_DEPTH:
                return (f"is nested too deeply (arrays or tables more than {MAX_TOML_DEPTH} levels, line "
                        f"{text.count(chr(10), 0, i) + 1})")
        elif c in "]}":
            depth, dots = max(0, depth - 1), 0
        elif not (c.isalnum() or c in "_-+: \t"):
            dots = 0
        i += 1
    return None


def _string_end(text: str, i: int) -> int:
    """Index just past the TOML string that starts at ``text[i]`` (basic or literal, one line or multi-line)."""
    q = text[i]
    if text.startswith(q * 3, i):
        j = i + 3
        while True:
            k = text.find(q * 3, j)
            if k < 0:
                return len(text)
            if q == "'" or not _escaped_at(text, k):
                return k + 3
            j = k + 1
    j = i + 1
    while j < len(text) and text[j] != "\n":
        if text[j] == q and (q == "'" or not _escaped_at(text, j)):
            return j + 1
        j += 1
    return j


def _escaped_at(text: str, k: int) -> bool:
    """The character at ``k`` follows an odd number of backslashes."""
    b = 0
    while k - b - 1 >= 0 and text[k - b - 1] == "\\":
        b += 1
    return b % 2 == 1
