"""Explicit time integration of the cell: central differences, lumped masses, one compiled loop.

One step (t_k -> t_k+1), velocities at half steps:

1. nodal forces of the stresses, damping and hourglass control at t_k (:mod:`.kernels`);
2. trial velocities v + dt f / m (nodes on the axis keep u_r = 0);
3. contacts on the trial velocities (:mod:`.contact`): plug front face on the sample's input face,
   sample on the tube's bore, plug on the bore;
4. the three bar ends (:mod:`.coupling`): input bar on the plug's back face (or the sample's input
   face when there is no plug), internal output bar on the sample's output face, external output
   bar on the tube's output end;
5. displacements, then stresses from the step's strain increments (Drucker-Prager return where
   asked) and the stress work.

Energy (J), accumulated for the balance W_bars = KE + W_stress + E_hourglass + D_viscous + D_contact:
the bars' work on the cell, the stress work (elastic energy and plastic dissipation), the
hourglass energy, the damping's dissipation and the energy taken by the contacts (friction
and closure). The kinetic energy is taken at t_k from the mean of the two half-step velocities.
"""

from __future__ import annotations

import numpy as np

from ..._jit import njit
from .contact import face_pairs, lateral_contact
from .coupling import WORK, bar_face
from .kernels import SZZ, add_internal_forces, update_stresses

# scalar parameters ``par``
DT, C_HG, DAMPING, END_F, OFF_SAMPLE, OFF_PLUG, Z_I, C_I, Z_IO, C_IO, Z_EO, C_EO, HOOP_R = range(13)
N_PAR = 13
#: friction law code of the plug/tube contact (Coulomb, coefficient in the plug's parameter vector)
PLUG_LAW = 0
# flags ``flag``
HAS_PLUG, HAS_TUBE, LAW = range(3)
# accumulated state ``acc``
W_STRESS, D_VISC, D_CONTACT, IMPULSE = range(4)
N_ACC = 4
# recorded scalars ``rec_s``
(R_V_PLUG, R_V_OUT, R_V_TUBE, R_P_SAMPLE, R_P_PLUG, R_P_TUBE, R_IMPULSE, R_PLUG_FRICTION, R_SLIP, R_HOOP,
 R_W_BARS, R_KE, R_W_STRESS, R_E_HG, R_D_VISC, R_D_CONTACT, R_F_WALL) = range(17)
N_REC = 17


@njit
def _tube_axial_at(z: float, masters: np.ndarray, X: np.ndarray, u: np.ndarray) -> float:
    """Axial displacement of the bore at current position ``z`` (linear between master nodes; ends held)."""
    n = masters.size
    zc0 = X[masters[0], 1] + u[masters[0], 1]
    if z <= zc0:
        return u[masters[0], 1]
    for j in range(n - 1):
        a, b = masters[j], masters[j + 1]
        za, zb = X[a, 1] + u[a, 1], X[b, 1] + u[b, 1]
        if z <= zb:
            w = (z - za) / (zb - za)
            return (1.0 - w) * u[a, 1] + w * u[b, 1]
    return u[masters[n - 1], 1]


@njit
def run_block(k0: int, k1: int, stride: int, par: np.ndarray, flag: np.ndarray, fpar: np.ndarray, fpar_p: np.ndarray,
              X: np.ndarray, mass: np.ndarray, conn: np.ndarray, geo: np.ndarray, mat: np.ndarray,
              axis: np.ndarray, body_nodes: np.ndarray,
              plug_front: np.ndarray, sample_in: np.ndarray, sample_out: np.ndarray, sample_outer: np.ndarray,
              sample_area: np.ndarray, plug_outer: np.ndarray, plug_area: np.ndarray, plug_extra: np.ndarray,
              tube_inner: np.ndarray, tube_end: np.ndarray, in_face: np.ndarray,
              share_in: np.ndarray, share_out: np.ndarray, share_tube: np.ndarray, hoop_nodes: np.ndarray,
              hoop_w: np.ndarray, sample_rows: np.ndarray,
              u: np.ndarray, v: np.ndarray, sig: np.ndarray, visc: np.ndarray, slip_s: np.ndarray,
              speed_s: np.ndarray, slip_p: np.ndarray, speed_p: np.ndarray, faces: np.ndarray, acc: np.ndarray,
              pf_coef: float, pf_force: float, fprev: np.ndarray,
              eps_in_i: np.ndarray, eps_in_io: np.ndarray, eps_in_eo: np.ndarray,
              eps_out_i: np.ndarray, eps_out_io: np.ndarray, eps_out_eo: np.ndarray,
              f_i: np.ndarray, f_io: np.ndarray, f_eo: np.ndarray,
              rec_p: np.ndarray, rec_u: np.ndarray, rec_ff: np.ndarray, rec_sz: np.ndarray,
              rec_s: np.ndarray) -> None:
    """Advance the cell over steps k0 <= k < k1 in place (arrays described in :mod:`.model_axisymmetric`).

    ``body_nodes`` (3, 2): first and last + 1 node index of plug, sample, tube. ``faces`` (3, N_FACE_STATE):
    state of the input, internal and external bar ends. ``fprev`` [0]: F_i of the previous step (for the
    plug friction strength proportional to F_i). ``sample_rows`` (nz, 2): first element and count of each
    row of sample elements. Every ``stride``-th step is recorded.
    """
    dt = par[DT]
    n = X.shape[0]
    has_plug, has_tube, law = flag[HAS_PLUG] > 0, flag[HAS_TUBE] > 0, flag[LAW]
    force = np.zeros((n, 2))
    v_prev = np.empty((n, 2))
    v_trial = np.empty((n, 2))
    du = np.empty((n, 2))
    js_n = np.zeros(sample_outer.size)
    js_t = np.zeros(sample_outer.size)
    jp_n = np.zeros(plug_outer.size)
    jp_t = np.zeros(plug_outer.size)
    jf = np.zeros(plug_front.size)
    extra_s = np.zeros(sample_outer.size)
    extra_p = np.zeros(plug_outer.size)
    for k in range(k0, k1):
        force[:, :] = 0.0
        e_hg = add_internal_forces(u, sig, visc, conn, geo, mat, par[C_HG], force)
        _trial_velocities(v, v_prev, v_trial, force, mass, dt, axis)
        if has_plug:
            face_pairs(plug_front, sample_in, X, u, v, mass, dt, par[END_F], jf)
        if has_tube:
            lateral_contact(sample_outer, sample_area, tube_inner, X, u, v, mass, dt, par[OFF_SAMPLE], law,
                            fpar, extra_s, slip_s, speed_s, js_n, js_t)
            if has_plug:
                s_pf = pf_force + pf_coef * fprev[0]
                for i in range(plug_outer.size):
                    extra_p[i] = s_pf * plug_extra[i]
                lateral_contact(plug_outer, plug_area, tube_inner, X, u, v, mass, dt, par[OFF_PLUG], PLUG_LAW,
                                fpar_p, extra_p, slip_p, speed_p, jp_n, jp_t)
        for i in range(n):  # axial impulses of the contacts (the bar ends' work is counted by the bars)
            v_trial[i, 1] = mass[i] * (v[i, 1] - v_trial[i, 1])
        fi, ei = bar_face(in_face, share_in, 1.0, par[Z_I], par[C_I], eps_in_i[k], v, mass, dt,
                          par[END_F] if not has_plug else 0.0, faces[0])
        fio, eio = bar_face(sample_out, share_out, -1.0, par[Z_IO], par[C_IO], eps_in_io[k], v, mass, dt,
                            par[END_F], faces[1])
        feo, eeo = 0.0, 0.0
        if has_tube:
            feo, eeo = bar_face(tube_end, share_tube, -1.0, par[Z_EO], par[C_EO], eps_in_eo[k], v, mass, dt,
                                0.0, faces[2])
        else:
            eeo = -eps_in_eo[k]
        for i in range(axis.size):
            v[axis[i], 0] = 0.0
        lost = _contact_loss(v, v_prev, v_trial, mass)
        f_i[k], f_io[k], f_eo[k] = fi, fio, feo
        eps_out_i[k], eps_out_io[k], eps_out_eo[k] = ei, eio, eeo
        fprev[0] = fi
        acc[IMPULSE] += dt * (fi - fio - feo)
        acc[D_CONTACT] += lost
        if k % stride == 0:
            _record(k // stride, X, u, v, v_prev, mass, sig, geo, body_nodes, sample_outer, js_n, js_t, sample_area,
                    tube_inner, jp_t, hoop_nodes, hoop_w, sample_rows, faces, acc, e_hg, dt, par[HOOP_R], has_tube,
                    rec_p, rec_u, rec_ff, rec_sz, rec_s)
        for i in range(n):
            for d in range(2):
                du[i, d] = dt * v[i, d]
                u[i, d] += du[i, d]
        w_stress, d_visc = update_stresses(du, dt, sig, visc, conn, geo, mat, par[DAMPING])
        acc[W_STRESS] += w_stress
        acc[D_VISC] += d_visc


@njit
def _trial_velocities(v: np.ndarray, v_prev: np.ndarray, v_trial: np.ndarray, force: np.ndarray, mass: np.ndarray,
                      dt: float, axis: np.ndarray) -> None:
    """v <- v + dt f / m (u_r = 0 on the axis); the old velocities to ``v_prev``, the trial ones to ``v_trial``."""
    for i in range(v.shape[0]):
        for d in range(2):
            v_prev[i, d] = v[i, d]
            v[i, d] += dt * force[i, d] / mass[i]
    for i in range(axis.size):
        v[axis[i], 0] = 0.0
    v_trial[:, :] = v


@njit
def _contact_loss(v: np.ndarray, v_prev: np.ndarray, v_trial: np.ndarray, mass: np.ndarray) -> float:
    """Energy (J) the contact impulses took over the step: minus their work on the mean of the two half-step
    velocities. ``v_trial`` holds the radial trial velocities and, axially, the contacts' impulses (the
    bar ends' axial work is counted by the bars)."""
    lost = 0.0
    for i in range(v.shape[0]):
        jr = mass[i] * (v[i, 0] - v_trial[i, 0])
        lost -= jr * 0.5 * (v[i, 0] + v_prev[i, 0]) + v_trial[i, 1] * 0.5 * (v[i, 1] + v_prev[i, 1])
    return lost


@njit
def _record(j: int, X: np.ndarray, u: np.ndarray, v: np.ndarray, v_prev: np.ndarray, mass: np.ndarray,
            sig: np.ndarray, geo: np.ndarray, body_nodes: np.ndarray, sample_outer: np.ndarray, js_n: np.ndarray,
            js_t: np.ndarray, sample_area: np.ndarray, tube_inner: np.ndarray, jp_t: np.ndarray,
            hoop_nodes: np.ndarray, hoop_w: np.ndarray, sample_rows: np.ndarray, faces: np.ndarray,
            acc: np.ndarray, e_hg: float, dt: float, hoop_r: float, has_tube: bool,
            rec_p: np.ndarray, rec_u: np.ndarray, rec_ff: np.ndarray, rec_sz: np.ndarray,
            rec_s: np.ndarray) -> None:
    """Record step j's fields (positions at t_k, velocities as the mean of the two half steps)."""
    ke = 0.0
    for i in range(X.shape[0]):
        vr = 0.5 * (v[i, 0] + v_prev[i, 0])
        vz = 0.5 * (v[i, 1] + v_prev[i, 1])
        ke += 0.5 * mass[i] * (vr * vr + vz * vz)
    for b, col in ((0, R_P_PLUG), (1, R_P_SAMPLE), (2, R_P_TUBE)):
        p = 0.0
        for i in range(body_nodes[b, 0], body_nodes[b, 1]):
            p += mass[i] * 0.5 * (v[i, 1] + v_prev[i, 1])
        rec_s[j, col] = p
    mean_rel = 0.0
    f_wall = 0.0
    for i in range(sample_outer.size):
        s = sample_outer[i]
        rec_p[j, i] = js_n[i] / (dt * sample_area[i])
        rec_ff[j, i] = -js_t[i] / dt
        f_wall += js_t[i] / dt
        if has_tube:
            rel = u[s, 1] - _tube_axial_at(X[s, 1] + u[s, 1], tube_inner, X, u)
        else:
            rel = u[s, 1]
        rec_u[j, i] = rel
        mean_rel += rel
    rec_s[j, R_SLIP] = mean_rel / sample_outer.size
    rec_s[j, R_F_WALL] = f_wall
    pf = 0.0
    for i in range(jp_t.size):
        pf -= jp_t[i] / dt
    rec_s[j, R_PLUG_FRICTION] = pf
    for row in range(sample_rows.shape[0]):
        e0, ne = sample_rows[row, 0], sample_rows[row, 1]
        num = 0.0
        den = 0.0
        for e in range(e0, e0 + ne):
            num += geo[e, 3] * sig[e, SZZ]
            den += geo[e, 3]
        rec_sz[j, row] = num / den
    hoop = 0.0
    for i in range(hoop_nodes.size):
        hoop += hoop_w[i] * u[hoop_nodes[i], 0]
    rec_s[j, R_HOOP] = hoop / hoop_r if hoop_r > 0.0 else 0.0
    rec_s[j, R_V_PLUG] = faces[0, 1]
    rec_s[j, R_V_OUT] = faces[1, 1]
    rec_s[j, R_V_TUBE] = faces[2, 1]
    rec_s[j, R_IMPULSE] = acc[IMPULSE]
    rec_s[j, R_W_BARS] = faces[0, WORK] + faces[1, WORK] + faces[2, WORK]
    rec_s[j, R_KE] = ke
    rec_s[j, R_W_STRESS] = acc[W_STRESS]
    rec_s[j, R_E_HG] = e_hg
    rec_s[j, R_D_VISC] = acc[D_VISC]
    rec_s[j, R_D_CONTACT] = acc[D_CONTACT]

