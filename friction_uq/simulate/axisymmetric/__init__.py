"""Axisymmetric (r, z) simulator of the cell: plug, sample and tube as 2-D elastic bodies in contact.

The higher-fidelity reference of the 1-D simulator (as the paper's ABAQUS model of the whole set-up):
explicit elastodynamics on 4-node rings (one-point integration, hourglass control, lumped masses),
kinematic contact with the simulator's friction laws between sample and tube and between plug and
tube, push-only end faces with friction, 1-D bars coupled at the three interfaces, and the
simulator's measurement layer. Chosen with ``[model] fidelity = "axisymmetric"``.

Modules: :mod:`.settings` (the ``[model]`` table), :mod:`.mesh` (structured meshes, lumped masses),
:mod:`.kernels` (element forces, stress update, Drucker-Prager, stability limit), :mod:`.contact`
(lateral and end-face contact with friction), :mod:`.coupling` (bar ends), :mod:`.solver` (the
compiled time loop), :mod:`.assembly` (a configuration's cell and its checks), :mod:`.model_axisymmetric` (the
run, gauges and outputs), :mod:`.side_by_side` (1-D against axisymmetric, per phase), :mod:`.statics`
(static solves with the same element, for verification against closed forms).
"""

from __future__ import annotations

from typing import Any

__all__ = ["run_axisymmetric"]


def run_axisymmetric(*args: Any, **kwargs: Any) -> Any:
    """:func:`.model_axisymmetric.run_axisymmetric` (imported on first use: the configuration reader imports this package)."""
    from .model_axisymmetric import run_axisymmetric as run

    return run(*args, **kwargs)
