"""Write a confined friction test record (``test.h5``, format version 1), atomically.

:func:`write_record` is the single way the package writes records (closed-form builders and the
simulator both use it); it flips the gauge sign back (elongation positive in the file).
"""

from __future__ import annotations

import io

import os
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import write_bytes
from ..apparatus import Apparatus, Bar
from .contract import CHANNELS, FORMAT, FORMAT_VERSION, UNITS


def _apparatus_attrs(app: Apparatus) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name in ("striker", "input_bar", "internal_output_bar", "external_output_bar"):
        b: Bar = getattr(app, name)
        d: dict[str, Any] = {"young_modulus": b.young_modulus, "wave_speed": b.wave_speed, "length": b.length}
        if name == "external_output_bar":
            d["outer_diameter"] = b.outer_diameter
            d["inner_diameter"] = b.inner_diameter
        else:
            d["diameter"] = b.outer_diameter
        if b.gauge_distance is not None:
            d["gauge_distance"] = b.gauge_distance
        d["poisson_ratio"] = b.poisson_ratio
        out[name] = d
    out["tube"] = asdict(app.tube)
    out["sample"] = asdict(app.sample)
    if app.plug is not None:
        out["plug"] = asdict(app.plug)
    return out


def write_record(
    path: str | os.PathLike[str],
    *,
    test_id: str,
    campaign: str,
    sample_rate: float,
    strains: Mapping[str, np.ndarray],
    apparatus: Apparatus,
    t0: float = 0.0,
    units: Mapping[str, str] | None = None,
    strain_per_volt: Mapping[str, float] | None = None,
    dtype: Any = np.float64,
    date: str | None = None,
    description: str | None = None,
    striker_velocity: float | None = None,
    truth: Mapping[str, Any] | None = None,
    provenance: Mapping[str, Any] | None = None,
) -> Path:
    """Write a record that follows the contract, atomically.

    Parameters
    ----------
    strains
        Channel name -> strain, **compression positive** (the package's convention); the gauge
        sign (elongation positive) is restored here.
    units
        Channel name -> ``"strain"``, ``"microstrain"`` or ``"V"`` (default ``"strain"``).
    strain_per_volt
        Channel name -> conversion factor, required for channels stored in ``"V"``.
    truth
        Parameters that generated a synthetic record (written to ``/truth``).
    """
    import h5py

    from .. import __version__

    units = dict(units or {})
    strain_per_volt = dict(strain_per_volt or {})
    p = Path(path)
    buf = io.BytesIO()  # built in memory, then written at once: HDF5 crashes on a disk that fills mid-file
    with h5py.File(buf, "w") as fh:
        fh.attrs["format"] = FORMAT
        fh.attrs["format_version"] = FORMAT_VERSION
        fh.attrs["test_id"] = test_id
        fh.attrs["campaign"] = campaign
        for k, v in (("date", date), ("description", description), ("striker_velocity", striker_velocity)):
            if v is not None:
                fh.attrs[k] = v
        sig = fh.create_group("signals")
        sig.attrs["sample_rate"] = float(sample_rate)
        sig.attrs["t0"] = float(t0)
        for name, eps in strains.items():
            if name not in CHANNELS:
                raise ValueError(f"unknown channel {name!r}, allowed: {CHANNELS}")
            u = units.get(name, "strain")
            if u == "V":
                scale = strain_per_volt[name]
            elif u in UNITS:
                scale = UNITS[u]
            else:
                raise ValueError(f"unknown units {u!r} for {name!r}, allowed: {tuple(UNITS)}")
            raw = -np.asarray(eps, dtype=np.float64) / scale
            ds = sig.create_dataset(name, data=raw.astype(dtype))
            ds.attrs["units"] = u
            if u == "V":
                ds.attrs["strain_per_volt"] = float(scale)
        write_apparatus(fh, _apparatus_attrs(apparatus))
        prov = fh.create_group("provenance")
        prov.attrs["generator"] = "friction-uq"
        prov.attrs["generator_version"] = __version__
        for k, v in (provenance or {}).items():
            prov.attrs[k] = v
        if truth is not None:
            tg = fh.create_group("truth")
            for k, v in truth.items():
                tg.attrs[k] = v
    write_bytes(p, buf.getvalue())
    return p


def write_apparatus(fh, parts) -> None:
    """The record's ``/apparatus`` group: one subgroup per part, its SI attributes (docs/record-format.md)."""
    app = fh.create_group("apparatus")
    for part, attrs in parts.items():
        g = app.create_group(part)
        for k, v in attrs.items():
            g.attrs[k] = v
