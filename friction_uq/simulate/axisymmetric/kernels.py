"""Element kernels: axisymmetric 4-node rectangles, one-point integration, hourglass control.

Inside the solver the continuum sign convention holds (stresses and strains positive in tension);
the model layer turns forces into compression-positive bar forces.

Per element (rectangle [r1, r2] x [z1, z2], centroid radius r_c, ring volume V = 2 pi r_c dr dz),
at the centroid: dN/dr = (-1, 1, 1, -1) / (2 dr), dN/dz = (-1, -1, 1, 1) / (2 dz), N = 1/4, and

    eps_rr = sum dN_i/dr u_r,i     eps_zz = sum dN_i/dz u_z,i     eps_tt = sum u_r,i / (4 r_c)
    gamma_rz = sum (dN_i/dz u_r,i + dN_i/dr u_z,i)

nodal forces f_r,i = -V (s_rr dN_i/dr + s_tt / (4 r_c) + s_rz dN_i/dz), f_z,i = -V (s_zz dN_i/dz +
s_rz dN_i/dr). Stresses are updated from the strain increments of each step (rate form, small
strain on the reference geometry: the sliding is a rigid axial translation, which strains nothing).

* **Hourglass control** (Flanagan-Belytschko, stiffness form): the bilinear mode h = (1, -1, 1, -1),
  orthogonal to the linear fields on a rectangle, is resisted by f_i = -k h_i (h . u) per direction,
  k = c_hg (lambda + 2 mu) V (1/dr^2 + 1/dz^2) / 4; its energy k (h.u)^2 / 2 is stored, not lost.
* **Stiffness-proportional damping** (Rayleigh): a viscous stress D eps_rate (l / c_p) z, l = min(dr,
  dz), gives the mesh's highest mode the damping ratio z and a mode of frequency omega the ratio
  z omega / omega_max: it damps ringing at the mesh scale (and the node-level stick-slip a
  velocity-weakening law feeds there, as the 1-D simulator's artificial viscosity does) and
  vanishes in a stationary state (rigid sliding strains nothing).
* **Drucker-Prager, perfectly plastic** (sample, optional): yield sigma_mises - alpha P = C
  (physics.md section 1: C = 25 MPa, alpha = 0.64 for I1). Return: the deviator is scaled back to
  the yield surface at constant pressure (no plastic dilatancy); below the apex (P < -C / alpha)
  the stress returns to the apex.
"""

from __future__ import annotations

import math

import numpy as np

from ..._jit import njit

# columns of the material rows (mesh.material_row)
LAM, MU, RHO, CP, COH, ALPHA, PLASTIC = range(7)
# stress components
SRR, SZZ, STT, SRZ = range(4)
DNR = np.array([-1.0, 1.0, 1.0, -1.0])
DNZ = np.array([-1.0, -1.0, 1.0, 1.0])
HG = np.array([1.0, -1.0, 1.0, -1.0])


@njit
def drucker_prager_return(s: np.ndarray, cohesion: float, alpha: float) -> None:
    """Bring the stress ``s`` (rr, zz, tt, rz; tension positive) back to sigma_mises - alpha P <= C, in place.

    >>> s = np.array([-50e6, -200e6, -50e6, 0.0])   # P = 100 MPa, sigma_mises = 150 MPa > 25 + 64 MPa
    >>> drucker_prager_return(s, 25e6, 0.64)
    >>> round(float(s[0] - s[1]) / 1e6, 3)           # sigma_mises on the yield surface
    89.0
    """
    p = -(s[SRR] + s[SZZ] + s[STT]) / 3.0
    d0, d1, d2, d3 = s[SRR] + p, s[SZZ] + p, s[STT] + p, s[SRZ]
    q = math.sqrt(1.5 * (d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * d3 * d3))
    limit = cohesion + alpha * p
    if q <= limit:
        return
    if limit <= 0.0:  # beyond the apex in tension
        p_apex = -cohesion / alpha if alpha > 0.0 else p
        s[SRR] = s[SZZ] = s[STT] = -p_apex
        s[SRZ] = 0.0
        return
    k = limit / q
    s[SRR] = k * d0 - p
    s[SZZ] = k * d1 - p
    s[STT] = k * d2 - p
    s[SRZ] = k * d3


@njit
def hourglass_stiffness(mat: np.ndarray, geo: np.ndarray, c_hg: float) -> float:
    """k = c_hg (lambda + 2 mu) V (1/dr^2 + 1/dz^2) / 4 (N/m) of one element."""
    return c_hg * (mat[LAM] + 2.0 * mat[MU]) * geo[3] * (1.0 / geo[1] ** 2 + 1.0 / geo[2] ** 2) / 4.0


@njit
def add_internal_forces(u: np.ndarray, sig: np.ndarray, visc: np.ndarray, conn: np.ndarray, geo: np.ndarray,
                        mat: np.ndarray, c_hg: float, force: np.ndarray) -> float:
    """Add the nodal forces of stress, damping and hourglass control to ``force`` (n, 2).

    Returns the hourglass energy (J). ``visc`` (n_el, 4) is the viscous stress added to ``sig``
    (tension positive).
    """
    e_hg = 0.0
    for e in range(conn.shape[0]):
        r1, dr, dz, vol = geo[e, 0], geo[e, 1], geo[e, 2], geo[e, 3]
        rc = r1 + 0.5 * dr
        srr = sig[e, SRR] + visc[e, SRR]
        szz = sig[e, SZZ] + visc[e, SZZ]
        stt = sig[e, STT] + visc[e, STT]
        srz = sig[e, SRZ] + visc[e, SRZ]
        k = hourglass_stiffness(mat[e], geo[e], c_hg)
        qr = 0.0
        qz = 0.0
        for i in range(4):
            n = conn[e, i]
            qr += HG[i] * u[n, 0]
            qz += HG[i] * u[n, 1]
        e_hg += 0.5 * k * (qr * qr + qz * qz)
        for i in range(4):
            n = conn[e, i]
            bnr = DNR[i] / (2.0 * dr)
            bnz = DNZ[i] / (2.0 * dz)
            force[n, 0] -= vol * (srr * bnr + stt * 0.25 / rc + srz * bnz) + k * HG[i] * qr
            force[n, 1] -= vol * (szz * bnz + srz * bnr) + k * HG[i] * qz
    return e_hg


@njit
def update_stresses(du: np.ndarray, dt: float, sig: np.ndarray, visc: np.ndarray, conn: np.ndarray,
                    geo: np.ndarray, mat: np.ndarray, damping: float) -> tuple[float, float]:
    """Stresses after the displacement increment ``du`` (n, 2) of one step.

    Returns (stress work, viscous dissipation) (J): V (s_old + s_new) / 2 : d_eps summed over the
    elements (elastic energy plus plastic dissipation), and V s_v : d_eps with the viscous stress s_v
    that acted during the step. ``visc`` is then set to the damping stress of this step's strain rate.
    """
    work = 0.0
    d_visc = 0.0
    for e in range(conn.shape[0]):
        r1, dr, dz, vol = geo[e, 0], geo[e, 1], geo[e, 2], geo[e, 3]
        rc = r1 + 0.5 * dr
        d_rr = 0.0
        d_zz = 0.0
        d_tt = 0.0
        g_rz = 0.0
        for i in range(4):
            n = conn[e, i]
            bnr = DNR[i] / (2.0 * dr)
            bnz = DNZ[i] / (2.0 * dz)
            d_rr += bnr * du[n, 0]
            d_zz += bnz * du[n, 1]
            d_tt += 0.25 * du[n, 0] / rc
            g_rz += bnz * du[n, 0] + bnr * du[n, 1]
        lam, mu = mat[e, LAM], mat[e, MU]
        tr = d_rr + d_zz + d_tt
        o0, o1, o2, o3 = sig[e, SRR], sig[e, SZZ], sig[e, STT], sig[e, SRZ]
        sig[e, SRR] = o0 + lam * tr + 2.0 * mu * d_rr
        sig[e, SZZ] = o1 + lam * tr + 2.0 * mu * d_zz
        sig[e, STT] = o2 + lam * tr + 2.0 * mu * d_tt
        sig[e, SRZ] = o3 + mu * g_rz
        if mat[e, PLASTIC] > 0.0:
            drucker_prager_return(sig[e], mat[e, COH], mat[e, ALPHA])
        work += 0.5 * vol * ((o0 + sig[e, SRR]) * d_rr + (o1 + sig[e, SZZ]) * d_zz
                             + (o2 + sig[e, STT]) * d_tt + (o3 + sig[e, SRZ]) * g_rz)
        d_visc += vol * (visc[e, SRR] * d_rr + visc[e, SZZ] * d_zz + visc[e, STT] * d_tt + visc[e, SRZ] * g_rz)
        eta = damping * min(dr, dz) / mat[e, CP] / dt
        visc[e, SRR] = eta * (lam * tr + 2.0 * mu * d_rr)
        visc[e, SZZ] = eta * (lam * tr + 2.0 * mu * d_zz)
        visc[e, STT] = eta * (lam * tr + 2.0 * mu * d_tt)
        visc[e, SRZ] = eta * mu * g_rz
    return work, d_visc


@njit
def elastic_forces(u: np.ndarray, conn: np.ndarray, geo: np.ndarray, mat: np.ndarray, c_hg: float,
                   force: np.ndarray) -> None:
    """force = -K u for the linear elastic mesh (stress from the total strain of ``u``; no viscosity)."""
    n_el = conn.shape[0]
    sig = np.zeros((n_el, 4))
    visc = np.zeros((n_el, 4))
    zero_mat = mat.copy()
    zero_mat[:, PLASTIC] = 0.0
    update_stresses(u, 1.0, sig, visc, conn, geo, zero_mat, 0.0)
    force[:, :] = 0.0
    add_internal_forces(u, sig, visc, conn, geo, mat, c_hg, force)


def highest_frequency(mass: np.ndarray, conn: np.ndarray, geo: np.ndarray, mat: np.ndarray, c_hg: float,
                      fixed_radial: np.ndarray, *, iterations: int = 60, seed: int = 0) -> float:
    """Largest angular frequency omega_max (rad/s) of the lumped-mass mesh, by power iteration on M^-1 K.

    Central differences are stable for dt < 2 / omega_max (Rayleigh quotient of the last iterate,
    raised by 2 % for the iteration's shortfall).
    """
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((mass.size, 2))
    u[fixed_radial, 0] = 0.0
    f = np.zeros_like(u)
    lam = 0.0
    for _ in range(iterations):
        u /= np.sqrt(np.sum(mass[:, None] * u * u))
        elastic_forces(u, conn, geo, mat, c_hg, f)
        f[fixed_radial, 0] = 0.0
        lam = float(-np.sum(u * f))  # u^T K u with u^T M u = 1
        u = -f / mass[:, None]
    return 1.02 * math.sqrt(max(lam, 0.0))


def critical_time_step(omega_max: float, *, damping: float) -> float:
    """Stability limit of central differences (s): (2 / omega_max)(sqrt(1 + z^2) - z), z the damping ratio
    of the highest mode."""
    z = damping
    return 2.0 / omega_max * (math.sqrt(1.0 + z * z) - z)
