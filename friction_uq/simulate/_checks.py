"""Typed readers for configuration values: each raises ConfigError with one sentence naming the
file, the key and the problem (style: what was received, what is allowed)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..errors import ConfigError
from ..plausible import text_bytes, unprintable


class Section:
    """One table of a configuration file, read key by key; unknown keys are refused."""

    def __init__(self, source: str, name: str, table: Any, allowed: Sequence[str]) -> None:
        self.source = source
        self.name = name
        if not isinstance(table, Mapping):
            raise ConfigError(f"{source}: [{name}] must be a table, got {_show(table)}.")
        unknown = [k for k in table if k not in allowed]
        if unknown:
            raise ConfigError(
                f"{source}: unknown key '{self._key(unknown[0])}'; allowed keys in [{name}]: {', '.join(allowed)}."
            )
        self.table = table

    def _key(self, key: str) -> str:
        return f"{self.name}.{key}"

    def fail(self, key: str, problem: str) -> ConfigError:
        return ConfigError(f"{self.source}: key '{self._key(key)}' {problem}.")

    def __contains__(self, key: str) -> bool:
        return key in self.table

    def number(self, key: str, default: float | None, *, low: float = -math.inf, high: float = math.inf,
               low_open: bool = False, required: bool = False) -> float:
        """A float (TOML integers accepted) in [low, high] (or (low, high] with ``low_open``)."""
        if key not in self.table:
            if required or default is None:
                raise self.fail(key, "is missing")
            return default
        value = self.table[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"must be a number, got {_show(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise self.fail(key, f"must be finite, got {value!r}")
        above = value > low if low_open else value >= low
        if not (above and value <= high):
            lo = "(" if low_open else "["
            raise self.fail(key, f"must lie in {lo}{low:g}, {high:g}], got {value!r}")
        return value

    def integer(self, key: str, default: int | None, *, low: int, high: int) -> int | None:
        if key not in self.table:
            return default
        value = self.table[key]
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"must be an integer, got {_show(value)}")
        if not low <= value <= high:
            raise self.fail(key, f"must lie in [{low}, {high}], got {value!r}")
        return int(value)

    def boolean(self, key: str, default: bool) -> bool:
        if key not in self.table:
            return default
        value = self.table[key]
        if not isinstance(value, bool):
            raise self.fail(key, f"must be true or false, got {_show(value)}")
        return value

    def string(self, key: str, default: str | None, *, choices: Sequence[str] | None = None,
               max_chars: int | None = None, max_bytes: int | None = None, free_text: bool = False) -> str | None:
        """``key``'s text; ``max_chars`` and ``max_bytes`` (UTF-8): the longest the record reader takes. No NUL (no
        record attribute holds one); no control, format or line-separator character unless ``free_text`` (the reader
        refuses them in ids and names: what is simulated can be read back)."""
        if key not in self.table:
            return default
        value = self.table[key]
        if not isinstance(value, str):
            raise self.fail(key, f"must be a string, got {_show(value)}")
        if "\x00" in value:
            raise self.fail(key, f"holds a NUL character at position {value.index(chr(0))}, which no record can store")
        if not free_text and (bad := unprintable(value)):
            raise self.fail(key, f"{bad}: it is printed on terminals and names files")
        if max_chars is not None and len(value) > max_chars:
            raise self.fail(key, f"is {len(value)} characters long, more than the {max_chars} a record takes")
        if max_bytes is not None and text_bytes(value) > max_bytes:
            raise self.fail(key, f"holds more than the {max_bytes} bytes of text a record's attribute may")
        if choices is not None and value not in choices:
            raise self.fail(key, f"is {value!r}, allowed values: {', '.join(choices)}")
        if choices is None and not value.strip():
            raise self.fail(key, "is empty")
        return value


def _show(value: Any) -> str:
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{text} ({type(value).__name__})"
