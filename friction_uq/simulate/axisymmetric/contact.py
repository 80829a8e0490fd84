"""Unilateral contact with friction, kinematic (momentum-exchange) enforcement in the explicit step.

Both contacts act on the trial velocities of a step (after the internal forces) and correct them by
equal and opposite impulses, so momentum is exchanged exactly and no penalty stiffness limits the
time step or adds compliance:

* **Lateral contact** (sample on the tube's bore, plug on the bore): each slave node (the body's
  outer nodes, r = R) meets the bore segment of the tube between master nodes j and j + 1 at its
  current axial position (weights 1 - w, w). The normal is radial (the bore stays within microns of
  a cylinder). With the predicted gap g = r_bore(z) - r_node - clearance_offset after the step, a
  negative g is closed by the normal impulse J = -g / (dt (1/m_s + (1-w)^2/m_j + w^2/m_j+1))
  (two Gauss-Seidel sweeps, J >= 0 in total). The wall pressure is p = J / (dt A_s), A_s the node's
  lateral area. The axial (tangential) impulse that would stop the relative sliding is then
  limited to the strength tau_max(p, V, d) A_s dt of the simulator's friction law (V the sliding
  speed at the end of the step, found with the impulse: implicit in V)
  (:func:`friction_uq.simulate.friction.shear_strength`), plus an optional strength independent of
  pressure (the parasitic plug friction of the 1-D model, per node).
* **End-face pairs** (plug front face on the sample's input face): node k of one face meets node k
  of the other (same radial divisions). Axial normal (push only) and radial friction f_e J (PTFE
  sheets: small f_e; a bare face: larger).

The energy the contacts take (friction and closure) is counted by the solver from their impulses
and the nodes' velocities before and after the whole step (what the kinetic energy sees).
"""

from __future__ import annotations

import math

import numpy as np

from ..._jit import njit
from ..friction import shear_strength


@njit
def find_segment(zm: np.ndarray, z: float) -> int:
    """Index j with zm[j] <= z < zm[j + 1] (zm ascending), or -1 outside [zm[0], zm[-1]]."""
    n = zm.size
    if z < zm[0] or z > zm[n - 1]:
        return -1
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if zm[mid] <= z:
            lo = mid
        else:
            hi = mid
    return lo


@njit
def sliding_speed(rel: float, invm: float, law: int, fpar: np.ndarray, p: float, slip: float, area: float,
                  extra: float, dt: float) -> float:
    """Sliding speed V after the step of a node that slides: V = rel - S(V) invm, S the strength impulse.

    Solved by bisection on [0, rel] (S(0) invm < rel when the node slides; S >= 0 at V = rel): the
    friction law is taken at the end of the step (implicit in V), as the stick test takes it at V = 0.
    """
    lo, hi = 0.0, rel
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        g = mid - rel + (shear_strength(law, fpar, p, mid, slip) * area + extra) * dt * invm
        if g > 0.0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@njit
def lateral_contact(slaves: np.ndarray, area: np.ndarray, masters: np.ndarray, X: np.ndarray, u: np.ndarray,
                    v: np.ndarray, mass: np.ndarray, dt: float, offset: float, law: int, fpar: np.ndarray,
                    extra_strength: np.ndarray, slip: np.ndarray, speed: np.ndarray, j_normal: np.ndarray,
                    j_tangent: np.ndarray) -> None:
    """Close the predicted gaps of ``slaves`` on the bore ``masters`` and apply the wall friction, in place.

    ``v`` holds the trial velocities (n, 2) and is corrected. ``offset`` (m) is added to the clearance
    of the reference geometry (so that the effective clearance is the configured one). Per slave:
    ``extra_strength`` (N, pressure-independent), ``slip`` (m) and ``speed`` (m/s) of the friction law
    (updated here), and the normal and tangential impulses of the step (N s, written).
    """
    nm = masters.size
    zm = np.empty(nm)
    rm = np.empty(nm)
    for k in range(nm):
        m = masters[k]
        zm[k] = X[m, 1] + u[m, 1] + dt * v[m, 1]
        rm[k] = X[m, 0] + u[m, 0] + dt * v[m, 0]
    ns = slaves.size
    seg = np.empty(ns, dtype=np.int64)
    wgt = np.empty(ns)
    for i in range(ns):
        s = slaves[i]
        z = X[s, 1] + u[s, 1] + dt * v[s, 1]
        j = find_segment(zm, z)
        seg[i] = j
        wgt[i] = (z - zm[j]) / (zm[j + 1] - zm[j]) if j >= 0 else 0.0
        j_normal[i] = 0.0
        j_tangent[i] = 0.0
    for _sweep in range(2):
        for i in range(ns):
            j = seg[i]
            if j < 0:
                continue
            s, a, b, w = slaves[i], masters[j], masters[j + 1], wgt[i]
            r_bore = (1.0 - w) * (X[a, 0] + u[a, 0] + dt * v[a, 0]) + w * (X[b, 0] + u[b, 0] + dt * v[b, 0])
            g = r_bore - (X[s, 0] + u[s, 0] + dt * v[s, 0]) - offset
            invm = 1.0 / mass[s] + (1.0 - w) ** 2 / mass[a] + w * w / mass[b]
            dj = -g / (dt * invm)
            if j_normal[i] + dj < 0.0:
                dj = -j_normal[i]
            if dj == 0.0:
                continue
            j_normal[i] += dj
            v[s, 0] -= dj / mass[s]
            v[a, 0] += dj * (1.0 - w) / mass[a]
            v[b, 0] += dj * w / mass[b]
    for i in range(ns):
        j = seg[i]
        s = slaves[i]
        if j < 0:
            speed[i] = 0.0
            continue
        a, b, w = masters[j], masters[j + 1], wgt[i]
        p = j_normal[i] / (dt * area[i])
        rel = v[s, 1] - (1.0 - w) * v[a, 1] - w * v[b, 1]
        invm = 1.0 / mass[s] + (1.0 - w) ** 2 / mass[a] + w * w / mass[b]
        jt = rel / invm
        strength = (shear_strength(law, fpar, p, 0.0, slip[i]) * area[i] + extra_strength[i]) * dt
        if abs(jt) > strength:  # sliding: the strength at the speed after the step (implicit in V)
            speed_after = sliding_speed(abs(rel), invm, law, fpar, p, slip[i], area[i], extra_strength[i], dt)
            strength = (shear_strength(law, fpar, p, speed_after, slip[i]) * area[i] + extra_strength[i]) * dt
            jt = strength if rel > 0.0 else -strength
        v[s, 1] -= jt / mass[s]
        v[a, 1] += jt * (1.0 - w) / mass[a]
        v[b, 1] += jt * w / mass[b]
        rel_after = v[s, 1] - (1.0 - w) * v[a, 1] - w * v[b, 1]
        j_tangent[i] = jt
        speed[i] = abs(rel_after)
        slip[i] += dt * abs(rel_after)


@njit
def face_pairs(lower: np.ndarray, upper: np.ndarray, X: np.ndarray, u: np.ndarray, v: np.ndarray,
               mass: np.ndarray, dt: float, friction: float, j_normal: np.ndarray) -> None:
    """Push-only axial contact of node pairs (``lower[k]`` below ``upper[k]``) with radial friction, in place.

    The predicted axial gap z_upper - z_lower (zero at the start) is closed by J >= 0; the radial
    sliding is resisted up to ``friction`` J; ``j_normal`` (N s) is written.
    """
    for k in range(lower.size):
        a, b = lower[k], upper[k]
        g = (X[b, 1] + u[b, 1] + dt * v[b, 1]) - (X[a, 1] + u[a, 1] + dt * v[a, 1]) - (X[b, 1] - X[a, 1])
        invm = 1.0 / mass[a] + 1.0 / mass[b]
        jn = -g / (dt * invm) if g < 0.0 else 0.0
        j_normal[k] = jn
        if jn == 0.0:
            continue
        v[a, 1] -= jn / mass[a]
        v[b, 1] += jn / mass[b]
        if friction > 0.0:
            rel = v[b, 0] - v[a, 0]
            jt = rel / invm
            lim = friction * jn
            jt = min(lim, max(-lim, jt))
            v[b, 0] -= jt / mass[b]
            v[a, 0] += jt / mass[a]


def clearance_offset(reference_gap: float, wanted_gap: float) -> float:
    """Offset (m) that makes a contact's effective clearance ``wanted_gap`` on a mesh whose is ``reference_gap``."""
    if not math.isfinite(wanted_gap):
        raise ValueError("clearance must be finite")
    return wanted_gap - reference_gap
