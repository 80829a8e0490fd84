"""friction-uq import: a bundled record written out as a scope would, imported back, analysed the same.

The reference is the original record's own analysis (deterministic identification, eq. 17, and its
forces), not the importer's output: the exported voltages go through the scope's text (9 digits),
the lab's wiring (a bridge the other way round, fixed by ``sign = -1``), the set-up file's
strain_per_volt, and back.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest

from friction_uq.acquisition import TEMPLATE, import_scope_files, parse_setup
from friction_uq.acquisition.scope_export import export_record, gauge_signals, write_scope_csv
from friction_uq.analysis import identify, prepare
from friction_uq.cli import main
from friction_uq.errors import ScopeFileError, SetupError
from friction_uq.record import read_record

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "data" / "A" / "A-03.h5"
SPV = {"input_bar": 2e-4, "internal_output_bar": 2e-4, "external_output_bar": 1e-4, "tube_hoop": 5e-5}
COLUMNS = {"input_bar": "CH1", "internal_output_bar": "CH2", "external_output_bar": "CH3", "tube_hoop": "CH4"}


def _apparatus(path: Path) -> dict:
    with h5py.File(path) as fh:
        return {part: {k: (v.decode() if isinstance(v, bytes) else v.item() if hasattr(v, "item") else v)
                       for k, v in fh["apparatus"][part].attrs.items()} for part in fh["apparatus"]}


def setup_doc(*, signs: dict | None = None, files: dict | None = None, time: dict | None = None,
              spv: dict | None = None) -> dict:
    """A SETUP document for A-03's apparatus: the template's record and time, this test's channels."""
    doc = tomllib.loads(TEMPLATE)
    doc["record"] = {"test_id": "A-03", "campaign": "A", "striker_velocity": 9.9}
    doc["time"] = time if time is not None else {"column": "Time"}
    doc["apparatus"] = _apparatus(RECORD)
    doc["channels"] = {}
    for g, col in COLUMNS.items():
        c = {"column": col, "units": "V", "strain_per_volt": (spv or SPV)[g], "sign": (signs or {}).get(g, 1)}
        if files:
            c["file"] = files[g]
        doc["channels"][g] = c
    return doc


def write_setup(path: Path, doc: dict) -> Path:
    def value(v):
        if isinstance(v, str):
            return '"' + v + '"'
        return repr(v) if not isinstance(v, bool) else str(v).lower()

    lines = []
    for top, table in doc.items():
        nested = {k: v for k, v in table.items() if isinstance(v, dict)}
        flat = {k: v for k, v in table.items() if not isinstance(v, dict)}
        if flat:
            lines.append(f"[{top}]")
            lines += [f"{k} = {value(v)}" for k, v in flat.items()]
        for k, sub in nested.items():
            lines.append(f"[{top}.{k}]")
            lines += [f"{kk} = {value(vv)}" for kk, vv in sub.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def assert_same_analysis(original: Path, imported: Path) -> None:
    a = identify(prepare(read_record(original)), nu=0.4)
    b = identify(prepare(read_record(imported)), nu=0.4)
    assert b.window == pytest.approx(a.window, abs=1e-9)
    for name in ("f", "ratio", "F_io", "F_eo", "p_mean", "V", "tau_mean"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-4), name


def test_template_is_a_valid_setup():
    s = parse_setup(tomllib.loads(TEMPLATE), path="SETUP.toml")
    assert s.channels["input_bar"].strain_per_volt == pytest.approx(4 / (2 * 2.1 * 10 * 100))  # half bridge
    assert s.apparatus["tube"]["gauge_offset"] == 0.0025 and s.time.column == "Time"


def test_one_file_with_metadata_volts_and_a_reversed_bridge(tmp_path, capsys):
    (csv,) = export_record(RECORD, tmp_path, strain_per_volt=SPV, signs={"input_bar": -1}, names=COLUMNS)
    assert csv.read_text().startswith("Model,")  # metadata lines before the header
    setup = write_setup(tmp_path / "SETUP.toml", setup_doc(signs={"input_bar": -1}))
    out = tmp_path / "A-03.h5"
    assert main(["import", str(csv), "--setup", str(setup), "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    orig, imp = read_record(RECORD), read_record(out)
    assert (imp.sample_rate, imp.t0, imp.n_samples) == pytest.approx((orig.sample_rate, orig.t0, orig.n_samples))
    for g in COLUMNS:
        np.testing.assert_allclose(imp.strain(g), orig.strain(g), rtol=0, atol=1e-9 * np.abs(orig.strain(g)).max())
    assert_same_analysis(RECORD, out)
    with h5py.File(out) as fh:
        assert fh["signals/input_bar"].attrs["sign_applied"] == -1
        assert fh["signals/input_bar"].attrs["units"] == "V"


def test_an_existing_record_is_not_replaced_unasked(tmp_path, capsys):
    (csv,) = export_record(RECORD, tmp_path, strain_per_volt=SPV, names=COLUMNS)
    setup = write_setup(tmp_path / "SETUP.toml", setup_doc())
    out = tmp_path / "A-03.h5"
    out.write_bytes(b"a lab's earlier record")
    assert main(["import", str(csv), "--setup", str(setup), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "A-03.h5: a file of that name exists; give another name, or --overwrite to replace it" in err
    assert err.count("\n") == 1 and out.read_bytes() == b"a lab's earlier record"
    assert main(["import", str(csv), "--setup", str(setup), "-o", str(out), "--overwrite"]) == 0
    assert read_record(out).n_samples == read_record(RECORD).n_samples


def test_one_file_per_channel_semicolons_and_decimal_commas(tmp_path):
    files = export_record(RECORD, tmp_path, strain_per_volt=SPV, names=COLUMNS, per_channel=True,
                          delimiter=";", decimal=",")
    assert [f.name for f in files] == ["CH1.csv", "CH2.csv", "CH3.csv", "CH4.csv"]
    assert "e-05;" in files[0].read_text().splitlines()[8].replace(",", ".") or ";" in files[0].read_text()
    doc = setup_doc(files={g: f"{c}.csv" for g, c in COLUMNS.items()})
    out = import_scope_files(files, parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    assert out.warnings == ()
    assert_same_analysis(RECORD, tmp_path / "r.h5")


def _tdms_shot(tmp_path: Path) -> tuple[Path, dict]:
    """A-03's gauges in one TDMS file with its own time base, and the set-up that reads it."""
    nptdms = pytest.importorskip("nptdms")
    strains, rate, t0 = gauge_signals(RECORD)
    chans = [nptdms.ChannelObject("scope", COLUMNS[g], eps / SPV[g],
                                  properties={"wf_increment": 1.0 / rate, "wf_start_offset": t0})
             for g, eps in strains.items()]
    path = tmp_path / "shot.tdms"
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment([nptdms.RootObject(), nptdms.GroupObject("scope"), *chans])
    doc = setup_doc()
    del doc["time"]  # TDMS carries its time base
    for g, c in COLUMNS.items():
        doc["channels"][g]["column"] = f"scope/{c}"
    return path, doc


def test_tdms_with_its_own_time_base(tmp_path):
    path, doc = _tdms_shot(tmp_path)
    import_scope_files([path], parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    assert_same_analysis(RECORD, tmp_path / "r.h5")


def _trc(path: Path, volts: np.ndarray, dt: float, t0: float) -> Path:
    """A LeCroy trace (WAVEDESC template LECROY_2_3, 16-bit little-endian samples), written by hand."""
    gain = float(np.max(np.abs(volts))) / 30000.0
    raw = np.round(volts / gain).astype("<i2")
    desc = bytearray(346)
    desc[0:8] = b"WAVEDESC"
    desc[16:26] = b"LECROY_2_3"
    np.frombuffer(desc, "<u2")  # (the descriptor is little-endian throughout)
    desc[32:34] = (1).to_bytes(2, "little")  # 16-bit samples
    desc[34:36] = (1).to_bytes(2, "little")  # little-endian
    desc[36:40] = (346).to_bytes(4, "little")
    desc[60:64] = (2 * raw.size).to_bytes(4, "little")
    desc[116:120] = raw.size.to_bytes(4, "little")
    desc[156:160] = np.float32(gain).tobytes()
    desc[176:180] = np.float32(dt).tobytes()
    desc[180:188] = np.float64(t0).tobytes()
    desc[172:174] = (16).to_bytes(2, "little")
    path.write_bytes(bytes(desc) + raw.tobytes())
    return path


def test_lecroy_traces_one_per_channel(tmp_path):
    pytest.importorskip("lecroyparser")
    strains, rate, t0 = gauge_signals(RECORD)
    files = [_trc(tmp_path / f"C{i + 1}shot00000.trc", eps / SPV[g], 1.0 / rate, t0)
             for i, (g, eps) in enumerate(strains.items())]
    doc = setup_doc(files={g: f.name for g, f in zip(strains, files)})
    del doc["time"]
    for c in doc["channels"].values():
        c["column"] = 1
    import_scope_files(files, parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    imp, orig = read_record(tmp_path / "r.h5"), read_record(RECORD)
    assert imp.sample_rate == pytest.approx(rate, rel=1e-9) and imp.t0 == pytest.approx(t0)
    for g in strains:  # 16-bit samples: within one step of the scope's scale
        step = np.abs(orig.strain(g)).max() / 30000
        assert np.max(np.abs(imp.strain(g) - orig.strain(g))) <= 0.51 * step
    a = identify(prepare(orig), nu=0.4)
    b = identify(prepare(imp), nu=0.4)
    assert b.f == pytest.approx(a.f, rel=1e-3)


def _isf(path: Path, volts: np.ndarray, dt: float, t0: float, name: str) -> Path:
    """A Tektronix ISF waveform (text preamble, 16-bit big-endian curve), written by hand."""
    ymult = float(np.max(np.abs(volts))) / 30000.0
    raw = np.round(volts / ymult).astype(">i2")
    nbytes = str(2 * raw.size)
    head = (f':WFMPRE:BYT_NR 2;BIT_NR 16;ENCDG BIN;BN_FMT RI;BYT_OR MSB;WFID "{name}, DC coupling, 2.0E-2 V/div";'
            f'NR_PT {raw.size};PT_FMT Y;XUNIT "s";XINCR {dt:.6E};XZERO {t0:.6E};PT_OFF 0;YUNIT "V";'
            f'YMULT {ymult:.6E};YOFF 0.0E+0;YZERO 0.0E+0;:CURVE #{len(nbytes)}{nbytes}')
    path.write_bytes(head.encode() + raw.tobytes() + b"\n")
    return path


def test_tektronix_isf_one_per_channel(tmp_path):
    pytest.importorskip("RigolWFM")
    strains, rate, t0 = gauge_signals(RECORD)
    files = [_isf(tmp_path / f"TEK000{i + 1}.ISF", eps / SPV[g], 1.0 / rate, t0, f"Ch{i + 1}")
             for i, (g, eps) in enumerate(strains.items())]
    doc = setup_doc(files={g: f.name for g, f in zip(strains, files)})
    del doc["time"]
    for c in doc["channels"].values():
        c["column"] = 1
    import_scope_files(files, parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    imp, orig = read_record(tmp_path / "r.h5"), read_record(RECORD)
    assert imp.sample_rate == pytest.approx(rate, rel=1e-9) and imp.t0 == pytest.approx(t0, abs=1e-12)
    for g in strains:  # 16-bit samples: within one step of the scope's scale
        step = np.abs(orig.strain(g)).max() / 30000
        assert np.max(np.abs(imp.strain(g) - orig.strain(g))) <= 0.51 * step
    assert identify(prepare(imp), nu=0.4).f == pytest.approx(identify(prepare(orig), nu=0.4).f, rel=1e-3)


# ---- bad input: one sentence naming the file, the line or column, exit 2, nothing written ----------


@pytest.fixture
def scope_csv(tmp_path) -> Path:
    (csv,) = export_record(RECORD, tmp_path, strain_per_volt=SPV, names=COLUMNS)
    return csv


def _refused(tmp_path, files, doc, capsys) -> str:
    setup = write_setup(tmp_path / "SETUP.toml", doc)
    out = tmp_path / "out.h5"
    assert main(["import", *map(str, files), "--setup", str(setup), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert not out.exists() and not list(tmp_path.glob(".out.h5*"))
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_missing_column_is_named(tmp_path, scope_csv, capsys):
    doc = setup_doc()
    doc["channels"]["external_output_bar"]["column"] = "CH7"
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "scope.csv: column 'CH7' not found; the header line 6 has: Time, CH1, CH2, CH3, CH4" in err


def test_rows_over_the_sample_limit_are_counted_before_parsing(tmp_path, scope_csv, capsys, monkeypatch):
    import friction_uq.acquisition.delimited as delimited

    def no_parse(*args, **kwargs):
        raise AssertionError("the numbers were parsed before the rows were counted")

    monkeypatch.setattr(delimited, "MAX_SAMPLES", 1000)  # the export holds a few thousand rows
    monkeypatch.setattr(delimited.np, "loadtxt", no_parse)
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert "scope.csv: more than 1000 data rows from line" in err


def test_a_device_is_not_an_export(tmp_path, capsys):
    setup = write_setup(tmp_path / "SETUP.toml", setup_doc())
    assert main(["import", "/dev/zero", "--setup", str(setup), "-o", str(tmp_path / "o.h5")]) == 2
    assert "/dev/zero: is not a regular file (a device or a pipe)" in capsys.readouterr().err


def test_non_numeric_cell_names_line_and_column(tmp_path, scope_csv, capsys):
    lines = scope_csv.read_text().splitlines()
    cells = lines[3000].split(",")
    cells[2] = "overload"
    lines[3000] = ",".join(cells)
    scope_csv.write_text("\n".join(lines) + "\n")
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert "scope.csv: line 3001, column 'CH2' (number 3): 'overload' is not a number" in err


@pytest.mark.parametrize("edit, words", [
    (lambda cells: cells[:2], "has 2 fields"),  # a row cut short
    (lambda cells: cells[:2] + ["overload"] + cells[3:], "is not a row of numbers ('"),
])
def test_a_damaged_row_near_the_end_is_named_by_its_line(tmp_path, scope_csv, capsys, edit, words):
    lines = scope_csv.read_text().splitlines()
    k = len(lines) - 5  # among the last lines, where the layout is read from
    ncols = len(lines[k].split(","))
    lines[k] = ",".join(edit(lines[k].split(",")))
    scope_csv.write_text("\n".join(lines) + "\n")
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert f"scope.csv: line {k + 1} {words}" in err, err
    assert f"where the rows around it are {ncols} numbers each" in err, err


@pytest.mark.parametrize("footer", [["End"], ["End of data", "Points: 6500"]])
def test_a_footer_after_the_rows_is_named_by_its_line(tmp_path, scope_csv, capsys, footer):
    """A footer after the data: refused as "not rows of numbers in any of the usual layouts: is it an oscilloscope
    export?", which named no line; now its first line, and what to do."""
    lines = scope_csv.read_text().splitlines()
    scope_csv.write_text("\n".join(lines + footer) + "\n")
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert f"scope.csv: line {len(lines) + 1} follows the last row of numbers and is not one ('{footer[0]}')" in err
    assert "a footer; delete it" in err


def test_a_damaged_row_is_found_by_its_place_not_by_its_text(tmp_path):
    """A flat signal: every row the same, one cut short, whose text is the start of every later row; and a footer
    after the data, which is not a damaged row: named as a footer, by its line."""
    from friction_uq.acquisition.delimited import read_delimited

    rows = ["time,a,b"] + ["0.000,0.000,0.000"] * 100
    rows[91] = "0.000,0.000"
    for name, end in (("lf", "\n"), ("crlf", "\r\n")):
        path = tmp_path / f"flat-{name}.csv"
        path.write_bytes(end.join(rows).encode() + end.encode())
        with pytest.raises(ScopeFileError, match=r"line 92 has 2 fields, where the rows around it are 3 numbers"):
            read_delimited(path, [1, 2])
    footer = tmp_path / "footer.csv"
    footer.write_text("\n".join(["time,a,b"] + [f"{k},1,2" for k in range(100)] + ["END OF DATA"]) + "\n")
    with pytest.raises(ScopeFileError, match=r"line 102 follows the last row of numbers and is not one \('END OF DATA'\): "
                       r"a footer; delete it and the lines after it \(the rows before it are 3 numbers each\)$"):
        read_delimited(footer, [1, 2])


def test_unequal_lengths_are_named(tmp_path, capsys):
    files = export_record(RECORD, tmp_path, strain_per_volt=SPV, names=COLUMNS, per_channel=True)
    files[2].write_text("\n".join(files[2].read_text().splitlines()[:-100]) + "\n")
    err = _refused(tmp_path, files, setup_doc(files={g: f"{c}.csv" for g, c in COLUMNS.items()}), capsys)
    assert "CH3.csv: column 'CH3' (number 2) (external_output_bar) has 6400 samples but" in err
    assert "must have equal lengths" in err


def test_unknown_unit_is_named(tmp_path, scope_csv, capsys):
    doc = setup_doc()
    doc["channels"]["tube_hoop"]["units"] = "mv"
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "SETUP.toml: [channels.tube_hoop] units: is 'mv'; allowed: V, mV, strain, microstrain" in err


def _units_row(csv: Path, row: str) -> None:
    lines = csv.read_text().splitlines()
    at = lines.index("s,V,V,V,V")
    lines[at] = row
    csv.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("row, key, words", [
    ("s,V,mV,V,V", "[channels.internal_output_bar] units: is 'V', but",
     "gives column 'CH2' (number 3) in mV by its units row (line 7); write units = \"mV\""),
    ("(us),(V),(V),(V),(V)", "[time] units: is 's', but",
     "gives the time column 'Time' (number 1) in us by its units row (line 7); write [time] units = \"us\""),
    ("second,Volt,Volt,uV,Volt", "[channels.external_output_bar] units: is 'V', but",
     "in uV by its units row (line 7); write the channel's numbers in V or mV (SETUP.toml has no uV)"),
    ("s,s,V,V,V", "[channels.input_bar] units: is 'V', but",
     "in s by its units row (line 7); the file gives its unit as s, a time: is it the time column?"),
])
def test_a_unit_the_file_writes_against_the_one_declared_is_refused(tmp_path, scope_csv, capsys, row, key, words):
    """A units row that says otherwise than SETUP.toml: a thousand or a million times off, refused naming both."""
    _units_row(scope_csv, row)
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert key in err and words in err, err


@pytest.mark.parametrize("row, words", [
    ("(us),,,,", "[time] units: is 's', but"),  # the empty cells at its end (the split drops them)
    ("s,V,mV", "[channels.internal_output_bar] units: is 'V', but"),  # fewer cells than columns
    ("s,V,V,(A),V", "[channels.external_output_bar] units: is 'V', but"),  # a current probe's column
    ("s,V,mV,V,V\n,,,,", "[channels.internal_output_bar] units: is 'V', but"),  # a line of delimiters before the data
])
def test_a_units_row_however_it_is_cut_is_read(tmp_path, scope_csv, capsys, row, words):
    """A reviewer's cases, each imported as if it held volts and seconds: a units row whose empty cells at its end
    the split drops, one shorter than the header, a unit that is no gauge's, a line of delimiters below it."""
    _units_row(scope_csv, row)
    assert words in _refused(tmp_path, [scope_csv], setup_doc(), capsys)


def test_a_unit_read_from_a_name_beside_a_units_row_is_said_to_come_from_the_name(tmp_path, scope_csv, capsys):
    _units_row(scope_csv, "s,V,,V,V")  # the units row says nothing of CH2; its name does
    scope_csv.write_text(scope_csv.read_text().replace("Time,CH1,CH2,CH3,CH4", "Time,CH1,CH2 [mV],CH3,CH4"))
    doc = setup_doc()
    doc["channels"]["internal_output_bar"]["column"] = "CH2 [mV]"
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "gives column 'CH2 [mV]' (number 3) in mV by its name;" in err, err


def test_columns_by_number_take_their_names_and_units_from_the_header_not_the_units_row(tmp_path, scope_csv, capsys):
    """With columns given by number, the message named column 3 after its units-row cell ("column 'mV'"), and a
    header "Time (us)" was not read."""
    _units_row(scope_csv, "s,V,mV,V,V")
    doc = setup_doc(time={"column": 1})
    for k, g in enumerate(COLUMNS, start=2):
        doc["channels"][g]["column"] = k
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "gives column 'CH2' (number 3) in mV by its units row (line 7)" in err, err
    text = scope_csv.read_text().replace("s,V,mV,V,V\n", "\n")  # no units row: the header's names say it
    scope_csv.write_text(text.replace("Time,CH1,CH2,CH3,CH4", "Time (us),CH1,CH2,CH3,CH4"))
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "[time] units: is 's', but" in err and "in us by its name" in err, err


def test_a_unit_in_a_column_name_is_read_and_a_row_of_other_words_is_not_a_units_row(tmp_path, scope_csv, capsys):
    _units_row(scope_csv, "Channel,probe 10:1,probe 10:1,probe 1:1,probe 1:1")  # words, not units: nothing said
    text = scope_csv.read_text().replace("Time,CH1,CH2,CH3,CH4", "Time (s),CH1,CH2 [mV],CH3,CH4")
    scope_csv.write_text(text)
    doc = setup_doc(time={"column": "Time (s)"})
    doc["channels"]["internal_output_bar"]["column"] = "CH2 [mV]"
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "gives column 'CH2 [mV]' (number 3) in mV by its name; write units = \"mV\"" in err, err
    doc["channels"]["internal_output_bar"]["units"] = "mV"
    doc["channels"]["internal_output_bar"]["strain_per_volt"] = SPV["internal_output_bar"] * 1e3  # (the volts written, read as mV)
    import_scope_files([scope_csv], parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    assert_same_analysis(RECORD, tmp_path / "r.h5")


def test_a_gap_in_the_time_column_is_named(tmp_path, scope_csv, capsys):
    lines = scope_csv.read_text().splitlines()
    del lines[2000:2010]
    scope_csv.write_text("\n".join(lines) + "\n")
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert "scope.csv: line 2001: the time column 'Time' is not evenly spaced" in err


def test_sample_rate_instead_of_a_time_column(tmp_path):
    strains, rate, t0 = gauge_signals(RECORD)
    csv = write_scope_csv(tmp_path / "no_time.txt", None, {COLUMNS[g]: e / SPV[g] for g, e in strains.items()},
                          delimiter="\t", preamble=())
    doc = setup_doc(time={"sample_rate": rate, "t0": t0})
    for i, c in enumerate(doc["channels"].values()):
        c["column"] = i + 1  # by number
    import_scope_files([csv], parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    assert_same_analysis(RECORD, tmp_path / "r.h5")


# ---- gauges that contradict the others: named with the evidence, at import and in inspect ------------


@pytest.mark.parametrize("fault, channel, words", [
    ({"signs": {"external_output_bar": -1}}, "external_output_bar", "reads tension through the loading"),
    ({"signs": {"input_bar": -1}}, "input_bar", "the first pulse is a tension"),
    ({"spv": {**SPV, "internal_output_bar": 2e-3}}, "internal_output_bar", "times too large"),
    ({"spv": {**SPV, "external_output_bar": 1e-3}}, "external_output_bar", "times too large"),
    ({"spv": {**SPV, "input_bar": 2e-3}}, "input_bar", "times what the striker's 9.9 m/s gives"),
    ({"signs": {"tube_hoop": -1}}, "tube_hoop", "reads the tube contracting through the loading"),
    ({"spv": {**SPV, "tube_hoop": 5e-4}}, "tube_hoop", "times too much"),
])
def test_a_gauge_contradicting_the_others_is_named(tmp_path, scope_csv, capsys, fault, channel, words):
    err = _refused(tmp_path, [scope_csv], setup_doc(**fault), capsys)
    assert f"scope.csv: column '{COLUMNS[channel]}'" in err and f"[channels.{channel}]" in err and words in err
    if "times too large" in words or "striker" in words:  # the factor found is the one put in (within a few %)
        assert 8.5 < float(re.search(r"(\d+\.?\d*) times", err).group(1)) < 11.5
    # written anyway on request, inspect names it too
    setup = tmp_path / "SETUP.toml"
    assert main(["import", str(scope_csv), "--setup", str(setup), "-o", str(tmp_path / "w.h5"), "--no-check"]) == 0
    assert "WARNING" in capsys.readouterr().out
    assert main(["inspect", str(tmp_path / "w.h5")]) == 0
    out = capsys.readouterr().out
    assert "GAUGE FAULT" in out and channel in out.split("GAUGE FAULT", 1)[1]


def test_input_scale_without_the_striker_speed_names_both_candidates(tmp_path, scope_csv, capsys):
    doc = setup_doc(spv={**SPV, "input_bar": 2e-3})
    del doc["record"]["striker_velocity"]
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "either /signals/input_bar looks" in err and "or /signals/internal_output_bar" in err
    assert "either /signals/input_bar looks 10" in err and "times too large or /signals/internal_output_bar 11" in err
    v_s = float(re.search(r"stands for a striker at (\d+) m/s", err).group(1))
    assert 90 < v_s < 110  # ten times the 9.9 m/s fired: the input gauge is the one off


def test_a_wrong_striker_speed_with_gauges_that_agree_is_a_note_not_a_refusal(tmp_path, scope_csv, capsys):
    """A light gate read 6 m/s for a 9.9 m/s shot: the incident wave disagrees with it by 1.6, but the output forces
    balance the input force and the ends' velocities agree, so no gauge is off. It was refused, the input gauge
    blamed; now imported, with a warning that names the speed recorded."""
    doc = setup_doc()
    doc["record"]["striker_velocity"] = 6.0
    setup = write_setup(tmp_path / "SETUP.toml", doc)
    assert main(["import", str(scope_csv), "--setup", str(setup), "-o", str(tmp_path / "r.h5")]) == 0
    out = capsys.readouterr().out
    assert "WARNING: the incident wave stands for a striker at 9." in out and "says 6 m/s" in out
    assert main(["inspect", str(tmp_path / "r.h5")]) == 0
    out = capsys.readouterr().out
    assert "GAUGE FAULT" not in out and "gauges      signs agree" in out and "the speed recorded looks wrong" in out


def test_swapped_output_channels_are_named(tmp_path, scope_csv, capsys):
    doc = setup_doc()
    ch = doc["channels"]
    ch["internal_output_bar"]["column"], ch["external_output_bar"]["column"] = "CH3", "CH2"
    ch["internal_output_bar"]["strain_per_volt"], ch["external_output_bar"]["strain_per_volt"] = 1e-4, 2e-4
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert "look swapped" in err and "exchange the column" in err


def test_a_sound_record_passes_inspect_quietly(capsys):
    assert main(["inspect", str(RECORD)]) == 0
    out = capsys.readouterr().out
    assert "GAUGE FAULT" not in out and "gauges      signs agree" in out


def test_template_prints(capsys):
    assert main(["import", "--template"]) == 0
    assert tomllib.loads(capsys.readouterr().out)["channels"]["input_bar"]["bridge"] == "half"


def test_bundled_scope_example_is_the_bundled_record(tmp_path, capsys):
    """data/scope/ (docs/import.md's example) imports into a record that analyses as data/A/A-03.h5."""
    scope = ROOT / "data" / "scope"
    out = tmp_path / "A-03.h5"
    assert main(["import", str(scope / "A-03_scope.csv"), "--setup", str(scope / "SETUP.toml"), "-o", str(out)]) == 0
    assert "WARNING" not in capsys.readouterr().out
    with h5py.File(out) as fh:
        assert fh["signals/input_bar"].attrs["sign_applied"] == -1
        assert fh["signals/input_bar"].attrs["strain_per_volt"] == pytest.approx(2e-4)  # from the bridge
    assert_same_analysis(RECORD, out)


def test_show_says_what_a_file_holds(capsys):
    """import --show: the layout, the lines above the data and each column, to write SETUP.toml from."""
    assert main(["import", str(ROOT / "data" / "scope" / "A-03_scope.csv"), "--show"]) == 0
    out = capsys.readouterr().out
    assert "comma-separated, decimal mark '.'; 7 line(s) before the data, data from line 8, 6500 rows" in out
    assert "line 6: Time, CH1, CH2, CH3, CH4" in out and "column names from line 6" in out
    assert "'Time'" in out and "(evenly increasing: a time column?)" in out.split("'CH1'")[0]


def test_show_lists_tdms_channels(tmp_path, capsys):
    nptdms = pytest.importorskip("nptdms")
    path = tmp_path / "shot.tdms"
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment([nptdms.ChannelObject("scope", "CH1", np.zeros(100), properties={"wf_increment": 2e-7})])
    assert main(["import", str(path), "--show"]) == 0
    assert '"scope/CH1"  100 samples, every 2e-07 s from 0 s' in capsys.readouterr().out


def test_windows_tsv_in_microseconds_and_millivolts(tmp_path):
    """Tab-separated, decimal commas, CRLF line ends, a Latin-1 'µs' in the units row, time in
    microseconds, one channel in millivolts: the layout of a European PC's export."""
    strains, rate, t0 = gauge_signals(RECORD)
    n = len(strains["input_bar"])
    volts = {COLUMNS[g]: e / SPV[g] for g, e in strains.items()}
    volts["CH2"] = volts["CH2"] * 1e3  # millivolts
    rows = np.column_stack([(t0 + np.arange(n) / rate) * 1e6, *volts.values()])
    body = "\r\n".join("\t".join(f"{v:.9e}" for v in r) for r in rows).replace(".", ",")
    head = "Oscilloscope\tPicoScope 4424\r\n\r\nZeit\tCH1\tCH2\tCH3\tCH4\r\n(µs)\t(V)\t(mV)\t(V)\t(V)\r\n"
    text = head + body + "\r\n"
    path = tmp_path / "shot.txt"
    path.write_bytes(text.encode("latin-1"))
    doc = setup_doc(time={"column": "Zeit", "units": "us"})
    doc["channels"]["internal_output_bar"]["units"] = "mV"
    import_scope_files([path], parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    assert_same_analysis(RECORD, tmp_path / "r.h5")


def test_bundled_scope_csv_is_a_fresh_export_of_the_bundled_record():
    import subprocess
    import sys

    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "make_scope_example.py"), "--check"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "identical to a fresh export" in r.stdout, r.stdout + r.stderr


def test_channels_already_in_strain_and_microstrain(tmp_path):
    """An amplifier that outputs strain: units strain and microstrain, stored as given (sign applied)."""
    strains, rate, t0 = gauge_signals(RECORD)
    cols = {"CH1": -strains["input_bar"], "CH2": strains["internal_output_bar"] * 1e6,
            "CH3": strains["external_output_bar"] * 1e6, "CH4": strains["tube_hoop"]}
    n = len(cols["CH1"])
    csv = write_scope_csv(tmp_path / "strain.csv", t0 + np.arange(n) / rate, cols, preamble=("Amplifier,strain out",),
                          units=("strain", "microstrain", "microstrain", "strain"))
    doc = setup_doc()
    units = {"input_bar": "strain", "internal_output_bar": "microstrain", "external_output_bar": "microstrain",
             "tube_hoop": "strain"}
    for g, c in doc["channels"].items():
        del c["strain_per_volt"]
        c["units"] = units[g]
    doc["channels"]["input_bar"]["sign"] = -1
    import_scope_files([csv], parse_setup(doc, path=tmp_path / "SETUP.toml"), tmp_path / "r.h5")
    with h5py.File(tmp_path / "r.h5") as fh:
        assert fh["signals/internal_output_bar"].attrs["units"] == "microstrain"
        assert "strain_per_volt" not in fh["signals/input_bar"].attrs
    assert_same_analysis(RECORD, tmp_path / "r.h5")
    doc["channels"]["tube_hoop"]["strain_per_volt"] = 1e-4
    with pytest.raises(SetupError, match=r"\[channels.tube_hoop\] strain_per_volt: applies to channels in V or mV"):
        parse_setup(doc, path=tmp_path / "SETUP.toml")


# ---- TDMS channels and properties, rows of another length, the time base's source -------------------


def _tdms(path: Path, *, data: dict | None = None, props: dict | None = None) -> Path:
    """A TDMS file of A-03's gauges in volts, group 'scope', channels CH1..CH4 with their time base; ``data`` and
    ``props`` replace a channel's samples or properties."""
    nptdms = pytest.importorskip("nptdms")
    strains, rate, t0 = gauge_signals(RECORD)
    chans = []
    for g, eps in strains.items():
        c = COLUMNS[g]
        p = {"wf_increment": 1.0 / rate, "wf_start_offset": t0, **(props or {}).get(c, {})}
        chans.append(nptdms.ChannelObject("scope", c, (data or {}).get(c, eps / SPV[g]), properties=p))
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment([nptdms.RootObject(), nptdms.GroupObject("scope"), *chans])
    return path


def _tdms_doc() -> dict:
    doc = setup_doc()
    del doc["time"]  # TDMS carries its time base
    for g, c in COLUMNS.items():
        doc["channels"][g]["column"] = f"scope/{c}"
    return doc


@pytest.mark.parametrize("values, what", [
    (lambda v: np.resize(np.array(["a", "b"]), v.size), "text"),
    (lambda v: v > 0, "booleans"),  # would import as 0 and 1 V
    (lambda v: v.astype(np.complex128), "complex numbers"),  # would import with a ComplexWarning
])
def test_a_tdms_channel_of_other_than_real_numbers_is_refused(tmp_path, capsys, values, what):
    strains, _, _ = gauge_signals(RECORD)
    path = _tdms(tmp_path / "shot.tdms",
                 data={"CH2": values(strains["internal_output_bar"] / SPV["internal_output_bar"])})
    err = _refused(tmp_path, [path], _tdms_doc(), capsys)
    assert f"shot.tdms: channel 'scope/CH2' holds {what}, not numeric samples" in err, err


@pytest.mark.parametrize("prop, value, words", [
    ("wf_increment", "abc", "must be a number (seconds), got 'abc'"),
    ("wf_increment", "2e-7", "must be a number (seconds), got '2e-7'"),  # was read as 2e-7
    ("wf_start_offset", "abc", "must be a number (seconds), got 'abc'"),
    ("wf_increment", float("nan"), "must be a finite number (seconds), got nan"),  # was accepted
    ("wf_increment", -2e-7, "must be positive (the time between two samples, s), got -2e-07"),
    ("wf_increment", 2e-16, "2e-16 s between samples is a sample rate that is 5000000000000000.0 Hz, outside"),
    ("wf_start_offset", 5.0, "the start is 5.0 s, outside the plausible range [-1, 1] s"),
])
def test_a_tdms_time_property_is_checked_and_named(tmp_path, capsys, prop, value, words):
    path = _tdms(tmp_path / "shot.tdms", props={"CH2": {prop: value}})
    err = _refused(tmp_path, [path], _tdms_doc(), capsys)
    assert f"shot.tdms: channel 'scope/CH2' property {prop}: {words}" in err, err


def test_show_names_a_tdms_time_property_that_is_not_a_number(tmp_path, capsys):
    path = _tdms(tmp_path / "shot.tdms", props={"CH3": {"wf_increment": "abc"}})
    assert main(["import", str(path), "--show"]) == 2
    err = capsys.readouterr().err
    assert "shot.tdms: channel 'scope/CH3' property wf_increment: must be a number (seconds), got 'abc'" in err
    assert err.count("\n") == 1


def test_tdms_lengths_are_checked_from_the_metadata_before_any_sample_is_read(tmp_path, capsys, monkeypatch):
    nptdms = pytest.importorskip("nptdms")
    path = _tdms(tmp_path / "shot.tdms", data={"CH1": np.zeros(1_000_001)})

    def no_data(*args, **kwargs):
        raise AssertionError("samples were read before the lengths were checked")

    monkeypatch.setattr(nptdms.TdmsFile, "read", no_data)
    monkeypatch.setattr(nptdms.tdms.TdmsChannel, "__getitem__", no_data)
    monkeypatch.setattr(nptdms.tdms.TdmsChannel, "read_data", no_data)
    err = _refused(tmp_path, [path], _tdms_doc(), capsys)
    assert "shot.tdms: channel 'scope/CH1' declares 1000001 samples, more than the 1000000 a record may hold" in err
    assert main(["import", str(path), "--show"]) == 0  # --show reads the metadata alone
    assert '"scope/CH1"  1000001 samples, every 2e-07 s' in capsys.readouterr().out


@pytest.mark.parametrize("edit, fields, drop_hoop", [
    (lambda c: c[:2] + ["0.0"] + c[2:], 6, False),  # a field inserted: CH2 would read 0, CH3 CH2's value
    (lambda c: c + ["0.0"], 6, False),  # a field too many at the end
    (lambda c: c[:2] + c[3:], 4, True),  # a field lost in the middle, the last column unused: CH3 would read CH4
])
def test_a_row_with_another_number_of_fields_is_refused(tmp_path, scope_csv, capsys, edit, fields, drop_hoop):
    lines = scope_csv.read_text().splitlines()
    lines[3506] = ",".join(edit(lines[3506].split(",")))
    scope_csv.write_text("\n".join(lines) + "\n")
    doc = setup_doc()
    if drop_hoop:
        del doc["channels"]["tube_hoop"]
    err = _refused(tmp_path, [scope_csv], doc, capsys)
    assert f"scope.csv: line 3507 has {fields} fields where the data rows have 5" in err, err


def test_a_non_finite_time_is_named_by_its_line(tmp_path, scope_csv, capsys):
    lines = scope_csv.read_text().splitlines()
    lines[3000] = "nan" + lines[3000][lines[3000].index(","):]
    scope_csv.write_text("\n".join(lines) + "\n")
    err = _refused(tmp_path, [scope_csv], setup_doc(), capsys)
    assert "scope.csv: line 3001: the time column 'Time' holds nan, not a finite time" in err, err


@pytest.mark.parametrize("time, words", [
    ({"sample_rate": 1e300, "t0": -8e-5}, "SETUP.toml: [time] sample_rate: is 1e+300 Hz, outside the plausible"),
    ({"sample_rate": 5e6, "t0": 5.0}, "SETUP.toml: [time] t0: is 5.0 s, outside the plausible range"),
    ({"column": "Time", "units": "ns"}, "SETUP.toml: [time] units: the sample rate from the time column 'Time' of "),
])
def test_an_implausible_time_base_names_the_setup_key(tmp_path, scope_csv, capsys, time, words):
    _units_row(scope_csv, "")  # no units row: the time base's own range is what refuses "ns"
    err = _refused(tmp_path, [scope_csv], setup_doc(time=time), capsys)
    assert words in err, err


def _scope_files(tmp_path: Path, writer, suffix: str, **kw) -> list[Path]:
    strains, rate, t0 = gauge_signals(RECORD)
    return [writer(tmp_path / f"CH{i + 1}{suffix}", eps / SPV[g], 1.0 / rate, t0, **kw)
            for i, (g, eps) in enumerate(strains.items())]


def _one_per_channel(files: list[Path]) -> dict:
    doc = setup_doc(files={g: f.name for g, f in zip(COLUMNS, files)})
    del doc["time"]
    for c in doc["channels"].values():
        c["column"] = 1
    return doc


@pytest.mark.parametrize("dt", [0.0, -2e-7, float("nan"), float("inf")])
def test_a_binary_files_sample_interval_that_is_no_time_base_is_named(tmp_path, capsys, dt):
    """A damaged header's 0, negative, NaN or infinite sample interval: once an internal error (a division by zero in
    the rate's rounding), or listed by --show as if sound."""
    pytest.importorskip("lecroyparser")
    pytest.importorskip("RigolWFM")
    trc = _scope_files(tmp_path, _trc, ".trc")
    trc[1] = _trc(trc[1], np.ones(100), dt, 0.0)
    err = _refused(tmp_path, trc, _one_per_channel(trc), capsys)
    assert "CH2.trc: the descriptor's HORIZ_INTERVAL: the sample interval is" in err and "positive number" in err
    if math.isfinite(dt):  # the ISF preamble prints the interval as text; a non-finite one is not written
        isf = tmp_path / "isf"
        isf.mkdir()
        files = _scope_files(isf, _isf, ".isf", name="Ch")
        files[1] = _isf(files[1], np.linspace(0, 1, 100), dt, 0.0, "Ch2")
        assert main(["import", str(files[1]), "--show"]) == 2
        assert "CH2.isf: channel" in capsys.readouterr().err
        err = _refused(isf, files, _one_per_channel(files), capsys)
        assert "the sample interval is" in err


def test_a_setup_file_with_a_key_of_50000_dotted_parts_is_refused_before_parsing(tmp_path, scope_csv, capsys):
    """Such a file of 100 kB took the TOML parser about a minute and 10 GB; the depth is checked first."""
    setup = tmp_path / "deep.toml"
    setup.write_text(".".join(["a"] * 50_000) + "=1\n")
    assert main(["import", str(scope_csv), "--setup", str(setup), "-o", str(tmp_path / "out.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "has a dotted key of more than" in err and not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize("keep", [0.5, 0.97])
def test_a_damaged_tdms_file_is_said_in_one_sentence(tmp_path, capfd, keep):
    """npTDMS's own warnings on a truncated file (printed to stderr before the refusal) are not printed; the refusal
    names the first of them. A file cut near its end reads without an error but with a warning: refused too (its
    samples are not all those recorded; they were imported silently)."""
    path, doc = _tdms_shot(tmp_path)
    path.write_bytes(path.read_bytes()[: int(path.stat().st_size * keep)])
    setup = write_setup(tmp_path / "SETUP.toml", doc)
    assert main(["import", str(path), "--setup", str(setup), "-o", str(tmp_path / "r.h5")]) == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "npTDMS warned" in err and not (tmp_path / "r.h5").exists()
    assert main(["import", str(path), "--show"]) == 0
    assert "npTDMS warned: " in capfd.readouterr().out


def test_an_import_never_replaces_its_own_input(tmp_path, scope_csv, capsys):
    """A scope export named shot.h5, imported with -o shot.h5 --overwrite, was replaced by the record."""
    shot = tmp_path / "shot.h5"
    shot.write_bytes(scope_csv.read_bytes())
    setup = write_setup(tmp_path / "SETUP.toml", setup_doc())
    assert main(["import", str(shot), "--setup", str(setup), "-o", str(shot), "--overwrite"]) == 2
    assert "is one of the files being imported" in capsys.readouterr().err
    assert shot.read_bytes() == scope_csv.read_bytes()


def test_a_column_name_the_header_gives_twice_is_refused(tmp_path, scope_csv, capsys):
    """A header Time,CH1,CH2,CH3,CH4,CH2: column 'CH2' was taken as the first of the two, silently."""
    lines = scope_csv.read_text().splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("Time"))
    lines[head] += ",CH2"
    lines[head + 1:] = [ln + "," + ln.split(",")[3] if ln.strip() else ln for ln in lines[head + 1:]]
    dup = tmp_path / "dup.csv"
    dup.write_text("\n".join(lines) + "\n")
    err = _refused(tmp_path, [dup], setup_doc(), capsys)
    assert "dup.csv: column 'CH2' is the name of columns 3, 6 on the header line" in err


def test_a_file_name_two_of_the_files_given_share_is_refused(tmp_path, scope_csv, capsys):
    """a/scope.csv and b/scope.csv given, a channel's file = "scope.csv": the first was taken, silently."""
    for d in "ab":
        (tmp_path / d).mkdir()
        (tmp_path / d / "scope.csv").write_bytes(scope_csv.read_bytes())
    files = [tmp_path / "a" / "scope.csv", tmp_path / "b" / "scope.csv"]
    doc = setup_doc(files={g: "scope.csv" for g in COLUMNS})
    err = _refused(tmp_path, files, doc, capsys)
    assert "file: 'scope.csv' names 2 of the files given" in err
