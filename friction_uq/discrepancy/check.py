"""The whole-record check of one analysis: fit the simulator to the whole record, compare, decide.

:func:`check_whole_record` is what ``friction-uq run`` runs beside the sampling of the
stationary-phase posterior (it needs none of its draws): the simulator driven by the measured
incident wave (its bars dispersive when the analysis corrects for dispersion, ``--dispersion``) is
fitted to every gauge (:mod:`.fit`, started from the lab's eq. 17 estimate and
from nu either side of the prior), the posterior draws are simulated
(:mod:`.whole_record`) and the misfit decision is taken (:mod:`.misfit`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ..analysis import Prepared
from ..models import SimulatorModel, measured_loading
from ..stats.streams import stream
from .extended import NU_STARTS
from .fit import WholeRecordFit, WholeRecordLikelihood, fit_whole_record
from .record_likelihood import HOOP_GAIN_SD
from .misfit import MisfitDecision, decide
from .whole_record import WholeRecord, compare_whole_record


@dataclass(frozen=True)
class WholeRecordCheck:
    """The fitted baseline over the whole record, its comparison with every gauge and the decision."""

    fit: WholeRecordFit
    hoop_gain: float | None  # None: no hoop gauge read (none recorded, or left out)
    comparison: WholeRecord
    decision: MisfitDecision
    seconds: float

    def to_json(self) -> dict[str, object]:
        out = self.decision.to_json()
        out["figures"] = [f.to_json() for f in self.comparison.figures]
        out["fit"] = {"model": "simulator driven by the measured incident wave (baseline)",
                      "parameters": {n: self.fit.summary(n) for n in self.fit.names},
                      "hoop_gain": self.hoop_gain, "pareto_k": self.fit.pareto_k, "simulator_calls": self.fit.n_calls}
        out["seconds"] = self.seconds
        return out


def check_whole_record(prep: Prepared, log_prior: Callable[[Mapping[str, float]], float], start: Mapping[str, float],
                       *, hoop: bool, seed: int, n_draws: int = 30,
                       hoop_calibration: tuple[float, float] = (1.0, HOOP_GAIN_SD)) -> WholeRecordCheck:
    """Fit, simulate the posterior draws, compare and decide (module docstring).

    ``log_prior`` takes ``{"f": ..., "nu": ...}``; ``start`` where the mode search starts (f, nu);
    ``hoop_calibration`` the hoop gauge's known factor (:func:`.record_likelihood.hoop_calibration`).
    """
    t0 = time.perf_counter()
    rec = prep.record
    # an analysis with the dispersion correction is checked against bars that disperse, as it reads them
    disp = bool(getattr(prep.forces, "dispersion", False))
    model = SimulatorModel(rec.apparatus, measured_loading(rec, prep.forces), hoop=hoop and rec.has_hoop,
                           dispersion=disp,
                           dispersive_loading=measured_loading(rec, prep.forces, dispersion=True) if disp else None)
    # the check's fit keeps the channels' own tolerance, with which its decision's tolerance table and thresholds were
    # calibrated, whatever LIKELIHOOD_TOLERANCE and SHAPE_SD hold: with 10 % on the hoop in its fit it flagged 11 of
    # 80 clean axisymmetric records (4 before; docs/trust.md)
    lik = WholeRecordLikelihood(prep, model, phase_tolerance={}, shape_sd={}, hoop_calibration=hoop_calibration)
    rng = stream(seed, "whole-record check")
    fit = fit_whole_record(lik, log_prior, {"f": start["f"], "nu": start["nu"]}, n_draws=n_draws, rng=rng,
                           extra_starts=tuple({"nu": nu} for nu in NU_STARTS))
    gain = lik.strains(fit.mode)[1]
    draws = dict(fit.draws)
    draws["hoop_gain"] = np.full(len(draws["f"]), gain)
    predicted = model.predict_draws(draws)
    comparison = compare_whole_record(prep, predicted)
    return WholeRecordCheck(fit=fit, hoop_gain=gain if "tube_hoop" in lik.channels else None,
                            comparison=comparison, decision=decide(comparison),
                            seconds=time.perf_counter() - t0)
