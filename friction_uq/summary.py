"""Plain-text summaries of a record and of the deterministic identification (render only)."""

from __future__ import annotations

import numpy as np

from .analysis import Identification
from .errors import SignalError
from .plausible import escaped
from .record import Record
from .signals import prepulse_noise


def _table(rows: list[tuple[str, ...]], header: tuple[str, ...]) -> str:
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    line = "  ".join("-" * w for w in widths)
    fmt = lambda r: "  ".join(str(c).ljust(w) for c, w in zip(r, widths))  # noqa: E731
    return "\n".join([fmt(header), line, *(fmt(r) for r in rows)])


def inspect_text(record: Record) -> str:
    """What ``friction-uq inspect`` prints."""
    a = record.apparatus
    out = [
        f"record      {record.path}",
        f"test        {record.test_id}   campaign {record.campaign}"
        + (f"   date {record.date}" if record.date else ""),
    ]
    if record.description:  # free text from the file: control characters shown escaped, never sent to the terminal
        out.append(f"description {escaped(record.description)}")
    if record.striker_velocity is not None:
        out.append(f"striker     {record.striker_velocity:.3f} m/s (measured)")
    out.append(
        f"signals     {record.n_samples} samples at {record.sample_rate / 1e6:g} MHz, "
        f"{record.duration * 1e6:.1f} us, t0 = {record.t0 * 1e6:.1f} us"
    )
    if record.provenance:
        out.append("provenance  " + escaped(", ".join(f"{k}={v}" for k, v in record.provenance.items())))
    out.append("")
    span = int(a.pulse_duration * record.sample_rate / 2)
    rows = []
    for name, ch in record.channels.items():
        units = ch.units + (f" ({ch.strain_per_volt:g} strain/V)" if ch.strain_per_volt else "")
        pol = -1 if name == "tube_hoop" else 1
        try:
            noise, arrival = prepulse_noise(ch.strain, span=span, polarity=pol)
            t_arr = f"{(record.t0 + arrival / record.sample_rate) * 1e6:9.2f}"
            off = f"{noise.offset * 1e6:+8.2f}"
            sd = f"{noise.sd * 1e6:7.3f}"
            rho = f"{noise.rho:5.2f}"
        except SignalError as exc:
            t_arr, off, sd, rho = "none", "-", "-", "-"
            units += f"  [{exc}]"
        peak = float(np.max(np.abs(ch.strain))) * 1e6
        rows.append((name, units, t_arr, off, sd, rho, f"{peak:8.1f}"))
    out.append(_table(rows, ("channel", "units stored", "arrival us", "offset ue", "noise ue", "rho", "|max| ue")))
    out.append("(strain in microstrain, compression positive; noise from the pre-pulse segment)")
    out.append("")
    app_rows = []
    for name in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
        b = getattr(a, name)
        d = f"{b.outer_diameter * 1e3:g}" + (f"/{b.inner_diameter * 1e3:g}" if b.inner_diameter else "")
        app_rows.append((
            name, f"{b.young_modulus / 1e9:g}", f"{b.wave_speed:g}", d, f"{b.length:g}",
            "-" if b.gauge_distance is None else f"{b.gauge_distance:g}",
            f"{b.area * 1e6:.2f}", f"{b.density:.0f}", f"{b.impedance:.1f}",
        ))
    out.append(_table(app_rows, ("part", "E GPa", "c m/s", "diam mm", "length m", "gauge m", "area mm2",
                                 "rho kg/m3", "Z N s/m")))
    t, s = a.tube, a.sample
    out.append("")
    out.append(
        f"tube        E {t.young_modulus / 1e9:g} GPa, nu {t.poisson_ratio:g}, bore {t.inner_diameter * 1e3:g} mm, "
        f"outer {t.outer_diameter * 1e3:g} mm, length {t.length * 1e3:g} mm; hoop gauge {t.gauge_offset * 1e3:+g} mm "
        f"from the sample's middle, {t.gauge_width * 1e3:g} mm wide; "
        f"Lame {t.lame_hoop_strain_per_pressure * 1e12:.2f} ue/MPa"
    )
    out.append(
        f"sample      {s.material}: diameter {s.diameter * 1e3:g} mm, length {s.length * 1e3:g} mm, "
        f"E {s.young_modulus / 1e9:g} GPa, density {s.density:g} kg/m3"
    )
    if a.plug:
        out.append(f"plug        length {a.plug.length * 1e3:g} mm, E {a.plug.young_modulus / 1e9:g} GPa")
    out.append(f"pulse       2 L_striker / c = {a.pulse_duration * 1e6:.1f} us")
    out.append("")
    out.extend(gauge_check_lines(record))
    return "\n".join(out)


def gauge_check_lines(record: Record) -> list[str]:
    """The gauge check of ``inspect``: a gauge whose sign or scale contradicts the others, with the evidence."""
    from .gauge_check import record_gauge_check

    try:
        faults, notes = record_gauge_check(record)
    except ValueError as exc:  # a record the force computation cannot take (the summary above still stands)
        return [f"gauges      not checked: {exc}"]
    lines = [f"GAUGE FAULT {g.sentence}" for g in faults]
    lines += [("gauges      " if g.kind == "ok" else "gauge note  ") + g.sentence for g in notes]
    return lines


def identification_table(record: Record, ident: Identification) -> str:
    """What ``friction-uq analyze`` prints."""
    rows = [
        ("f (eq. 17)", f"{ident.f:.4f}", "-"),
        ("F_eo / F_io", f"{ident.ratio:.4f}", "-"),
        ("kappa = f nu/(1-nu)", f"{ident.kappa:.4f}", "-"),
        ("F_io", f"{ident.F_io:.0f}", "N"),
        ("F_eo", f"{ident.F_eo:.0f}", "N"),
        ("p_mean = tau_mean / f (eq. 20)", f"{ident.p_mean / 1e6:.2f}", "MPa"),
        ("(p_min + p_max) / 2 (eq. 21)", f"{ident.p_mean_approx / 1e6:.2f}", "MPa"),
        ("p_min (eq. 19)", f"{ident.p_min / 1e6:.2f}", "MPa"),
        ("p_max (eq. 19)", f"{ident.p_max / 1e6:.2f}", "MPa"),
        ("tau_mean (eq. 18)", f"{ident.tau_mean / 1e6:.3f}", "MPa"),
        ("V sliding (eq. 7)", f"{ident.V:.3f}", "m/s"),
        ("equilibrium error (eq. 5)", f"{100 * ident.equilibrium_error:+.2f}", "%"),
        ("equilibrium error: gauges' noise sd", f"{100 * ident.equilibrium_sd:.2f}", "%"),
        ("stationarity error (eq. 6)", f"{100 * ident.stationarity_error:+.2f}", "%"),
        ("f over the window: sd", f"{np.std(ident.f_series):.4f}", "-"),
    ]
    head = (
        f"{record.campaign} {record.test_id}: deterministic identification with nu = {ident.nu:g} "
        f"over {ident.window[0] * 1e6:.1f} to {ident.window[1] * 1e6:.1f} us "
        f"({(ident.window[1] - ident.window[0]) * 1e6:.1f} us)"
    )
    return head + "\n" + _table(rows, ("quantity", "value", "unit"))
