"""The units a text export writes beside its columns (friction_uq.acquisition.file_units)."""

from __future__ import annotations

import pytest

from friction_uq.acquisition.file_units import (
    channel_unit_conflict,
    suffix_unit,
    time_unit_conflict,
    unit_name,
    units_row,
)


@pytest.mark.parametrize("cell, unit", [
    ("V", "V"), ("(V)", "V"), ("Volt", "V"), (" volts ", "V"), ('"mV"', "mV"), ("[mV]", "mV"), ("( mV )", "mV"),
    ("\u00b5V", "uV"), ("\u03bcV", "uV"), ("s", "s"), ("second", "s"), ("(\u00b5s)", "us"), ("(\u03bcs)", "us"),
    ("us", "us"), ("ms", "ms"), ("ns", "ns"), ("microstrain", "microstrain"), ("\u00b5\u03b5", "microstrain"),
    ("strain", "strain"),
    ("Channel A", None), ("CH1", None), ("probe 10:1", None), ("", None), ("1.5e-3", None), ("Vertical", None),
])
def test_a_cell_names_a_unit_or_nothing(cell, unit):
    assert unit_name(cell) == unit


@pytest.mark.parametrize("name, unit", [
    ("Time (s)", "s"), ("CH2 [mV]", "mV"), ("Zeit(\u00b5s)", "us"), ("CH1", None), ("(mV)", None), ("A (probe)", None),
])
def test_a_column_name_ends_in_its_unit_or_not(name, unit):
    assert suffix_unit(name) == unit


def test_a_units_row_has_a_unit_in_every_cell_that_is_not_empty():
    assert units_row(["(us)", "(mV)", "", "(V)"], 4) == ["us", "mV", None, "V"]
    assert units_row(["s", "V", "V"], 4) == ["s", "V", "V", None]  # the empty cells at its end dropped by the split
    assert units_row(["s", "V", "V", "V", "V"], 4) is None  # more cells than columns: not this table's row
    assert units_row(["(s)", "(A)"], 2) == ["s", "A"]  # a current probe's unit is a unit, not a word
    assert units_row(["s", "V", "probe"], 3) is None  # a word that is no unit: not a units row
    assert units_row(["", "", ""], 3) is None


def test_conflicts_are_said_only_where_the_file_says_another_unit():
    assert channel_unit_conflict(None, "V") is None and channel_unit_conflict("V", "V") is None
    assert channel_unit_conflict("mV", "V") == 'write units = "mV"'
    assert channel_unit_conflict("microstrain", "strain") == 'write units = "microstrain"'
    assert "is it the time column" in channel_unit_conflict("s", "V")
    assert "is it the right column" in channel_unit_conflict("A", "V")
    assert time_unit_conflict("us", "\u00b5s") is None and time_unit_conflict("s", "s") is None
    assert time_unit_conflict("V", "s") is None  # a time column the file calls volts: its range decides
    assert time_unit_conflict("ms", "s") == 'write [time] units = "ms"'


def test_a_metadata_line_of_numbered_columns_is_no_header_to_read_units_from():
    """Columns by number, no header, a line "Sample Rate (Hz),1000000" right above the data: its bracket is no
    column's unit (a reviewer's case; a "Sampling interval (us)" would have refused a time column in s)."""
    from friction_uq.acquisition.delimited import _units

    assert _units([], None, ["Sample Rate (Hz)", "1000000"], False, 2, [0, 1], ".") == [(None, "its name")] * 2
    assert _units([], None, ["Time (us)", "CH1 [mV]"], False, 2, [0, 1], ".") == [("us", "its name"),
                                                                               ("mV", "its name")]
