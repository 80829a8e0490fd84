"""The settings of one analysis, as one frozen object written into the provenance.

``run`` builds an :class:`AnalysisSettings` from its arguments, builds the likelihood from it once
and writes it into the DataTree's root attributes and the JSON (key ``analysis_settings``), so a
result says how it was obtained.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass

from .likelihood import FORCE_MODES, RATIO_MODEL_FORM
from .likelihood.hoop import HOOP_DISCREPANCY, HOOP_MODES


@dataclass(frozen=True)
class AnalysisSettings:
    """How a record is analysed (SI units).

    Attributes
    ----------
    window : (float, float) or None
        Stationary window asked for (s, record time base); None: found from eq. 6.
    dispersion : bool
        Pochhammer-Chree dispersion correction of the transported waves.
    hoop : bool
        Use the tube hoop gauge when the record allows it (the run may still leave it out, with a note).
    hoop_mode : {"level", "series"}
        How the hoop reading enters the likelihood (:class:`friction_uq.likelihood.HoopTerm`).
    axial_poisson : bool
        The tube's axial Poisson term in the hoop prediction.
    hoop_discrepancy : float
        Relative sd of the hoop model's error on the level.
    force_mode : {"level", "series"}
        How the force ratio enters the likelihood (:class:`friction_uq.likelihood.Likelihood`).
    ratio_model_form : float
        Relative sd of eq. 17's ratio against the world (the "level" force term's model-form term).
    """

    window: tuple[float, float] | None = None
    dispersion: bool = False
    hoop: bool = True
    hoop_mode: str = "level"
    axial_poisson: bool = True
    hoop_discrepancy: float = HOOP_DISCREPANCY
    force_mode: str = "level"
    ratio_model_form: float = RATIO_MODEL_FORM

    def __post_init__(self) -> None:
        if self.hoop_mode not in HOOP_MODES:
            raise ValueError(f"hoop mode {self.hoop_mode!r} is not understood, allowed values: {', '.join(HOOP_MODES)}")
        if self.force_mode not in FORCE_MODES:
            raise ValueError(f"force mode {self.force_mode!r} is not understood, allowed values: "
                             f"{', '.join(FORCE_MODES)}")
        if self.window is not None:
            object.__setattr__(self, "window", (float(self.window[0]), float(self.window[1])))

    def to_json(self) -> dict[str, object]:
        """Plain JSON types (the window as a list or null)."""
        out = asdict(self)
        out["window"] = None if self.window is None else list(self.window)
        return out

    def to_attr(self) -> str:
        """The settings as one JSON string (a netCDF attribute holds no mapping)."""
        return json.dumps(self.to_json(), sort_keys=True)
