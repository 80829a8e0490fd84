"""Static solutions with the explicit kernels' element (for verification against closed forms).

:func:`stiffness_matrix` assembles K of the same one-point element with hourglass stiffness that
:mod:`.kernels` integrates in time (a test checks K u = -f_int(u) on a random field), so a static
solve K u = f checks the element against Lame and the pressure band of physics.md section 6
without running a transient to rest.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .kernels import DNR, DNZ, HG, LAM, MU, hourglass_stiffness
from .mesh import Mesh


def element_stiffness(geo: np.ndarray, mat: np.ndarray, c_hg: float) -> np.ndarray:
    """8 x 8 stiffness of one element, dofs (u_r0, u_z0, u_r1, u_z1, ...): V B^T D B + hourglass."""
    r1, dr, dz, vol = geo
    rc = r1 + 0.5 * dr
    b = np.zeros((4, 8))  # rows: eps_rr, eps_zz, eps_tt, gamma_rz
    for i in range(4):
        b[0, 2 * i] = DNR[i] / (2.0 * dr)
        b[1, 2 * i + 1] = DNZ[i] / (2.0 * dz)
        b[2, 2 * i] = 0.25 / rc
        b[3, 2 * i] = DNZ[i] / (2.0 * dz)
        b[3, 2 * i + 1] = DNR[i] / (2.0 * dr)
    lam, mu = mat[LAM], mat[MU]
    d = np.zeros((4, 4))
    d[:3, :3] = lam
    d[[0, 1, 2], [0, 1, 2]] += 2.0 * mu
    d[3, 3] = mu
    k = vol * b.T @ d @ b
    khg = hourglass_stiffness(mat, geo, c_hg)
    for c in range(2):
        idx = np.arange(4) * 2 + c
        k[np.ix_(idx, idx)] += khg * np.outer(HG, HG)
    return k


def stiffness_matrix(mesh: Mesh, c_hg: float) -> sp.csr_matrix:
    """Global stiffness (2 n x 2 n, dofs 2 i (radial) and 2 i + 1 (axial) of node i)."""
    cache: dict[tuple[float, ...], np.ndarray] = {}  # structured meshes repeat the same few rings
    rows, cols, vals = [], [], []
    for e in range(mesh.n_elements):
        key = (*mesh.geo[e], *mesh.mat[e])
        ke = cache.get(key)
        if ke is None:
            ke = cache[key] = element_stiffness(mesh.geo[e], mesh.mat[e], c_hg)
        dofs = np.ravel(np.column_stack([2 * mesh.conn[e], 2 * mesh.conn[e] + 1]))
        rows.append(np.repeat(dofs, 8))
        cols.append(np.tile(dofs, 8))
        vals.append(ke.ravel())
    n = 2 * mesh.n_nodes
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))


class StaticSolver:
    """K u = f on ``mesh`` with the dofs ``fixed_dofs`` held at zero (K factorised once, for many loads)."""

    def __init__(self, mesh: Mesh, fixed_dofs: np.ndarray, *, c_hg: float) -> None:
        k = stiffness_matrix(mesh, c_hg)
        self.n = k.shape[0]
        self.free = np.setdiff1d(np.arange(self.n), fixed_dofs)
        self._lu = spla.splu(k[self.free][:, self.free].tocsc())

    def solve(self, load: np.ndarray) -> np.ndarray:
        """Displacements (n, 2) under nodal ``load`` (n, 2)."""
        u = np.zeros(self.n)
        u[self.free] = self._lu.solve(load.ravel()[self.free])
        return u.reshape(-1, 2)


def pressure_load(mesh: Mesh, nodes: np.ndarray, pressure: np.ndarray) -> np.ndarray:
    """Nodal forces (n, 2) of a radial pressure (Pa, outward) on a line of nodes at one radius.

    ``pressure`` (nodes.size - 1,) is uniform on each segment between neighbouring nodes (ascending
    z); each segment's force goes half to each of its nodes.
    """
    z = mesh.X[nodes, 1]
    r = mesh.X[nodes[0], 0]
    load = np.zeros((mesh.n_nodes, 2))
    seg = 2.0 * np.pi * r * np.diff(z) * np.asarray(pressure, float)
    np.add.at(load[:, 0], nodes[:-1], 0.5 * seg)
    np.add.at(load[:, 0], nodes[1:], 0.5 * seg)
    return load
