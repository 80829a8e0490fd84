"""The deterministic identification on closed-form records (truth known by construction)."""

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from friction_uq.analysis import identify, prepare
from friction_uq.errors import NoStationaryPhase, SignalError
from friction_uq.record import read_record, read_truth
from friction_uq.synthetic import ClosedFormTest, closed_form_strains, write_closed_form_record
from friction_uq.record import paper_apparatus


@pytest.fixture(scope="module")
def paper_record(tmp_path_factory):
    return write_closed_form_record(tmp_path_factory.mktemp("rec") / "paper.h5", ClosedFormTest(), seed=11)


def _sd_f(prep, nu):
    """Standard error of eq. 17's f from the window's noise (AR(1) effective sample size)."""
    d = prep.data
    n_eff = d.n * (1 - d.rho_eo) / (1 + d.rho_eo)
    r = np.mean(d.F_eo) / np.mean(d.F_io)
    sd_r = np.hypot(d.sd_eo, r * d.sd_io) / np.mean(d.F_io) / np.sqrt(n_eff)
    return (1 - nu) * d.radius / (2 * nu * d.length) * sd_r / (1 + r)


@pytest.mark.parametrize("f, nu", [(0.05, 0.4), (0.2, 0.4), (0.131, 0.2), (0.01, 0.3)])
def test_identification_recovers_f_within_its_noise(tmp_path, f, nu):
    p = write_closed_form_record(tmp_path / "r.h5", ClosedFormTest(f=f, nu=nu), seed=5)
    prep = prepare(read_record(p))
    ident = identify(prep, nu=nu)
    tol = 4 * _sd_f(prep, nu)
    assert ident.f == pytest.approx(f, abs=tol)
    truth = read_truth(p)
    assert ident.ratio == pytest.approx(truth["ratio"], abs=tol * 2 * nu * 0.01 / ((1 - nu) * 0.005) * 1.5)
    assert ident.V == pytest.approx(truth["V"], rel=0.01)
    assert ident.p_mean == pytest.approx(truth["p_mean"], rel=max(0.01, 4 * _sd_f(prep, nu) / f))
    # eq. 21 approximates eq. 20 for small f beta
    assert ident.p_mean_approx == pytest.approx(ident.p_mean, rel=0.02 + f)
    assert abs(ident.equilibrium_error) < 0.01


def test_window_lies_in_the_plateau(paper_record):
    rec = read_record(paper_record)
    prep = prepare(rec)
    test = ClosedFormTest()
    a = rec.apparatus
    t_cell = a.input_bar.gauge_delay  # incident front at the gauge at t = 0
    plateau = (t_cell + test.rise_time, t_cell + a.pulse_duration - test.rise_time)
    assert plateau[0] <= prep.window.t0 < prep.window.t1 <= plateau[1]
    # most of the plateau is found
    assert prep.window.duration > 0.8 * (plateau[1] - plateau[0])


def test_noise_levels_recovered_within_ten_percent(paper_record):
    prep = prepare(read_record(paper_record))
    truth = read_truth(paper_record)
    for ch in ("internal_output_bar", "external_output_bar"):
        assert prep.forces.channels[ch].noise.sd == pytest.approx(truth[f"noise_sd_{ch}"], rel=0.10)


def test_manual_window_overrides(paper_record):
    rec = read_record(paper_record)
    prep = prepare(rec, window=(4.0e-4, 5.0e-4))
    assert prep.window.t0 == pytest.approx(4.0e-4, abs=rec.sample_interval)
    assert not prep.window.automatic
    given = rf"^{re.escape(str(rec.path))}: the window given by hand \(--window\) "  # the record and the option
    with pytest.raises(SignalError, match=given + r"-1\.0:0\.0005 s lies outside the record"):
        prepare(rec, window=(-1.0, 5.0e-4))
    with pytest.raises(SignalError, match=given + r"0\.0005:0\.0004 s: T1 must be after T0"):
        prepare(rec, window=(5.0e-4, 4.0e-4))
    with pytest.raises(SignalError, match="outside the time where F_io is valid"):
        prepare(rec, window=(1.1e-3, 1.2e-3))
    with pytest.raises(SignalError, match="the cell is not loaded there"):
        prepare(rec, window=(-5e-5, 1e-4))


def test_a_drifting_ratio_has_no_stationary_phase(tmp_path):
    """F_eo keeps growing through the plateau: the criterion must refuse the record."""
    test = ClosedFormTest()
    app = paper_apparatus()
    t, strains, _ = closed_form_strains(test, app)
    eo = app.external_output_bar
    ramp = np.clip((t - 0.2e-3) / 0.5e-3, 0, None)
    strains_eo = strains["external_output_bar"] * (0.3 + 4.0 * ramp)
    p = write_closed_form_record(tmp_path / "drift.h5", test, seed=2,
                                 strains_override={"external_output_bar": strains_eo})
    with pytest.raises(NoStationaryPhase, match="no stationary phase"):
        prepare(read_record(p))
    del eo


def test_dispersion_option_changes_little_on_slow_fronts(paper_record):
    rec = read_record(paper_record)
    a = identify(prepare(rec), nu=0.4)
    b = identify(prepare(rec, dispersion=True), nu=0.4)
    assert b.f == pytest.approx(a.f, rel=0.02)


def test_analyze_json_cli(paper_record, capsys):
    from friction_uq.cli import main

    assert main(["analyze", str(paper_record), "--nu", "0.4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("f", "ratio", "p_mean", "p_min", "p_max", "tau_mean", "V", "window"):
        assert key in out
    assert out["f"] == pytest.approx(0.05, abs=0.003)
    assert len(out["window"]) == 2
    # how the record was read, so that the file alone reproduces it
    assert out["window_automatic"] is True and out["dispersion_correction"] is False


def test_a_reversed_output_gauge_is_refused(tmp_path):
    test = ClosedFormTest()
    _, strains, _ = closed_form_strains(test, paper_apparatus())
    p = write_closed_form_record(tmp_path / "rev.h5", test, seed=3,
                                 strains_override={"external_output_bar": -strains["external_output_bar"]})
    with pytest.raises(SignalError, match=r"rev\.h5: /signals/external_output_bar reads tension through the "
                                          r"loading .* looks reversed"):
        prepare(read_record(p))


def test_every_gauge_read_a_thousand_times_small_is_said_not_passed(tmp_path, capsys):
    """All four channels scaled by 1e-3 (strain_per_volt in the wrong unit): f's ratio is unchanged, the forces and
    pressures are a thousand times small. The incident wave against the striker's speed (eq. 14) says so, in the
    prepared record's notes (which become a run's warning) and under analyze's table and in its JSON."""
    import shutil

    import h5py

    from friction_uq.cli import main

    path = tmp_path / "milli.h5"
    shutil.copy(Path(__file__).parents[1] / "data" / "A" / "A-01.h5", path)
    with h5py.File(path, "r+") as fh:
        for name in ("input_bar", "internal_output_bar", "external_output_bar", "tube_hoop"):
            fh["signals"][name][...] = fh["signals"][name][()] * 1e-3
    notes = prepare(read_record(path)).gauge_notes
    assert any("/signals/input_bar reads an incident wave 0.00099 times" in n and "eq. 14" in n for n in notes), notes
    assert prepare(read_record(Path(__file__).parents[1] / "data" / "A" / "A-01.h5")).gauge_notes == ()
    assert main(["analyze", str(path)]) == 0
    assert "gauge note: /signals/input_bar reads an incident wave 0.00099" in capsys.readouterr().out
    assert main(["analyze", str(path), "--json"]) == 0
    assert any("eq. 14" in n for n in json.loads(capsys.readouterr().out)["gauge_notes"])


def test_a_spike_on_the_input_bar_is_said_to_leave_the_gauges_unchecked(tmp_path, capsys):
    """One spike as the input force's peak leaves no loading above half of it: inspect said "signs agree and the
    output forces sum to nan %", a pass, though neither check had run."""
    import h5py

    from friction_uq.cli import main

    rec = write_closed_form_record(tmp_path / "spike.h5", ClosedFormTest(), seed=3)
    with h5py.File(rec, "r+") as fh:
        x = fh["signals/input_bar"][...]
        x[len(x) // 2] = 20 * x[np.argmax(np.abs(x))]
        fh["signals/input_bar"][...] = x
    main(["inspect", str(rec)])
    out = capsys.readouterr().out
    assert "nan %" not in out and "not checked: neither the gauges' signs nor the output forces" in out


def test_a_record_ending_before_the_reflected_wave_has_passed_keeps_its_force_balance(tmp_path):
    """A trigger 40 us before the incident wave and 1000 us recorded: the reflected wave's last 37 us are not in
    the record. Brought back to the cell over a wrap-around, they read zero: the input force was the incident
    wave's alone there, the balance "20 % of the input force" blamed on a gain. Now the forces end with the data."""
    import h5py

    from friction_uq.forces import compute_forces
    from friction_uq.gauge_balance import force_balance

    src = Path(__file__).parents[1] / "data" / "A" / "A-03.h5"
    path = tmp_path / "late.h5"
    shutil.copyfile(src, path)
    with h5py.File(path, "r+") as fh:
        sig = fh["signals"]
        fs, t0 = float(sig.attrs["sample_rate"]), float(sig.attrs["t0"])
        start = int(round((-t0 - 40e-6) * fs))
        stop = start + int(1000e-6 * fs)
        for name in list(sig):
            attrs, data = dict(sig[name].attrs), sig[name][start:stop]
            del sig[name]
            sig.create_dataset(name, data=data)
            sig[name].attrs.update(attrs)
        sig.attrs["t0"] = t0 + start / fs
    rec = read_record(path)
    forces = compute_forces(rec)
    d_in = rec.apparatus.input_bar.gauge_delay * rec.sample_rate
    assert np.isnan(forces.F_i[int(np.ceil(rec.n_samples - d_in)):]).all()
    assert abs(force_balance(forces) - 1.0) < 0.05


def test_a_spike_before_the_incident_front_is_not_in_the_waves(tmp_path):
    """A 2-sample spike of 80 % of the pulse on the input bar 20 us before its front: left out of the noise, and of
    the incident wave too (it was a pulse of the simulated test's loading, and the whole-record check blamed the
    external gauge for what it made there)."""
    import h5py

    from friction_uq.forces import compute_forces
    from friction_uq.models.loading import measured_loading

    src = Path(__file__).parents[1] / "data" / "A" / "A-03.h5"
    path = tmp_path / "spike.h5"
    shutil.copyfile(src, path)
    with h5py.File(path, "r+") as fh:
        sig = fh["signals"]
        i = int((-float(sig.attrs["t0"]) - 20e-6) * float(sig.attrs["sample_rate"]))
        x = sig["input_bar"][()]
        x[i:i + 2] -= 0.8 * np.abs(x).max()
        sig["input_bar"][...] = x
    clean, spiked = read_record(src), read_record(path)
    fc, fs = compute_forces(clean), compute_forces(spiked)
    noise = fc.channels["input_bar"].noise.sd
    assert fs.channels["input_bar"].noise.sd == pytest.approx(noise, rel=0.02)
    lc, ls = measured_loading(clean, fc), measured_loading(spiked, fs)
    assert np.max(np.abs(ls.at_gauge - lc.at_gauge)) < 3 * noise
    assert np.nanmax(np.abs(fs.eps_incident - fc.eps_incident)) < 3 * noise


def test_a_striker_speed_at_odds_with_agreeing_gauges_is_a_warning_of_its_own(tmp_path):
    """A light gate read 6 m/s for 9.9: no gauge is blamed (the gauges agree), but the run says it, since a scale
    every gauge shares would leave f and move the forces, the pressure and the velocity."""
    import h5py

    from friction_uq.record_run.warnings import speed_warning

    path = tmp_path / "v6.h5"
    shutil.copyfile(Path(__file__).parents[1] / "data" / "A" / "A-03.h5", path)
    with h5py.File(path, "r+") as fh:
        fh.attrs["striker_velocity"] = 6.0
    prep = prepare(read_record(path))
    assert prep.gauge_notes == () and len(prep.speed_notes) == 1
    said = speed_warning(prep.speed_notes)
    assert said.startswith("The incident wave stands for a striker at 9.") and "every gauge's scale is off" in said
    assert prepare(read_record(Path(__file__).parents[1] / "data" / "A" / "A-03.h5")).speed_notes == ()
