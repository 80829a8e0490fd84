"""Structured axisymmetric meshes of the plug, the sample and the tube: 4-node rectangles in (r, z).

Coordinates (m): r from the axis, z along the axis, positive towards the output bars, z = 0 on the
sample's input face at the start. Bodies (each a rectangle of the (r, z) half plane, meshed with
equal rectangles of about the requested size):

* plug ``[0, R_p] x [-L_p, 0]`` (absent when its length is 0);
* sample ``[0, R] x [0, L]``; the plug's front face and the sample's input face share the same
  number of radial divisions, so their nodes face each other (node pairs of :mod:`.contact`);
* tube ``[a, b] x [z_t, z_t + L_t]`` with z_t = -(plug length inside the tube) (absent on request).

Lumped (row-sum) masses of the axisymmetric bilinear element: a rectangle [r1, r2] x [z1, z2] of
density rho gives each of its two inner nodes rho 2 pi (dz/2)(r1 dr/2 + dr^2/6) and each outer node
rho 2 pi (dz/2)(r1 dr/2 + dr^2/3); the four add up to the ring's mass rho 2 pi r_c dr dz.

Node order of an element: (r1, z1), (r2, z1), (r2, z2), (r1, z2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

PLUG, SAMPLE, TUBE = 0, 1, 2
BODY_NAMES = ("plug", "sample", "tube")


@dataclass(frozen=True)
class Material:
    """Isotropic elastic solid (SI), optionally Drucker-Prager perfectly plastic (``cohesion`` > 0).

    Yield: sigma_mises - alpha P < C (physics.md section 1, eq. 1), P the pressure (compression positive).
    """

    young_modulus: float
    poisson_ratio: float
    density: float
    cohesion: float = 0.0
    friction_angle_alpha: float = 0.0

    @property
    def lame(self) -> tuple[float, float]:
        """(lambda, mu) (Pa)."""
        e, nu = self.young_modulus, self.poisson_ratio
        return e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu))

    @property
    def dilatational_speed(self) -> float:
        """c_p = sqrt((lambda + 2 mu) / rho) (m/s)."""
        lam, mu = self.lame
        return math.sqrt((lam + 2.0 * mu) / self.density)


@dataclass(frozen=True)
class Block:
    """One body's rectangle, its divisions and material."""

    body: int
    r0: float
    r1: float
    z0: float
    z1: float
    nr: int
    nz: int
    material: Material


@dataclass
class Mesh:
    """All bodies in one set of arrays (what the compiled kernels read).

    ``X`` (n, 2) reference coordinates (r, z); ``mass`` (n,); ``conn`` (n_el, 4); ``geo`` (n_el, 4):
    inner radius r1, dr, dz, ring volume 2 pi r_c dr dz; ``mat`` (n_el, 7): lambda, mu, rho, c_p,
    cohesion C, alpha, plastic flag; ``grids``: body -> node index grid (nz + 1, nr + 1) (row iz,
    column ir); ``body_of_element`` (n_el,); ``axis`` node indices on r = 0.
    """

    X: np.ndarray
    mass: np.ndarray
    conn: np.ndarray
    geo: np.ndarray
    mat: np.ndarray
    body_of_element: np.ndarray
    grids: dict[int, np.ndarray] = field(default_factory=dict)
    blocks: dict[int, Block] = field(default_factory=dict)

    @property
    def axis(self) -> np.ndarray:
        return np.flatnonzero(self.X[:, 0] == 0.0)

    @property
    def n_nodes(self) -> int:
        return self.X.shape[0]

    @property
    def n_elements(self) -> int:
        return self.conn.shape[0]

    def has(self, body: int) -> bool:
        return body in self.grids

    def element_size(self, body: int) -> tuple[float, float]:
        """(dr, dz) of a body's elements (m)."""
        b = self.blocks[body]
        return (b.r1 - b.r0) / b.nr, (b.z1 - b.z0) / b.nz

    # surfaces (node indices, ordered by z for lateral faces, by r for end faces)
    def outer(self, body: int) -> np.ndarray:
        return self.grids[body][:, -1].copy()

    def inner(self, body: int) -> np.ndarray:
        return self.grids[body][:, 0].copy()

    def bottom(self, body: int) -> np.ndarray:
        """Face z = z0 (the input side)."""
        return self.grids[body][0, :].copy()

    def top(self, body: int) -> np.ndarray:
        """Face z = z1 (the output side)."""
        return self.grids[body][-1, :].copy()


def divisions(length: float, size: float, *, minimum: int = 1) -> int:
    """Number of equal elements of at most about ``size`` on ``length`` (at least ``minimum``)."""
    return max(minimum, int(math.ceil(length / size - 1e-9)))


def material_row(m: Material) -> np.ndarray:
    lam, mu = m.lame
    plastic = 1.0 if m.cohesion > 0.0 else 0.0
    return np.array([lam, mu, m.density, m.dilatational_speed, m.cohesion, m.friction_angle_alpha, plastic])


def build_mesh(blocks: list[Block]) -> Mesh:
    """Assemble the blocks' nodes, elements, lumped masses and element data (no shared nodes)."""
    xs, masses, conns, geos, mats, owners = [], [], [], [], [], []
    grids: dict[int, np.ndarray] = {}
    offset = 0
    for blk in blocks:
        r = np.linspace(blk.r0, blk.r1, blk.nr + 1)
        z = np.linspace(blk.z0, blk.z1, blk.nz + 1)
        rr, zz = np.meshgrid(r, z)  # (nz + 1, nr + 1)
        grid = offset + np.arange(rr.size).reshape(rr.shape)
        grids[blk.body] = grid
        xs.append(np.column_stack([rr.ravel(), zz.ravel()]))
        dr, dz = (blk.r1 - blk.r0) / blk.nr, (blk.z1 - blk.z0) / blk.nz
        m = np.zeros(rr.size)
        rho = blk.material.density
        for iz in range(blk.nz):
            for ir in range(blk.nr):
                r1 = r[ir]
                n0, n1 = grid[iz, ir], grid[iz, ir + 1]
                n2, n3 = grid[iz + 1, ir + 1], grid[iz + 1, ir]
                conns.append((n0, n1, n2, n3))
                rc = r1 + 0.5 * dr
                geos.append((r1, dr, dz, 2.0 * math.pi * rc * dr * dz))
                inner = rho * 2.0 * math.pi * 0.5 * dz * (r1 * dr / 2.0 + dr * dr / 6.0)
                outer = rho * 2.0 * math.pi * 0.5 * dz * (r1 * dr / 2.0 + dr * dr / 3.0)
                for n, mm in ((n0, inner), (n3, inner), (n1, outer), (n2, outer)):
                    m[n - offset] += mm
        masses.append(m)
        mats.append(np.tile(material_row(blk.material), (blk.nr * blk.nz, 1)))
        owners.append(np.full(blk.nr * blk.nz, blk.body, dtype=np.int64))
        offset += rr.size
    return Mesh(
        X=np.concatenate(xs), mass=np.concatenate(masses), conn=np.array(conns, dtype=np.int64),
        geo=np.array(geos, dtype=np.float64), mat=np.concatenate(mats), body_of_element=np.concatenate(owners),
        grids=grids, blocks={b.body: b for b in blocks},
    )


def segment_lengths(z: np.ndarray) -> np.ndarray:
    """Tributary length of each node of a line of nodes at positions ``z`` (half of each neighbouring segment)."""
    seg = np.diff(z)
    out = np.zeros(z.size)
    out[:-1] += 0.5 * seg
    out[1:] += 0.5 * seg
    return out


def face_areas(r: np.ndarray) -> np.ndarray:
    """Tributary annular area of each node of an end face at radii ``r`` (ascending), linear shape functions."""
    out = np.zeros(r.size)
    for i in range(r.size - 1):
        r1, r2 = r[i], r[i + 1]
        dr = r2 - r1
        out[i] += 2.0 * math.pi * (r1 * dr / 2.0 + dr * dr / 6.0)
        out[i + 1] += 2.0 * math.pi * (r1 * dr / 2.0 + dr * dr / 3.0)
    return out
