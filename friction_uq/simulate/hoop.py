"""Hoop gauge on the tube: wall pressure seen through the tube's influence function.

Physical hoop strain at the outer surface (positive when the tube swells), docs/physics.md section 6:

    eps_theta(t) = [2 a^2 / (E_t (b^2 - a^2))] * sum_e p_e(t) * B_e(t)
                   (+ nu_t N(z_g, t) / (E_t A_t) with the optional axial term)

* p_e is the wall pressure of sample element e, uniform between its two nodes, whose positions
  in the tube's frame z_e(t) = z_e(0) + u_e(t) - u_tube(t) follow the sliding;
* B_e = G(z_g - z_e) - G(z_g - z_{e+1}) is the gauge's response to that pressure band,
  normalised to the Lame long-tube strain, from the influence function
  K(x) = (beta/2) exp(-beta|x|)(cos(beta|x|) + sin(beta|x|)) (integral 1,
  :func:`friction_uq.physics.tube.hoop_kernel`, beta_eff = 192 /m for the paper's tube): G is the
  integral of K from -inf, averaged over the gauge width w (closed form, tabulated once and read
  by linear interpolation, step 0.02 / beta);
* z is measured in the tube's frame from the sample's middle at the start, positive towards the
  output bars; the gauge's middle sits at z_g = ``tube.gauge_offset``;
* optional axial term: the tube carries the friction forces applied upstream of the gauge to the
  external output bar, N(z_g) (compressive), whose Poisson effect swells the tube by
  nu_t N / (E_t A_t) (about 19 microstrain for 5 kN on the paper's tube).

The relation is quasi-static (tube ring frequency ~95 kHz, above the test's content).
"""

from __future__ import annotations

import numpy as np

from ..record import Tube
from .._jit import njit

#: Table half-width in units of 1/beta (K < 1e-12 of its peak beyond) and table step.
_HALF_WIDTH = 30.0
_STEP = 0.02


def _integral_of_cdf(x: np.ndarray, beta: float) -> np.ndarray:
    """I(x) = integral_0^x G0(s) ds with G0 the integral of K: max(x, 0) - J(|x|) / 2,
    J(y) = (1 + exp(-beta y)(sin(beta y) - cos(beta y))) / (2 beta)."""
    y = np.abs(x) * beta
    j = (1.0 + np.exp(-y) * (np.sin(y) - np.cos(y))) / (2.0 * beta)
    return np.maximum(x, 0.0) - 0.5 * j


def averaged_cdf_table(*, beta: float, width: float) -> tuple[float, float, np.ndarray]:
    """(x0, step, values) of G(x), the kernel's integral averaged over a gauge of ``width`` (m)."""
    step = _STEP / beta
    x = np.arange(-_HALF_WIDTH / beta, _HALF_WIDTH / beta + step, step)
    if width > 0.0:
        g = (_integral_of_cdf(x + width / 2, beta) - _integral_of_cdf(x - width / 2, beta)) / width
    else:
        y = np.abs(x) * beta
        g = 0.5 + np.sign(x) * 0.5 * (1.0 - np.exp(-y) * np.cos(y))
    return float(x[0]), step, g


@njit
def _lookup(x: float, x0: float, step: float, table: np.ndarray) -> float:
    s = (x - x0) / step
    if s <= 0.0:
        return table[0]
    n = table.size - 1
    if s >= n:
        return table[n]
    i = int(s)
    w = s - i
    return table[i] * (1.0 - w) + table[i + 1] * w


@njit
def _hoop_loop(pressure: np.ndarray, rel_disp: np.ndarray, z0: np.ndarray, z_gauge: float,
               x0: float, step: float, table: np.ndarray, tube_force: np.ndarray, width: float,
               lame: float, axial: float) -> np.ndarray:
    n_t, n_el = pressure.shape
    out = np.zeros(n_t)
    g = np.empty(n_el + 1)
    for j in range(n_t):
        for i in range(n_el + 1):
            g[i] = _lookup(z_gauge - (z0[i] + rel_disp[j, i]), x0, step, table)
        acc = 0.0
        for e in range(n_el):
            acc += pressure[j, e] * (g[e] - g[e + 1])
        out[j] = lame * acc
        if axial != 0.0:
            n_ax = 0.0
            for i in range(n_el + 1):
                zi = z0[i] + rel_disp[j, i]
                if width > 0.0:
                    share = min(1.0, max(0.0, (z_gauge + 0.5 * width - zi) / width))
                else:
                    share = 1.0 if zi < z_gauge else 0.0
                n_ax += tube_force[j, i] * share
            out[j] += axial * n_ax
    return out


def hoop_strain(pressure: np.ndarray, rel_disp: np.ndarray, *, tube: Tube, sample_length: float, beta: float,
                tube_force: np.ndarray | None = None) -> np.ndarray:
    """Physical hoop strain (swelling positive) at the gauge for each recorded time.

    Parameters
    ----------
    pressure
        Wall pressure per element (Pa), shape (n_t, N).
    rel_disp
        Node displacement relative to the tube (m), shape (n_t, N + 1).
    tube
        Tube and gauge (``gauge_offset``, ``gauge_width``, elastic constants).
    sample_length
        Sample length L (m); nodes start at -L/2 + i L / N.
    beta
        Decay rate of the influence function (1/m).
    tube_force
        Axial force given to the tube at each node (N, positive towards the output), shape
        (n_t, N + 1), the plug's share included on node 0; None leaves out the axial term.
    """
    n_el = pressure.shape[1]
    z0 = -0.5 * sample_length + sample_length * np.arange(n_el + 1) / n_el
    x0, step, table = averaged_cdf_table(beta=beta, width=tube.gauge_width)
    a, b = tube.inner_diameter / 2, tube.outer_diameter / 2
    lame = 2.0 * a * a / (tube.young_modulus * (b * b - a * a))
    if tube_force is None:
        axial, tube_force = 0.0, np.zeros_like(rel_disp)
    else:
        axial = tube.poisson_ratio / (tube.young_modulus * tube.area)
    return _hoop_loop(np.ascontiguousarray(pressure), np.ascontiguousarray(rel_disp), z0, tube.gauge_offset,
                      x0, step, table, np.ascontiguousarray(tube_force), tube.gauge_width, lame, axial)

