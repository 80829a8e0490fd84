"""The generic split Hopkinson bar, apart from the confined cell: a standard two-bar record.

This package is how the generic signal code (:mod:`friction_uq.signals`) is exercised on a record
that no one on this project made (``shared/data/real/lanl-hoppybar-cu/``): a compression test with
one input bar (incident and reflected waves on one gauge) and one transmitted bar. It has nothing
to do with the confined friction cell.

* :mod:`.record`: the bars, the specimen and the signals of a two-bar record;
* :mod:`.lanl`: :func:`read_lanl_raw`, the reader of the LANL text format (and the one sign flip);
* :mod:`.face_forces`: :func:`two_bar_forces`, the waves at the specimen faces, the forces on both
  faces (eq. 2-3) and their balance;
* :mod:`.waves`: :func:`gauge_waves`, the incident, reflected and transmitted waves at the gauges;
* :mod:`.balance`: the force balance as a forward model (the transmitted gauge predicted from the
  input gauge) and its misfit;
* :mod:`.balance_mechanisms`: the bar-level mechanisms (``gauge_gain``, ``wave_speed``, ``dispersion``);
* :mod:`.balance_fit`, :mod:`.balance_diagnosis`: their posteriors, block-LOO ELPD and the forward selection that
  names the causes of a misfit (:func:`diagnose_balance`).

Strain from volts (quarter bridge): strain = V (2 / GF) / (gain Vexc).
"""

from .balance import BalanceObservation, BarSettings, Misfit, transmitted_from_input
from .balance_diagnosis import BalanceDiagnosis, diagnose_balance
from .balance_fit import BalanceFit, fit_balance
from .face_forces import (
    BALANCE_LEVEL,
    PULSE_END_FRACTION,
    TwoBarForces,
    WaveSpeed,
    transport_speeds,
    two_bar_forces,
)
from .lanl import HEADER_ROWS, read_lanl_raw
from .balance_mechanisms import MECHANISMS, combine
from .record import BarProperties, SpecimenProperties, TwoBarRecord
from .waves import GaugeWaves, gauge_waves

__all__ = [
    "BALANCE_LEVEL",
    "MECHANISMS",
    "BalanceDiagnosis",
    "BalanceFit",
    "BalanceObservation",
    "BarSettings",
    "GaugeWaves",
    "Misfit",
    "HEADER_ROWS",
    "PULSE_END_FRACTION",
    "BarProperties",
    "SpecimenProperties",
    "TwoBarForces",
    "TwoBarRecord",
    "WaveSpeed",
    "combine",
    "diagnose_balance",
    "fit_balance",
    "gauge_waves",
    "read_lanl_raw",
    "transmitted_from_input",
    "transport_speeds",
    "two_bar_forces",
]
