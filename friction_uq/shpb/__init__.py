"""The generic split Hopkinson bar, apart from the confined cell: a standard two-bar record.

This package is how the generic signal code (:mod:`friction_uq.signals`) is exercised on a record
that no one on this project made (``shared/data/real/lanl-hoppybar-cu/``): a compression test with
one input bar (incident and reflected waves on one gauge) and one transmitted bar. It has nothing
to do with the confined friction cell.

* :mod:`.record`: the bars, the specimen and the signals of a two-bar record;
* :mod:`.lanl`: :func:`read_lanl_raw`, the reader of the LANL text format (and the one sign flip);
* :mod:`.forces`: :func:`two_bar_forces`, the waves at the specimen faces, the forces on both
  faces (eq. 2-3) and their balance.

Strain from volts (quarter bridge): strain = V (2 / GF) / (gain Vexc).
"""

from .forces import (
    BALANCE_LEVEL,
    PULSE_END_FRACTION,
    TwoBarForces,
    WaveSpeed,
    transport_speeds,
    two_bar_forces,
)
from .lanl import HEADER_ROWS, read_lanl_raw
from .record import BarProperties, SpecimenProperties, TwoBarRecord

__all__ = [
    "BALANCE_LEVEL",
    "HEADER_ROWS",
    "PULSE_END_FRACTION",
    "BarProperties",
    "SpecimenProperties",
    "TwoBarForces",
    "TwoBarRecord",
    "WaveSpeed",
    "read_lanl_raw",
    "transport_speeds",
    "two_bar_forces",
]
