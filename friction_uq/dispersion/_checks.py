"""Argument checks of the dispersion functions: a bad value raises ValueError naming it."""

from __future__ import annotations

import math


def check_positive(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive finite number, received {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a positive finite number, received {value!r}")
    return v


def check_finite(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, received {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number, received {value!r}")
    return v


def check_nu(nu: float) -> float:
    try:
        v = float(nu)
    except (TypeError, ValueError):
        raise ValueError(f"nu (Poisson ratio) must be a number in [0, 0.5), received {nu!r}") from None
    if not (0.0 <= v < 0.5):
        raise ValueError(f"nu (Poisson ratio) must be in [0, 0.5), received {nu!r}")
    return v


def check_geometry(diameter: float, inner_diameter: float) -> tuple[float, float]:
    d = check_positive("diameter", diameter)
    try:
        di = float(inner_diameter)
    except (TypeError, ValueError):
        raise ValueError(
            f"inner_diameter must be a number in [0, diameter={d!r}) m, received {inner_diameter!r}"
        ) from None
    if not math.isfinite(di) or not (0.0 <= di < d):
        raise ValueError(f"inner_diameter must be in [0, diameter={d!r}) m, received {inner_diameter!r}")
    return d, di
