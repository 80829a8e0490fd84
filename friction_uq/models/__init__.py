"""Forward models with named parameters: the closed form (eq. 13-21, the tube kernel) and the
simulator of the whole test. Both declare their parameters (:mod:`.parameters`) and predict
observations for given parameter values; the likelihood takes a model and the observations."""

from .closed_form import ClosedFormModel, HoopPrediction, force_ratio, gauge_kernel
from .loading import measured_loading
from .parameters import F, HOOP_GAIN, NU, Parameter, ParameterSet
from .simulator import GAUGES, Prediction, SimulatorModel

__all__ = ["F", "GAUGES", "HOOP_GAIN", "NU", "ClosedFormModel", "HoopPrediction", "Parameter", "ParameterSet", "Prediction",
           "SimulatorModel", "force_ratio", "gauge_kernel", "measured_loading"]
