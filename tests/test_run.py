"""The main job end to end, as a user runs it: outputs, their content, refusals, atomicity."""

import hashlib
import json
import math

import pytest
import xarray as xr

from friction_uq.cli import main
from friction_uq.synthetic import ClosedFormTest, write_closed_form_record

JSON_KEYS = ("f", "nu", "kappa", "p_mean", "tau_mean", "V", "ratio")
STATS = ("mean", "sd", "q05", "q50", "q95")


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory):
    """The paper's case (V_s = 10 m/s, f = 0.05, nu = 0.4) run through the CLI with the default priors."""
    d = tmp_path_factory.mktemp("run")
    rec = write_closed_form_record(d / "paper.h5", ClosedFormTest(f=0.05, nu=0.4), seed=2016,
                                   test_id="P-01", campaign="paper")
    out = d / "reports"
    code = main(["run", str(rec), "--out", str(out), "--seed", "7", "--quiet"])
    return code, out, rec


def test_run_writes_the_three_outputs(paper_run):
    code, out, _ = paper_run
    assert code == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["paper_P-01.json", "paper_P-01.nc", "paper_P-01.pdf"]  # no temporary or backend left


def test_json_has_the_contract_keys(paper_run):
    _, out, rec = paper_run
    # strict JSON (RFC 8259): no NaN or Infinity, which JavaScript's JSON.parse and most parsers refuse
    doc = json.loads((out / "paper_P-01.json").read_text(), parse_constant=lambda name: pytest.fail(name))
    for k in JSON_KEYS:
        assert set(STATS) <= set(doc[k]), k
        assert doc[k]["q05"] <= doc[k]["q50"] <= doc[k]["q95"]
    for k in ("window", "rhat_max", "ess_min", "seed", "seconds"):
        assert k in doc
    assert doc["seed"] == 7
    assert doc["rhat_max"] < 1.01 and doc["ess_min"] > 400
    # the record's checksum: what a campaign compares to skip an up-to-date record
    assert doc["record_sha256"] == hashlib.sha256(rec.read_bytes()).hexdigest()
    # kappa is the product the forces fix
    assert doc["kappa"]["q50"] == pytest.approx(doc["f"]["q50"] * doc["nu"]["q50"] / (1 - doc["nu"]["q50"]), rel=0.02)


def test_analysis_settings_are_in_the_provenance(paper_run):
    """The frozen settings the likelihood was built from, in the JSON and the DataTree's root attrs."""
    _, out, _ = paper_run
    want = {"window": None, "dispersion": False, "hoop": True, "hoop_mode": "level", "axial_poisson": True,
            "hoop_discrepancy": 0.03, "force_mode": "level", "ratio_model_form": 0.025}
    assert json.loads((out / "paper_P-01.json").read_text())["analysis_settings"] == want
    dt = xr.open_datatree(out / "paper_P-01.nc", engine="h5netcdf")
    assert json.loads(dt.attrs["analysis_settings"]) == want


def test_the_papers_case_contains_0049(paper_run):
    """docs/physics.md: F_eo/F_io ~ 0.14 gives f ~ 0.049 with nu = 0.4; the 90 % interval must contain it."""
    _, out, _ = paper_run
    f = json.loads((out / "paper_P-01.json").read_text())["f"]
    assert f["q05"] <= 0.049 <= f["q95"]


def test_netcdf_is_an_arviz_datatree(paper_run):
    _, out, _ = paper_run
    dt = xr.open_datatree(out / "paper_P-01.nc", engine="h5netcdf")
    for group in ("posterior", "log_likelihood", "observed_data", "sample_stats", "prior", "posterior_predictive",
                  "whole_record_observed"):
        assert group in dt.children, group
    post = dt["posterior"]
    assert post["f"].dims[:2] == ("chain", "draw")
    assert {"f", "nu", "kappa", "ratio", "p_mean", "tau_mean"} <= set(post.data_vars)
    assert dt.attrs["seed"] == 7


def test_pdf_is_a_multipage_report(paper_run):
    _, out, _ = paper_run
    data = (out / "paper_P-01.pdf").read_bytes()
    assert data[:4] == b"%PDF"
    pages = data.count(b"/Type /Page") - data.count(b"/Type /Pages")
    # summary (page 1) + pages 2-8 + page 9 (hoop gauge vs model: the hoop term was used) + 10-11 (the whole
    # test simulated against the four gauges, two per page)
    assert pages == 11


def test_pdf_pages_in_order_though_made_on_two_cores(paper_run):
    """The record's and the check's pages are made on the other core, the posterior's here: merged, every
    page stands where the summary's table of pages says."""
    from pypdf import PdfReader

    _, out, _ = paper_run
    reader = PdfReader(out / "paper_P-01.pdf")
    texts = [page.extract_text() for page in reader.pages]
    titles = ["friction-uq report", "2. Record", "3. Waves", "4. Stationary window", "5. Joint posterior",
              "6. How the uncertainty of nu", "7. Convergence", "8. Posterior predictive", "9. Tube hoop gauge",
              "10. paper P-01: the whole test simulated with the posterior",
              "11. paper P-01: the whole test simulated with the posterior"]
    assert len(texts) == len(titles)
    for k, (text, title) in enumerate(zip(texts, titles)):
        assert title in " ".join(text.split()), (k, title)  # each page's title starts with its PDF page number
    pages = texts[0][texts[0].index("Pages"):]
    for n, what in ((2, "raw gauges"), (5, "posterior vs prior"), (9, "hoop gauge vs model"),
                    ("10-11", "whole test vs gauges")):
        assert f"{n} {what}" in " ".join(pages.split()), (n, what)  # the summary's list uses the same numbers
    assert "(1/2)" in texts[9] and "(2/2)" in texts[10]
    assert "the bars' dispersion not corrected" in " ".join(texts[0].split())  # how the forces were read
    assert reader.metadata["/Title"] == "friction-uq paper P-01"
    # the window's change as the JSON gives it, in words on the first page
    doc = json.loads((out / "paper_P-01.json").read_text())
    h = doc["window_halves"]
    first = " ".join(texts[0].split())
    assert f"slides {h['slip_m'][0] * 1e3:.2f} to {h['slip_m'][1] * 1e3:.2f} mm" in first
    assert f"kappa changes by {100 * math.expm1(h['log_kappa_change']):+.1f} %" in first


def test_a_prior_file_with_a_typo_is_refused_and_nothing_is_written(paper_run, tmp_path, capsys):
    _, _, rec = paper_run
    bad = tmp_path / "bad.toml"
    bad.write_text('material = "I1"\n[f]\ndistribution = "halfnormal"\nscael = 0.3\n'
                   '[nu]\ndistribution = "uniform"\nlower = 0.2\nupper = 0.45\n')
    out = tmp_path / "out"
    assert main(["run", str(rec), "--priors", str(bad), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("friction-uq: error:")
    assert "bad.toml" in err[0] and "scael" in err[0]
    assert not out.exists() or not any(out.iterdir())


def test_no_stationary_phase_is_refused(tmp_path, capsys):
    import numpy as np

    from friction_uq.record import paper_apparatus
    from friction_uq.synthetic import closed_form_strains

    test = ClosedFormTest()
    t, strains, _ = closed_form_strains(test, paper_apparatus())
    ramp = np.clip((t - 0.2e-3) / 0.5e-3, 0, None)
    rec = write_closed_form_record(tmp_path / "drift.h5", test, seed=4,
                                   strains_override={"external_output_bar": strains["external_output_bar"] * (0.3 + 4 * ramp)})
    out = tmp_path / "out"
    assert main(["run", str(rec), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "no stationary phase" in err and "Traceback" not in err
    assert not out.exists() or not any(out.iterdir())


def test_a_dead_hoop_gauge_is_left_out_with_a_note(tmp_path, capsys):
    """A tube_hoop channel with only noise must not drive the fit (it would read as nu -> 0)."""
    import numpy as np

    test = ClosedFormTest(f=0.05, nu=0.4)
    n = int(round(test.duration * test.sample_rate))
    rec = write_closed_form_record(tmp_path / "dead.h5", test, seed=8, test_id="D-01", campaign="dead",
                                   strains_override={"tube_hoop": np.zeros(n)})
    out = tmp_path / "out"
    assert main(["run", str(rec), "--out", str(out), "--quiet", "--no-pdf"]) == 0
    assert "hoop gauge is left out of the likelihood: tube_hoop shows no" in capsys.readouterr().err
    doc = json.loads((out / "dead_D-01.json").read_text())
    assert doc["hoop_term"] is False and doc["hoop_left_out"]
    assert doc["f"]["q05"] <= 0.05 <= doc["f"]["q95"]
    assert doc["f"]["source"] == "the stationary analysis (eq. 17; the hoop gauge left out)"  # not "and the hoop"
    # the only witness of nu gone, f follows the prior file's nu: a warning, as a sample of nu near 0 reads the same
    # (a simulated nu = 0.01 was reported as f = 0.0009 for 0.05 with every check passed)
    assert any(w.startswith("The hoop gauge is left out: tube_hoop shows no pulse") for w in doc["warnings"])
    # nor the whole-record check, where its calibration prior would make a flat gauge pull nu
    channels = {fig["channel"] for fig in doc["misfit"]["figures"]}
    assert "tube_hoop" not in channels and "external_output_bar" in channels


def test_a_record_without_a_hoop_gauge_says_why_the_term_is_off(tmp_path, capsys):
    """The JSON said "hoop_term": false with no reason while its settings asked for the hoop."""
    import h5py

    rec = write_closed_form_record(tmp_path / "bare.h5", ClosedFormTest(f=0.05, nu=0.4), seed=8, test_id="N-01",
                                   campaign="bare")
    with h5py.File(rec, "r+") as fh:
        del fh["signals/tube_hoop"]
    out = tmp_path / "out"
    assert main(["run", str(rec), "--out", str(out), "--quiet", "--no-pdf"]) == 0
    assert "hoop gauge is left out of the likelihood: the record has no hoop gauge" in capsys.readouterr().err
    doc = json.loads((out / "bare_N-01.json").read_text())
    assert doc["hoop_term"] is False and "no hoop gauge (/signals/tube_hoop)" in doc["hoop_left_out"]


def test_a_reversed_hoop_gauge_is_said_as_reversed(tmp_path, capsys):
    test = ClosedFormTest(f=0.05, nu=0.4)
    rec = write_closed_form_record(tmp_path / "rev.h5", test, seed=8, test_id="R-01", campaign="rev")
    import h5py

    with h5py.File(rec, "r+") as fh:
        fh["signals/tube_hoop"][...] = -fh["signals/tube_hoop"][...]
    assert main(["run", str(rec), "--out", str(tmp_path / "o"), "--quiet", "--no-pdf"]) == 0
    err = capsys.readouterr().err
    assert "hoop gauge is left out of the likelihood: /signals/tube_hoop reads the tube contracting" in err
    assert "looks reversed" in err and "no pulse above its noise" not in err


def test_out_that_is_a_file_is_refused(paper_run, tmp_path, capsys):
    _, _, rec = paper_run
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert main(["run", str(rec), "--out", str(afile), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "must be a directory" in err and "Traceback" not in err


def test_json_names_the_checksums_and_the_nu_priors(paper_run):
    import hashlib

    _, out, _ = paper_run
    doc = json.loads((out / "paper_P-01.json").read_text())
    for key, suffix in (("netcdf", ".nc"), ("pdf", ".pdf")):
        f = out / f"paper_P-01{suffix}"
        assert doc["outputs"][key] == {"file": f.name, "sha256": hashlib.sha256(f.read_bytes()).hexdigest()}
    sens = doc["f_under_nu_priors"]
    assert sorted(sens) == ["default", "nu-tight", "nu-wide"]
    for label in ("nu-tight", "nu-wide"):
        assert sens[label]["method"] in ("reweighted", "sampled")
        # reweighted only where the Pareto k says it is reliable (S = 4000 draws: k <= 0.7)
        assert (sens[label]["method"] == "reweighted") == (sens[label]["pareto_k"] <= 0.7)
    assert doc["prior_data_conflict"]["conflict"] is False


def test_a_prior_that_overwhelms_the_data_is_said_everywhere(paper_run, tmp_path, capsys, monkeypatch):
    """f ~ half-normal(1e-9): the posterior of f is the prior's; terminal, JSON and summary page say so."""
    import matplotlib.pyplot as plt

    import friction_uq.report.pdf as report
    from friction_uq.prior_loader import default_prior_path

    _, _, rec = paper_run
    original = default_prior_path("I1").read_text()
    text = original.replace("scale = 0.3", "scale = 1e-9")
    assert text != original
    pri = tmp_path / "I1-squeezed.toml"
    pri.write_text(text)
    seen = {}
    render = report.render_report

    def keep(inputs, **parts):
        seen["inputs"] = inputs
        return render(inputs, **parts)

    monkeypatch.setattr(report, "render_report", keep)
    out = tmp_path / "out"
    assert main(["run", str(rec), "--priors", str(pri), "--out", str(out), "--quiet", "--seed", "2"]) == 0
    captured = capsys.readouterr()
    assert "note: WARNING: the priors, not the data, drive the result - f: prior dominates the data" in captured.err
    assert "WARNING: the priors, not the data, drive the result" in captured.out  # the summary table
    js = json.loads((out / "paper_P-01.json").read_text())
    assert js["prior_data_conflict"]["conflict"] is True and js["prior_data_conflict"]["flagged"] == ["f"]
    assert js["f"]["q95"] < 1e-8
    fig = report.page_summary(seen["inputs"])
    lines = [t.get_text() for t in fig.axes[0].texts]
    plt.close(fig)
    assert any(line.startswith("WARNING: the priors, not the data, drive the result - f:") for line in lines)


def test_a_uniform_prior_is_run_and_its_power_scaling_is_zero(paper_run, tmp_path):
    """The shipped sensitivity file puts a uniform prior on nu: a power of a flat prior is the same prior, so the
    posterior cannot move with it (prior sensitivity 0); before, the power-scaling check ended the run with an
    internal error after sampling, and left a checkpoint behind."""
    from friction_uq.prior_loader import PRIORS_DIR

    _, _, rec = paper_run
    out = tmp_path / "wide"
    code = main(["run", str(rec), "--out", str(out), "--seed", "7", "--quiet", "--no-pdf",
                 "--priors", str(PRIORS_DIR / "I1-nu-wide.toml")])
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == ["paper_P-01.json", "paper_P-01.nc"]
    js = json.loads((out / "paper_P-01.json").read_text())
    assert js["prior_data_conflict"]["prior_sensitivity"]["nu"] == 0.0
    assert js["prior_data_conflict"]["prior_sensitivity"]["f"] > 0.0  # the half-normal f prior is scaled as before


def test_run_file_can_run_silently(paper_run, tmp_path, capsys):
    from friction_uq.record_run import run_file

    _, _, rec = paper_run
    res = run_file(rec, out_dir=tmp_path / "o", seed=9, pdf=False, progress=False, table=False, notes=False)
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""
    assert set(res.outputs) == {"netcdf", "json"} and res.convergence.ok
    assert {"signals", "sampling", "datatree", "sensitivity", "outputs", "pdf"} <= set(res.stages)


def test_the_report_has_no_character_its_fonts_cannot_show(paper_run):
    """The PDF's standard fonts (Helvetica, Courier) encode Latin-1 only: a Unicode minus in a tick label
    shows as '?'. Every text drawn through them is checked for characters outside Latin-1."""
    import re
    import zlib

    _, out, _ = paper_run
    pdf = next(out.glob("*.pdf")).read_bytes()
    shown = b""
    for m in re.finditer(rb"stream\r?\n(.*?)\r?\nendstream", pdf, re.S):
        try:
            shown += zlib.decompress(m.group(1))
        except zlib.error:
            continue
    # text shown with the standard fonts is written as (string) Tj; a character it lacks is written as '?'
    strings = re.findall(rb"\(((?:[^()\\]|\\.)*)\)\s*Tj", shown)
    assert strings, "no text drawn with the standard fonts"
    assert any(re.fullmatch(rb"-\d[\d.]*", s) for s in strings), "no negative tick label to check"
    assert not [s for s in strings if re.fullmatch(rb"\?\d.*", s)], "a tick label lost its minus sign"


def test_the_prior_data_warning_is_said_once_as_a_warning():
    """The run's warnings are printed after "WARNING: "; the conflict's sentence carried its own: "WARNING: WARNING:"."""
    from friction_uq.prior_sensitivity import PriorDataConflict
    from friction_uq.record_run.warnings import conflict_warning

    flagged = PriorDataConflict(prior={"nu": 0.12}, likelihood={"nu": 0.05}, diagnosis={"nu": "prior-data conflict"},
                                flagged=("nu",), threshold=0.05)
    said = conflict_warning(flagged)
    assert said.startswith("The prior file and the data disagree - nu:") and "WARNING" not in said
    dominated = PriorDataConflict(prior={"f": 0.3}, likelihood={"f": 0.01}, diagnosis={"f": "prior dominates the data"},
                                  flagged=("f",), threshold=0.05)
    assert conflict_warning(dominated).startswith("The priors, not the data, drive the result - f:")


def test_a_page_title_stays_on_the_page_whatever_the_test_id():
    """A test id of 100 letters ran off both sides of every page's title, and a Hebrew or Chinese one printed as
    '?' (the standard fonts encode Latin-1 only): the title is written with escapes for what Latin-1 lacks, at
    most two lines long, wrapped within the page."""
    from friction_uq.report.style import TITLE_CHARS, TITLE_WORD, figure, title_text

    hebrew = title_text("2. Record \u05d0\u05d1 \u6f22\u5b57: gauges")
    assert hebrew == "2. Record \\u05d0\\u05d1 \\u6f22\\u5b57: gauges" and max(map(ord, hebrew)) < 256
    long = title_text("friction-uq report: " + "M" * 100 + " " + "W" * 100 + " (sample I1)")
    assert len(long) <= TITLE_CHARS + 10 and long.endswith("...") and max(map(len, long.split())) <= TITLE_WORD
    fig, _ = figure("friction-uq report: " + "M" * 64 + " A (sample I1)")
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert 0 <= box.x0 and box.x1 <= fig.bbox.x1
