"""The Python interface: the commands as functions, and a run's outputs read back.

>>> import friction_uq as fu                                    # doctest: +SKIP
>>> res = fu.run("data/A/A-03.h5", out_dir="reports")           # doctest: +SKIP
>>> res.f["q50"], res.f["q05"], res.f["q95"]                    # doctest: +SKIP
>>> dt = res.datatree()   # xarray.DataTree: open it with ArviZ   # doctest: +SKIP

Each function checks its inputs as the command does and raises
:class:`~friction_uq.errors.FrictionUQError` with the same one sentence. Nothing heavy is imported
until a function is called.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

RUN_SCHEMA = "friction-uq/run-result"


@dataclass(frozen=True)
class Result:
    """One record's analysis as ``run`` wrote it: the JSON document and the paths of its files.

    Attributes
    ----------
    doc : dict
        The JSON document (schema ``friction-uq/run-result``, docs/outputs.md).
    json_path, netcdf_path, pdf_path : Path or None
        The files written side by side.
    details : object or None
        The in-process :class:`friction_uq.record_run.RunResult` when the result comes from :func:`run` in
        this process (forces, window, draws); None when read back from files.
    """

    doc: dict[str, Any]
    json_path: Path
    netcdf_path: Path | None
    pdf_path: Path | None
    details: Any = field(default=None, repr=False, compare=False)

    @property
    def f(self) -> dict[str, Any]:
        """The f to quote: ``mean``, ``sd``, ``q05``, ``q50``, ``q95`` (the output bars' calibration folded in), ``model``,
        ``source``, ``bar_calibration_sd``, ``calibration_folded_in_sd`` and ``given_bar_headers`` (the posterior's
        own summary); docs/outputs.md."""
        return self.doc["f"]

    @property
    def warnings(self) -> list[str]:
        """One sentence per check that says the model does not describe the record (empty when all pass)."""
        return list(self.doc.get("warnings", []))

    @property
    def warning_kinds(self) -> list[str]:
        """Each warning's kind, in the same order (``misfit``, ``misfit_diagnosed``, ``gauge``, ...: docs/outputs.md);
        empty for a JSON of schema version 11 or older, which did not write them."""
        return list(self.doc.get("warning_kinds", []))

    @property
    def test_id(self) -> str:
        return str(self.doc.get("test_id", ""))

    def datatree(self) -> Any:
        """The posterior, prior, log-likelihood and observed data as an ``xarray.DataTree`` (ArviZ reads it)."""
        from .errors import FrictionUQError

        if self.netcdf_path is None or not self.netcdf_path.is_file():
            raise FrictionUQError(f"{self.json_path}: its netCDF file ({self.netcdf_path}) is missing")
        import xarray as xr

        try:
            return xr.open_datatree(self.netcdf_path, engine="h5netcdf")
        except (OSError, ValueError) as exc:  # not HDF5, truncated, or not a netCDF of groups
            raise FrictionUQError(f"{self.netcdf_path}: not a readable netCDF file ({exc})") from None


def read_result(path: str | os.PathLike[str]) -> Result:
    """Read a run's outputs back from its ``.json`` (or its ``.nc``, or the common stem).

    Parameters
    ----------
    path
        ``reports/A_A-03.json``, ``reports/A_A-03.nc`` or ``reports/A_A-03``.

    Raises
    ------
    FrictionUQError
        The file is missing, not JSON, or not a run result (another schema).
    """
    from ._json_text import read_json_file
    from .api_arguments import path_argument
    from .errors import FrictionUQError

    p = path_argument("path", path)
    js = p.with_suffix(".json") if p.suffix in (".nc", ".pdf", "") else p
    doc = read_json_file(js)
    if not isinstance(doc, dict) or doc.get("schema") != RUN_SCHEMA:
        raise FrictionUQError(f"{js}: not a run result (key 'schema' is not {RUN_SCHEMA!r})")
    if not isinstance(doc.get("f"), dict):
        raise FrictionUQError(f"{js}: not a run result: key 'f' (the f to quote) is missing or not an object")
    warns = doc.get("warnings", [])
    if not isinstance(warns, list) or not all(isinstance(w, str) for w in warns):
        raise FrictionUQError(f"{js}: key 'warnings' must be a list of sentences, got {warns!r:.60}")
    nc, pdf = js.with_suffix(".nc"), js.with_suffix(".pdf")
    return Result(doc, js, nc if nc.is_file() else None, pdf if pdf.is_file() else None)


def run(path: str | os.PathLike[str], *, priors: str | os.PathLike[str] | None = None,
        out_dir: str | os.PathLike[str] = "reports", seed: int = 20161, window: tuple[float, float] | None = None,
        dispersion: bool = False, hoop: bool = True, pdf: bool = True, progress: bool = False,
        diagnose: bool = False) -> Result:
    """``friction-uq run``: the joint posterior of f and nu for one record, its outputs written to ``out_dir``.

    Parameters
    ----------
    path
        A test record (``test.h5``; :func:`import_scope_files` writes one from oscilloscope files).
    priors
        A prior file (default: the one of the sample's material, docs/priors.md).
    out_dir
        Where ``<campaign>_<test_id>.json``, ``.nc`` and ``.pdf`` go.
    seed
        Random seed, 0 <= seed < 2**64: same seed, same draws.
    window
        The stationary window (t0, t1) in seconds on the record's time base (default: found).
    dispersion, hoop, pdf
        Pochhammer-Chree correction; the tube gauge in the likelihood; the PDF report.
    progress
        Progress lines on stderr (off by default in Python).
    diagnose
        Also fit each mechanism of the catalogue and name the cause of a misfit (as :func:`diagnose`).

    Returns
    -------
    Result
        The JSON document and the files; ``details`` holds the in-process run.
    """
    from .api_arguments import flag_argument, path_argument, window_argument
    from .record_run import run_file

    path, priors = path_argument("path", path), path_argument("priors", priors, optional=True)
    out_dir, window = path_argument("out_dir", out_dir), window_argument(window)
    dispersion, hoop, pdf, progress, diagnose = (flag_argument(k, v) for k, v in (
        ("dispersion", dispersion), ("hoop", hoop), ("pdf", pdf), ("progress", progress), ("diagnose", diagnose)))
    rr = run_file(path, priors_path=priors, out_dir=out_dir, seed=seed, window=window, dispersion=dispersion,
                  hoop=hoop, pdf=pdf, progress=progress, table=progress, notes=progress, diagnose=diagnose)
    res = read_result(rr.outputs["json"])
    return Result(res.doc, res.json_path, res.netcdf_path, res.pdf_path, rr)


def diagnose(path: str | os.PathLike[str], **options: Any) -> Result:
    """``friction-uq diagnose``: :func:`run`, then each mechanism fitted to the whole record and the cause named.

    Takes the options of :func:`run`; the JSON then holds a ``discrepancy`` block and ``f`` is the f
    under the named causes (docs/outputs.md).
    """
    unknown = sorted(set(options) - {"priors", "out_dir", "seed", "window", "dispersion", "hoop", "pdf", "progress"})
    if unknown:
        raise TypeError(f"diagnose() got unexpected keyword argument(s): {', '.join(unknown)}")
    return run(path, **{**options, "diagnose": True})


def campaign(records: Sequence[str | os.PathLike[str]], out_dir: str | os.PathLike[str], *, workers: int = 2,
             scheduler: str | None = None, seed: int = 20161, priors: str | os.PathLike[str] | None = None,
             dispersion: bool = False, hoop: bool = True, pdf: bool = True, diagnose: bool = False,
             progress: bool = False) -> Any:
    """``friction-uq campaign``: many records in parallel (Dask), pooled, the friction law across set-ups.

    Parameters
    ----------
    records
        Record files or folders of them (one path, or a list).
    out_dir
        Receives ``campaign.json``, ``campaign.nc``, ``campaign.pdf`` and ``records/`` (one run each).
    workers, scheduler
        Local worker processes, or the address of a running Dask scheduler.

    Returns
    -------
    friction_uq.campaigns.CampaignOutcome
        ``.doc`` is the campaign's JSON document, ``.outputs`` the files written; each record's
        result reads back with :func:`read_result` from ``out_dir/records``.
    """
    from .api_arguments import flag_argument, path_argument, paths_argument, scheduler_argument, workers_argument
    from .campaigns import run_campaign

    records, out_dir = paths_argument("records", records), path_argument("out_dir", out_dir)
    priors, workers = path_argument("priors", priors, optional=True), workers_argument(workers)
    scheduler = scheduler_argument(scheduler)
    dispersion, hoop, pdf, diagnose, progress = (flag_argument(k, v) for k, v in (
        ("dispersion", dispersion), ("hoop", hoop), ("pdf", pdf), ("diagnose", diagnose), ("progress", progress)))
    return run_campaign(records, out_dir, workers=workers, scheduler=scheduler, seed=seed, priors_path=priors,
                        dispersion=dispersion, hoop=hoop, pdf=pdf, diagnose=diagnose, progress=progress)


def import_scope_files(files: Sequence[str | os.PathLike[str]], setup: str | os.PathLike[str],
                       output: str | os.PathLike[str], *, check: bool = True) -> Any:
    """``friction-uq import``: oscilloscope files and a SETUP.toml to a checked record (docs/import.md).

    Returns the :class:`friction_uq.acquisition.ImportOutcome` (path written, samples, warnings).
    """
    from .acquisition import import_scope_files as _import
    from .api_arguments import flag_argument, path_argument, paths_argument

    return _import(paths_argument("files", files), path_argument("setup", setup), path_argument("output", output),
                   check=flag_argument("check", check))
