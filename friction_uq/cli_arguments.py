"""The command line's argument types and the checks of its input and output files, before any work: each
refusal one sentence (argparse's usage error, or a FrictionUQError naming the file)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path

from .errors import ConfigError, FrictionUQError, OutputError

#: Figure formats of ``design -o`` and ``compare -o`` (matplotlib writes them without extra packages).
FIGURE_SUFFIXES = (".pdf", ".png", ".svg", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff", ".webp")
#: Record file names ``simulate -o`` writes.
RECORD_SUFFIXES = (".h5", ".hdf5")


def seed_argument(text: str) -> int:
    """A seed in decimal ASCII digits ("010" is 10; "0x10", "5_000" and other scripts' digits are refused, not read
    another way)."""
    digits = text.strip()
    if not (digits.isascii() and digits.lstrip("+-").isdigit() and len(digits) - len(digits.lstrip("+-")) <= 1):
        raise argparse.ArgumentTypeError(f"seed {text!r} is not a decimal integer (digits 0-9 only)")
    v = int(digits, 10)
    if not 0 <= v < 2**64:
        raise argparse.ArgumentTypeError(f"seed must be an integer in [0, 2**64), got {text}")
    return v


def output_file(path: Path, suffixes: Sequence[str], what: str) -> None:
    """Refuse an output name that is a directory, has a parent that is a file, or an unknown suffix."""
    if path.is_dir():
        raise OutputError(f"{path}: is a directory; give a {what} file name ending in {' or '.join(suffixes)}")
    if path.suffix.lower() not in suffixes:
        raise OutputError(f"{path}: unknown {what} format {path.suffix or '(no suffix)'!r}; "
                          f"give a name ending in {', '.join(suffixes)}")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"{path}: {parent} is a file, not a folder")
            break


def path_argument(text: str) -> Path:
    """A path given on the command line; an empty one is refused (``Path('')`` is the current folder: ``--out ''``
    wrote there, ``run ''`` read it as a folder)."""
    if not text:
        raise argparse.ArgumentTypeError("an empty path: give a file or folder name")
    return Path(text)


def text_file(path: Path, what: str, error: type[FrictionUQError]) -> str:
    """The UTF-8 text of an input file, or one sentence saying why it is not one."""
    from .plausible import MAX_TEXT_BYTES, NotText, text_of

    try:
        return text_of(path, what, MAX_TEXT_BYTES)
    except NotText as why:
        raise error(f"{path}: {why}") from None


def config_file(path: Path) -> None:
    """Refuse a configuration that is not UTF-8 TOML, or is nested too deeply to parse."""
    import tomllib

    from .plausible import toml_shape_problem

    text = text_file(path, "simulation configuration (TOML)", ConfigError)
    problem = toml_shape_problem(text)
    if problem:
        raise ConfigError(f"{path}: {problem}, too deep for a simulation configuration (docs/limits.md)")
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be a simulation configuration") from None


_TIME_UNITS = {"s": "1", "ms": "1e-3", "us": "1e-6", "\u00b5s": "1e-6"}  # exact decimal scales


def window_argument(text: str) -> tuple[float, float]:
    """T0:T1 in seconds, or with a unit (s, ms, us) on either bound or on the second for both: 400us:600us,
    400:600us, 0.4ms:0.6ms, 4e-4:6e-4."""
    import re
    from decimal import Decimal

    bad = (f"window {text!r} is not T0:T1 on the record's time base, in seconds or with a unit: "
           "400us:600us, 0.4ms:0.6ms or 4e-4:6e-4")
    parts = text.split(":")
    m = [re.fullmatch(r"\s*([-+0-9.eE]+)\s*(s|ms|us|\u00b5s)?\s*", p) for p in parts]
    if len(parts) != 2 or not all(m):
        raise argparse.ArgumentTypeError(bad)
    unit_b = m[1].group(2)
    try:
        vals = [float(Decimal(x.group(1)) * Decimal(_TIME_UNITS[x.group(2) or unit_b or "s"])) for x in m]
    except (ValueError, ArithmeticError):  # not a number; or one past Decimal's exponent range (Overflow)
        raise argparse.ArgumentTypeError(bad) from None
    if not all(math.isfinite(v) for v in vals):
        raise argparse.ArgumentTypeError(f"window {text!r}: its times must be finite")
    if not (m[0].group(2) or unit_b) and max(abs(v) for v in vals) > 1.0:
        raise argparse.ArgumentTypeError(f"window {text!r}: {vals[0]:g} to {vals[1]:g} s is longer than any record; "
                                         f"for microseconds write {parts[0]}us:{parts[1]}us")
    if not vals[1] > vals[0]:
        raise argparse.ArgumentTypeError(f"window {text!r}: T1 must be after T0")
    return vals[0], vals[1]


def _plausible_number(text: str, label: str, key: str) -> float:
    """``text`` as a number inside its plausible range (:data:`friction_uq.plausible.RANGES` ``key``)."""
    from .plausible import out_of_range

    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{label} {text!r} is not a number") from None
    problem = out_of_range(key, v)
    if problem:
        raise argparse.ArgumentTypeError(f"{label} {problem}")
    return v


def striker_velocity_argument(text: str) -> float:
    return _plausible_number(text, "striker velocity", "striker_velocity")


def nu_argument(text: str) -> float:
    return _plausible_number(text, "nu", "sample.poisson_ratio")


def workers_argument(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"workers {text!r} is not a whole number") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"workers must be at least 1, got {v}")
    return v
