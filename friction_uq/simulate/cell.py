"""Time integration of the cell: plug, sample column, tube, and the three bar ends touching them.

Model (SI units, forces and stresses positive in compression, axial velocities positive towards
the output bars):

* **Sample**: N equal elements of a confined elastic column of length h = L/N between N + 1
  nodes (lumped masses rho A h, halves at the faces). Element stress sigma from the element
  strain eps = (u_e - u_{e+1}) / h by the zero-tension, gap-aware law of :func:`element_stress`:
  uniaxial (sigma = E eps, no wall pressure) until the sample's Poisson expansion closes the
  radial clearance g at sigma* = E g / (nu R), then the wall pressure of docs/physics.md section 6,
  p = (nu sigma - E g / R) / D with D = (1 - nu) + E C_t / E_t (D = 1 - nu for a rigid tube), and
  the matching axial stiffness E / (1 - 2 nu^2 / D) (the oedometric modulus
  M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) when g = 0 and the tube is rigid). With g = 0 and a rigid
  tube p = nu/(1-nu) sigma (eq. 8), so the stationary state is the Janssen solution of eq. 11-13.
  Tension is not carried (a pressed granular sample; it also makes the PTFE-lubricated
  plug/sample and sample/bar faces push-only).
* **Wall friction** per node: each element gives half of its wall area pi R h to each of its two
  nodes, with shear strength tau_max(p_e, |V_node|, slip_node) from :mod:`.friction`. The law is
  applied implicitly (return mapping): the node sticks to the tube when the force that keeps it
  there is below the strength, and slides at the full strength otherwise. No regularisation
  speed is needed and the step is not limited by the friction.
* **Plug**: a rigid mass lumped on the sample's first node (its 10 mm of steel are crossed by
  waves in 2 us). Optional parasitic friction plug/tube of strength F_pf = force + coefficient x
  F_i, applied to the same node with its reaction on the tube (it bypasses the sample).
* **Tube**: a rigid mass receiving the reactions of all wall friction forces, resting on the
  external output bar.
* **Bar ends** (method of characteristics, exact for 1-D elastic bars): with eps_in the wave
  arriving at the end (compression positive) and v the velocity of the body it pushes,
  input bar F_i = Z_i (2 c_i eps_in - v), output bars F = Z (v + 2 c eps_in). A contact only
  pushes: when the force would be tensile the bar end is free (F = 0, end velocity 2 c eps_in or
  -2 c eps_in), and the separation is tracked until the two surfaces meet again. The outgoing
  waves eps_out = eps_in - v_end / c (input) and eps_in + v_end / c (outputs) are returned for the
  bar legs (:mod:`.bars`).

Artificial viscosity: each element in contact adds a viscous stress eta (v_e - v_{e+1}) / h with
eta = z rho c_max h, which damps the column's highest mode with damping ratio z (``numerics.damping``,
default 0.2) and its physical modes far less (ratio ~ z pi / (2 N) for the first). It vanishes in
the stationary state (no strain rate) and keeps the undamped column from ringing at the mesh
scale, e.g. under velocity-weakening friction (a negative damping at every node).

Integration: explicit central differences (velocities at half steps) for the column; the bar
end dampers are taken implicitly (average of the two half-step velocities), so the only stability
limit is the column's: dt <= (h / c_max)(sqrt(1 + z^2) - z), c_max = sqrt(E / (rho (1 - 2 nu^2 / D))).
Every force is applied with its reaction, so the momentum of sample + plug + tube equals the
impulse of F_i - F_io - F_eo to rounding (a validation test checks it).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from .friction import shear_strength

# indices of the parameter vector ``par``
DT, H, AREA, WALL, E, NU, DEN, EGR, SIGSTAR, ZI, CI, ZIO, CIO, ZEO, CEO, MT, PF_FORCE, PF_COEF, MPLUG, ETA, END_F = range(21)
N_PAR = 21
# indices of the state vector ``st`` (carried from one block of steps to the next)
UT, VT, SEP_I, SEP_IO, SEP_EO, IMPULSE, FI_PREV = range(7)
N_STATE = 7
# columns of the recorded scalars ``rec_s``
R_V0, R_VN, R_VT, R_P_SAMPLE, R_P_PLUG, R_P_TUBE, R_IMPULSE, R_PLUG_FRICTION, R_SLIP = range(9)
N_REC = 9


@njit
def element_stress(eps: float, young: float, nu: float, den: float, egr: float, sigstar: float) -> float:
    """Axial stress (Pa) of a confined column element at axial strain ``eps`` (compression positive).

    sigma = E eps up to sigma* = E g / (nu R) (gap open), then (E eps - 2 nu E g / (R D)) /
    (1 - 2 nu^2 / D) (wall contact, docs/physics.md section 6); 0 in extension. ``den`` = D,
    ``egr`` = E g / R.
    """
    if eps <= 0.0:
        return 0.0
    s = young * eps
    if s > sigstar:
        s = (young * eps - 2.0 * nu * egr / den) / (1.0 - 2.0 * nu * nu / den)
    return s


@njit
def wall_pressure(sigma: float, nu: float, den: float, egr: float) -> float:
    """Wall pressure (Pa): p = max(0, (nu sigma - E g / R) / D). Eq. 8 when g = 0 and D = 1 - nu."""
    p = (nu * sigma - egr) / den
    return p if p > 0.0 else 0.0


@njit
def end_face_relief(p: float, sigma: float, end_f: float, z: float, length: float, radius: float) -> float:
    """Wall pressure (Pa) lowered near the sample's end faces by their friction (docs/physics.md section 5).

    Shear on an end face (coefficient ``end_f``, at most end_f sigma) holds back the sample's radial
    expansion there; the relief decays into the sample over about one radius:
    p = max(0, p - end_f sigma [exp(-z / R) + exp(-(L - z) / R)]), z from the input face. The
    cell's equilibrium (eq. 5) is unchanged; F_eo / F_io falls below eq. 13 for the same f.

    >>> round(end_face_relief(1e8, 1.5e8, 0.05, 0.0, 0.01, 0.005) / 1e6, 3)
    91.485
    """
    q = p - end_f * sigma * (math.exp(-z / radius) + math.exp(-(length - z) / radius))
    return q if q > 0.0 else 0.0


@njit
def _project(v_trial: float, v_tube: float, m_eff: float, strength: float, dt: float) -> tuple[float, float]:
    """Implicit Coulomb update of one node: (new velocity, friction force on the node)."""
    rel = v_trial - v_tube
    lim = strength * dt / m_eff
    if abs(rel) <= lim:
        return v_tube, -rel * m_eff / dt
    if rel > 0.0:
        return v_trial - lim, -strength
    return v_trial + lim, strength


@njit
def run_block(k0: int, k1: int, stride: int, par: np.ndarray, law: int, fpar: np.ndarray,
              mass: np.ndarray, u: np.ndarray, v: np.ndarray, slip: np.ndarray, st: np.ndarray,
              eps_in_i: np.ndarray, eps_in_io: np.ndarray, eps_in_eo: np.ndarray,
              eps_out_i: np.ndarray, eps_out_io: np.ndarray, eps_out_eo: np.ndarray,
              f_i: np.ndarray, f_io: np.ndarray, f_eo: np.ndarray,
              rec_p: np.ndarray, rec_u: np.ndarray, rec_ff: np.ndarray, rec_s: np.ndarray) -> None:
    """Advance the cell over steps k0 <= k < k1 (time t_k = t_start + k dt), in place.

    ``u``, ``v``, ``slip`` (node displacement, half-step velocity, slip distance; N + 1 each) and
    ``st`` are the state. ``eps_in_*`` are the waves arriving at the three bar ends, ``eps_out_*``
    and ``f_*`` are written for every step; every ``stride``-th step is recorded in ``rec_*``
    (wall pressure per element, node displacement relative to the tube, friction force per node,
    scalars of the ``R_*`` columns).
    """
    n_el = u.size - 1
    dt, h, area, wall = par[DT], par[H], par[AREA], par[WALL]
    young, nu, den, egr, sigstar = par[E], par[NU], par[DEN], par[EGR], par[SIGSTAR]
    zi, ci, zio, cio, zeo, ceo = par[ZI], par[CI], par[ZIO], par[CIO], par[ZEO], par[CEO]
    mt, mplug, eta = par[MT], par[MPLUG], par[ETA]
    end_f = par[END_F]
    radius = math.sqrt(area / math.pi)
    sig = np.empty(n_el)
    pres = np.empty(n_el)
    force = np.empty(n_el + 1)
    strength = np.empty(n_el + 1)
    ff = np.empty(n_el + 1)
    vnew = np.empty(n_el + 1)
    for k in range(k0, k1):
        vt = st[VT]
        # stresses, wall pressures, internal nodal forces
        for i in range(n_el + 1):
            force[i] = 0.0
        for e in range(n_el):
            s = element_stress((u[e] - u[e + 1]) / h, young, nu, den, egr, sigstar)
            sig[e] = s
            pres[e] = wall_pressure(s, nu, den, egr)
            if end_f > 0.0 and pres[e] > 0.0:
                pres[e] = end_face_relief(pres[e], s, end_f, (e + 0.5) * h, n_el * h, radius)
            if s > 0.0:  # viscous stress while the element is in contact, never tensile in total
                s = max(0.0, s + eta * (v[e] - v[e + 1]) / h)
            force[e] -= area * s
            force[e + 1] += area * s
        # friction strength per node (half of each neighbouring element's wall)
        for i in range(n_el + 1):
            vr = abs(v[i] - vt)
            s = 0.0
            if i > 0:
                s += wall * shear_strength(law, fpar, pres[i - 1], vr, slip[i])
            if i < n_el:
                s += wall * shear_strength(law, fpar, pres[i], vr, slip[i])
            strength[i] = s
        # interior nodes
        for i in range(1, n_el):
            vnew[i], ff[i] = _project(v[i] + dt * force[i] / mass[i], vt, mass[i], strength[i], dt)
        # node 0: plug + input face, pushed by the input bar
        ein = eps_in_i[k]
        s_pf = par[PF_FORCE] + par[PF_COEF] * st[FI_PREV]
        s0 = strength[0] + s_pf
        m0, v0 = mass[0], v[0]
        fi = 0.0
        contact = st[SEP_I] <= 0.0
        if contact:
            meff = m0 + 0.5 * dt * zi
            vtr = (m0 * v0 + dt * (force[0] + zi * (2.0 * ci * ein - 0.5 * v0))) / meff
            vn0, f0 = _project(vtr, vt, meff, s0, dt)
            fi = zi * (2.0 * ci * ein - 0.5 * (vn0 + v0))
            contact = fi >= 0.0
        if not contact:
            fi = 0.0
            vn0, f0 = _project(v0 + dt * force[0] / m0, vt, m0, s0, dt)
            st[SEP_I] = max(0.0, st[SEP_I] + dt * (0.5 * (vn0 + v0) - 2.0 * ci * ein))
            eps_out_i[k] = -ein
        else:
            st[SEP_I] = 0.0
            eps_out_i[k] = ein - 0.5 * (vn0 + v0) / ci
        vnew[0] = vn0
        pf = f0 * s_pf / s0 if s0 > 0.0 else 0.0
        ff[0] = f0 - pf
        # node N: output face, pushing the internal output bar
        ein = eps_in_io[k]
        mn, vo = mass[n_el], v[n_el]
        fio = 0.0
        contact = st[SEP_IO] <= 0.0
        if contact:
            meff = mn + 0.5 * dt * zio
            vtr = (mn * vo + dt * (force[n_el] - zio * (0.5 * vo + 2.0 * cio * ein))) / meff
            vnn, fn = _project(vtr, vt, meff, strength[n_el], dt)
            fio = zio * (0.5 * (vnn + vo) + 2.0 * cio * ein)
            contact = fio >= 0.0
        if not contact:
            fio = 0.0
            vnn, fn = _project(vo + dt * force[n_el] / mn, vt, mn, strength[n_el], dt)
            st[SEP_IO] = max(0.0, st[SEP_IO] + dt * (-2.0 * cio * ein - 0.5 * (vnn + vo)))
            eps_out_io[k] = -ein
        else:
            st[SEP_IO] = 0.0
            eps_out_io[k] = ein + 0.5 * (vnn + vo) / cio
        vnew[n_el] = vnn
        ff[n_el] = fn
        # tube: reactions of the wall friction (and plug friction), pushing the external bar
        ftube = -pf
        for i in range(n_el + 1):
            ftube -= ff[i]
        ein = eps_in_eo[k]
        feo = 0.0
        contact = st[SEP_EO] <= 0.0
        if contact:
            meff = mt + 0.5 * dt * zeo
            vtn = (mt * vt + dt * (ftube - zeo * (0.5 * vt + 2.0 * ceo * ein))) / meff
            feo = zeo * (0.5 * (vtn + vt) + 2.0 * ceo * ein)
            contact = feo >= 0.0
        if not contact:
            feo = 0.0
            vtn = vt + dt * ftube / mt
            st[SEP_EO] = max(0.0, st[SEP_EO] + dt * (-2.0 * ceo * ein - 0.5 * (vtn + vt)))
            eps_out_eo[k] = -ein
        else:
            st[SEP_EO] = 0.0
            eps_out_eo[k] = ein + 0.5 * (vtn + vt) / ceo
        f_i[k], f_io[k], f_eo[k] = fi, fio, feo
        st[IMPULSE] += dt * (fi - fio - feo)
        st[FI_PREV] = fi
        # record (positions at t_k, before the update; velocities averaged to t_k)
        if k % stride == 0:
            j = k // stride
            ut = st[UT]
            mean_rel = 0.0
            for e in range(n_el):
                rec_p[j, e] = pres[e]
            for i in range(n_el + 1):
                rec_u[j, i] = u[i] - ut
                rec_ff[j, i] = ff[i]
                mean_rel += u[i] - ut
            rec_s[j, R_SLIP] = mean_rel / (n_el + 1)
        # update positions, slip distances
        for i in range(n_el + 1):
            u[i] += dt * vnew[i]
            slip[i] += dt * abs(vnew[i] - vtn)
        st[UT] += dt * vtn
        if k % stride == 0:
            j = k // stride
            p_sample = 0.0
            for i in range(n_el + 1):
                p_sample += mass[i] * vnew[i]
            rec_s[j, R_V0] = 0.5 * (vnew[0] + v[0])
            rec_s[j, R_VN] = 0.5 * (vnew[n_el] + v[n_el])
            rec_s[j, R_VT] = 0.5 * (vtn + vt)
            rec_s[j, R_P_SAMPLE] = p_sample - mplug * vnew[0]
            rec_s[j, R_P_PLUG] = mplug * vnew[0]
            rec_s[j, R_P_TUBE] = mt * vtn
            rec_s[j, R_IMPULSE] = st[IMPULSE]
            rec_s[j, R_PLUG_FRICTION] = pf
        for i in range(n_el + 1):
            v[i] = vnew[i]
        st[VT] = vtn


def max_wave_speed(*, young_modulus: float, density: float, nu: float, den: float) -> float:
    """Fastest axial wave speed of the column, c_max = sqrt(E / (rho (1 - 2 nu^2 / D))) (m/s)."""
    return math.sqrt(young_modulus / (1.0 - 2.0 * nu * nu / den) / density)


def critical_time_step(*, element_length: float, wave_speed: float, damping: float) -> float:
    """Stability limit of central differences for the column (s): (h / c_max)(sqrt(1 + z^2) - z).

    z is the damping ratio of the column's highest mode given by the artificial viscosity
    (stiffness-proportional damping lowers the limit by that factor).
    """
    return element_length / wave_speed * (math.sqrt(1.0 + damping * damping) - damping)
