"""Coupling of a 1-D bar's end to a face of the mesh (plane sections stay plane).

A bar end is a rigid, push-only face tied to the axial motion of the face's nodes: while the bar
pushes, those nodes move axially together with the bar end's velocity v, radially free (or held
back by the end-face friction). The bar is the exact 1-D characteristic relation used by the 1-D
simulator (:mod:`friction_uq.simulate.cell`): with eps_in the wave arriving at the end
(compression positive) and s = +1 for the input bar (pushing towards +z) or -1 for an output bar,

    F = Z (2 c eps_in - s v)          eps_out = eps_in - s v / c

taken implicitly over the step (v = mean of the two half-step velocities), so the bar's damping
adds no stability limit. The face's momentum after the step is P* + s F dt, P* the nodes' trial
momentum. When F would pull, the end is free (F = 0, eps_out = -eps_in) and the separation is
tracked until the surfaces meet again, as in the 1-D simulator.
"""

from __future__ import annotations

import numpy as np

from ..._jit import njit

# per-face state
SEP, V_OLD, WORK = range(3)
N_FACE_STATE = 3


@njit
def bar_face(nodes: np.ndarray, share: np.ndarray, sign: float, z_bar: float, c_bar: float, eps_in: float,
             v: np.ndarray, mass: np.ndarray, dt: float, end_friction: float, state: np.ndarray) -> tuple:
    """Apply one bar end to the face ``nodes`` (trial velocities ``v`` corrected in place).

    ``share`` is each node's fraction of the face area (for the end-face friction f_e F share_i).
    ``state`` holds the separation (m), the face's last velocity and the bar's work on the cell (J).
    Returns (force F >= 0 (N), outgoing wave eps_out).
    """
    m_face = 0.0
    p_star = 0.0
    for i in range(nodes.size):
        n = nodes[i]
        m_face += mass[n]
        p_star += mass[n] * v[n, 1]
    v_old = state[V_OLD]
    force = 0.0
    contact = state[SEP] <= 0.0
    if contact:
        v_new = (p_star + dt * z_bar * (sign * 2.0 * c_bar * eps_in - 0.5 * v_old)) / (m_face + 0.5 * dt * z_bar)
        force = z_bar * (2.0 * c_bar * eps_in - sign * 0.5 * (v_new + v_old))
        contact = force >= 0.0
    if contact:
        for i in range(nodes.size):
            v[nodes[i], 1] = v_new
        if end_friction > 0.0:
            for i in range(nodes.size):
                n = nodes[i]
                lim = end_friction * force * share[i] * dt
                jt = min(lim, max(-lim, mass[n] * v[n, 0]))
                v[n, 0] -= jt / mass[n]
        state[SEP] = 0.0
        v_mid = 0.5 * (v_new + v_old)
        eps_out = eps_in - sign * v_mid / c_bar
        state[WORK] += dt * force * sign * v_mid
        state[V_OLD] = v_new
    else:
        force = 0.0
        v_new = p_star / m_face
        v_mid = 0.5 * (v_new + v_old)
        sep = state[SEP] + dt * sign * (v_mid - sign * 2.0 * c_bar * eps_in)
        state[SEP] = sep if sep > 0.0 else 0.0
        eps_out = -eps_in
        state[V_OLD] = v_new
    return force, eps_out
